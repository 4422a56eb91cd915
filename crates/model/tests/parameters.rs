//! `[parameters]`: named constants, numbers written as expressions of them, parameters freed
//! by `[fit] free`, and the writer keeping the expressions.
use model::model_file::{FreeTarget, PlantMatrix};
use model::{parse_str, to_toml_string};

const MASS_SPRING: &str = r#"
name = "mass on a spring"
[parameters]
M = 2.0
c = 0.6
k = 4.0
g = 1
[plant]
A = [[0, 1], ["-k/M", "-c/M"]]
B = [0, "g/M"]
C = [[1, 0]]
E = [[0], ["k/M/2"]]
[theta]
shape = "interval"
half_width = 0.1
[input]
kind = "sine"
amplitudes = [1.0]
omega = 1.0
[initial]
x0 = ["1/2", 0]
[[effects]]
kind = "coulomb_friction"
state = 1
level = "0.05*g/M"
[fit]
free = ["M", "plant.A[0][1]"]
[fit.bounds]
M = [1.0, 4.0]
"#;

#[test]
fn expressions_take_the_values_of_the_parameters() {
    let sys = parse_str(MASS_SPRING).unwrap();
    assert_eq!(sys.A[(1, 0)], -2.0);
    assert_eq!(sys.A[(1, 1)], -0.3);
    assert_eq!(sys.B[(1, 0)], 0.5, "a flat B is a column, integer literals are floats");
    assert_eq!(sys.E[(1, 0)], 1.0);
    assert_eq!(sys.x0[0], 0.5, "1/2 is 0.5, not an integer division");
    assert_eq!(sys.z0[0], 0.5, "an unstated z0 is C x0");
    assert_eq!(sys.effects.list[0], model::effects::Effect::CoulombFriction { state: 1, level: 0.025 });
    assert_eq!(sys.parameters.names, ["M", "c", "g", "k"]);
    assert_eq!(sys.parameters.bindings.len(), 6);
}

#[test]
fn a_freed_parameter_moves_every_number_written_with_it() {
    let mut sys = parse_str(MASS_SPRING).unwrap();
    let m = &sys.fit.free[0];
    assert_eq!((m.name.as_str(), m.target, m.bounds), ("M", FreeTarget::Parameter, Some((1.0, 4.0))));
    assert_eq!(sys.fit.free[1].target, FreeTarget::Entry { matrix: PlantMatrix::A, row: 0, col: 1 });
    assert_eq!(m.get(&sys), 2.0);
    let m = m.clone();
    m.set(&mut sys, 4.0).unwrap();
    assert_eq!((sys.A[(1, 0)], sys.A[(1, 1)], sys.B[(1, 0)], sys.E[(1, 0)]), (-1.0, -0.15, 0.25, 0.5));
    assert_eq!(sys.effects.list[0], model::effects::Effect::CoulombFriction { state: 1, level: 0.0125 });
    assert_eq!(m.get(&sys), 4.0);
    // an expression leaving its range (a negative friction level) is refused, nothing changes
    let before = to_toml_string(&sys);
    let e = sys.set_parameter("g", -1.0).unwrap_err().to_string();
    assert!(e.contains("effects[0].level") && e.contains("non-negative"), "{e}");
    assert_eq!(to_toml_string(&sys), before);
    let e = sys.set_parameter("Q", 1.0).unwrap_err().to_string();
    assert!(e.contains("`Q`") && e.contains("M, c, g, k"), "{e}");
}

#[test]
fn the_writer_keeps_the_expressions_and_the_fitted_values() {
    let mut sys = parse_str(MASS_SPRING).unwrap();
    sys.set_parameter("M", 2.5).unwrap();
    let text = to_toml_string(&sys);
    assert!(text.contains("\"-k/M\"") && text.contains("\"0.05*g/M\"") && text.contains("\"1/2\""), "{text}");
    assert!(text.contains("M = 2.5"), "{text}");
    let back = parse_str(&text).unwrap();
    assert_eq!(back.A, sys.A);
    assert_eq!(back.B, sys.B);
    assert_eq!(back.effects, sys.effects);
    assert_eq!(back.fit.free, sys.fit.free);
    // a number changed by other means than its parameters is written as that number
    sys.A[(1, 0)] = -7.0;
    let text = to_toml_string(&sys);
    assert!(!text.contains("\"-k/M\"") && text.contains("-7.0"), "{text}");
    assert_eq!(parse_str(&text).unwrap().A[(1, 0)], -7.0);
}

#[test]
fn expressions_read_as_a_physicist_writes_them() {
    let eval = |e: &str| {
        let text = format!("[parameters]\nM = 3\n[plant]\nA = [[\"{e}\"]]\nB = [[0]]\nC = [[1]]\nE = [[0]]\n");
        parse_str(&text).unwrap().A[(0, 0)]
    };
    assert_eq!(eval("-M^2"), -9.0);
    assert_eq!(eval("1/2*M"), 1.5);
    assert_eq!(eval("1e-3*M"), 0.003);
    assert_eq!(eval("2.5E+1 - M"), 22.0);
    assert_eq!(eval("sqrt(M*3) + abs(-1)"), 4.0);
    assert!((eval("-sin(pi/2)") + 1.0).abs() < 1e-15);
    assert_eq!(eval("7 % 2"), 1.0);
}

#[test]
fn bad_expressions_name_the_key_the_expression_and_the_problem() {
    let with = |params: &str, a: &str| {
        let text = format!("[parameters]\n{params}\n[plant]\nA = [[{a}]]\nB = [[0]]\nC = [[1]]\nE = [[0]]\n");
        parse_str(&text).unwrap_err().to_string()
    };
    let e = with("M = 1", "\"-k/M\"");
    assert!(
        e.contains("plant.A[0][0]") && e.contains("\"-k/M\"") && e.contains("unknown symbol `k`") && e.contains("M"),
        "{e}"
    );
    let e = with("M = 1", "\"M*\"");
    assert!(e.contains("plant.A[0][0]") && e.contains("\"M*\""), "{e}");
    let e = with("M = 1", "\"foo(M)\"");
    assert!(e.contains("unknown function `foo`") && e.contains("sqrt"), "{e}");
    let e = with("M = 0", "\"1/M\"");
    assert!(e.contains("plant.A[0][0]") && e.contains("inf"), "{e}");
    let e = with("pi = 3", "1");
    assert!(e.contains("parameters.pi") && e.contains("constant pi"), "{e}");
    let e = with("\"2M\" = 3", "1");
    assert!(e.contains("parameters.2M"), "{e}");
    let e = with("M = \"3\"", "1");
    assert!(e.contains("parameters.M") && e.contains("a number"), "{e}");
    let e = with("M = 1", "\"true\"");
    assert!(e.contains("plant.A[0][0]"), "{e}");
    // a deeply nested expression is refused by its length before the parser recurses into it
    let deep = format!("\"{}M{}\"", "(".repeat(100_000), ")".repeat(100_000));
    let e = with("M = 1", &deep);
    assert!(e.contains("plant.A[0][0]") && e.contains("limit of 500 bytes"), "{e}");
    let text =
        format!("[parameters]\nM = 1\n[plant]\nA = [[\"{}M\"]]\nB = [[0]]\nC = [[1]]\nE = [[0]]\n", "-".repeat(499));
    assert_eq!(parse_str(&text).unwrap().A[(0, 0)], -1.0, "500 bytes are allowed, an odd count of minus signs");
    // without [parameters], a symbol is unknown and the message says where to declare it
    let e = parse_str("[plant]\nA = [[\"-k\"]]\nB = [[0]]\nC = [[1]]\nE = [[0]]\n").unwrap_err().to_string();
    assert!(e.contains("unknown symbol `k`") && e.contains("[parameters]"), "{e}");
    // expressions stand only where the documentation says: not in [theta]
    let e = parse_str("[parameters]\nd = 1\n[plant]\nA = [[-1]]\nB = [[0]]\nC = [[1]]\nE = [[0]]\n[theta]\nshape = \"interval\"\nhalf_width = \"d\"\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("theta.half_width") && e.contains("a number"), "{e}");
}

#[test]
fn an_entry_written_as_an_expression_cannot_be_freed_by_itself() {
    let text = MASS_SPRING
        .replace("free = [\"M\", \"plant.A[0][1]\"]", "free = [\"plant.A[1][0]\"]")
        .replace("M = [1.0, 4.0]\n", "");
    let e = parse_str(&text).unwrap_err().to_string();
    assert!(e.contains("fit.free[0]") && e.contains("\"-k/M\"") && e.contains("free its parameters"), "{e}");
    let text =
        MASS_SPRING.replace("free = [\"M\", \"plant.A[0][1]\"]", "free = [\"mass\"]").replace("M = [1.0, 4.0]\n", "");
    let e = parse_str(&text).unwrap_err().to_string();
    assert!(e.contains("fit.free[0]") && e.contains("\"mass\"") && e.contains("parameters: M, c, g, k"), "{e}");
}
