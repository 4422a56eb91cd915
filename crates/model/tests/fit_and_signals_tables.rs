//! `[fit]` (grey-box refit: freed nominal parameters, bounds, recorded results) and
//! `[signals]` (units) in model files: parsed, validated with errors naming key and value,
//! and written back by `to_toml_string`.
use model::model_file::{FreeTarget, PlantMatrix};

const BASE: &str = "name = \"servo\"\n[plant]\nA = [[0.0, 1.0], [-2.0, -0.6]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n";

fn parse(extra: &str) -> Result<model::System, String> {
    model::parse_str(&format!("{BASE}{extra}")).map_err(|e| e.to_string())
}

#[test]
fn free_parameters_bounds_and_units_are_read_and_written_back() {
    let sys = parse(
        "[fit]\nfree = [\"plant.A[1][1]\", \"plant.B[1][0]\"]\n[fit.bounds]\n\"plant.A[1][1]\" = [-10, 0]\n[signals]\ny = \"m\"\nw = [\"V\"]\nt = \"s\"\nreference = \"w1\"\n",
    )
    .unwrap();
    assert_eq!(sys.fit.free.len(), 2);
    let a11 = &sys.fit.free[0];
    assert_eq!(a11.name, "plant.A[1][1]");
    assert_eq!(a11.target, FreeTarget::Entry { matrix: PlantMatrix::A, row: 1, col: 1 });
    assert_eq!(a11.bounds, Some((-10.0, 0.0)));
    assert_eq!(a11.get(&sys), -0.6);
    assert_eq!(sys.fit.free[1].bounds, None);
    assert_eq!(sys.fit.free[1].get(&sys), 1.0);
    assert_eq!(sys.signals.y_unit(0), "m");
    assert_eq!(sys.signals.w_unit(0), "V");
    assert_eq!((sys.signals.t.as_str(), sys.signals.y_common_unit()), ("s", "m"));
    assert_eq!(sys.signals.reference, vec![0]);
    // Round trip, with a recorded result.
    let mut s2 = sys.clone();
    s2.fit.result.push(model::model_file::FitRecord {
        name: "plant.A[1][1]".into(),
        nominal: -0.6,
        value: -0.45,
        std: 0.003,
        correlation: vec![("plant.B[1][0]".into(), -0.875)],
    });
    s2.fit.result.push(model::model_file::FitRecord {
        name: "plant.B[1][0]".into(),
        nominal: 1.0,
        value: 1.2,
        std: f64::NAN,
        correlation: vec![],
    });
    let text = model::to_toml_string(&s2);
    let back = model::parse_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(back.fit.free, s2.fit.free);
    assert_eq!(back.fit.result[0], s2.fit.result[0]);
    assert!(back.fit.result[1].std.is_nan(), "a NaN uncertainty is left out, not written as nan");
    assert_eq!(back.signals, s2.signals);
    // Without the tables nothing is written.
    let plain = parse("").unwrap();
    let t = model::to_toml_string(&plain);
    assert!(!t.contains("[fit") && !t.contains("[signals"), "{t}");
}

#[test]
fn bad_fit_tables_name_key_and_value() {
    let cases = [
        ("[fit]\nfree = [\"plant.Q[1][1]\"]\n", &["fit.free[0]", "plant.Q[1][1]"][..]),
        ("[fit]\nfree = [\"plant.A[1]\"]\n", &["fit.free[0]", "plant.A[1]"]),
        ("[fit]\nfree = [\"plant.A[0][0]\", \"plant.A[2][0]\"]\n", &["fit.free[1]", "plant.A[2][0]", "2x2"]),
        ("[fit]\nfree = [\"plant.B[1][1]\"]\n", &["fit.free[0]", "plant.B[1][1]", "2x1"]),
        ("[fit]\nfree = [\"plant.A[1][1]\", \"plant.A[1][1]\"]\n", &["fit.free[1]", "at most once"]),
        ("[fit]\nfree = [1.5]\n", &["fit.free[0]", "float 1.5"]),
        (
            "[fit]\nfree = [\"plant.A[1][1]\"]\n[fit.bounds]\n\"plant.A[1][1]\" = [0, -10]\n",
            &["fit.bounds", "plant.A[1][1]", "lower bound 0", "upper bound -10"],
        ),
        (
            "[fit]\nfree = [\"plant.A[1][1]\"]\n[fit.bounds]\n\"plant.A[1][1]\" = [0, 10]\n",
            &["fit.bounds", "outside the bounds", "-0.6"],
        ),
        (
            "[fit]\nfree = [\"plant.A[1][1]\"]\n[fit.bounds]\n\"plant.A[0][1]\" = [0, 10]\n",
            &["fit.bounds", "plant.A[0][1]", "listed in fit.free"],
        ),
        ("[fit]\nfree = [\"plant.A[1][1]\"]\n[fit.bounds]\n\"plant.A[1][1]\" = [-1]\n", &["fit.bounds", "length 1"]),
        ("[fit]\nfree = [\"plant.A[1][1]\"]\nstart = 3\n", &["fit.start", "unknown key"]),
        (
            "[fit]\nfree = [\"plant.A[1][1]\", \"plant.B[1][0]\"]\n[fit.result.\"plant.A[1][1]\"]\nnominal = -0.6\nvalue = -0.5\ncorrelation = { \"plant.B[1][0]\" = 1.5 }\n",
            &["correlation", "plant.B[1][0]", "1.5", "[-1, 1]"],
        ),
        (
            "[fit]\nfree = [\"plant.A[1][1]\"]\n[fit.result.\"plant.A[1][1]\"]\nnominal = -0.6\nvalue = -0.5\ncorrelation = { \"plant.A[0][0]\" = 0.5 }\n",
            &["correlation", "plant.A[0][0]", "listed in fit.free"],
        ),
        ("[signals]\ny = [\"m\", \"rad\"]\n", &["signals.y", "one unit per output (1)", "length 2"]),
        ("[signals]\ny = 3\n", &["signals.y", "integer 3"]),
        ("[signals]\nz = \"m\"\n", &["signals.z", "unknown key"]),
        ("[signals]\nt = 1\n", &["signals.t", "integer 1"]),
        ("[signals]\nreference = \"w2\"\n", &["signals.reference", "w2", "1 input"]),
        ("[signals]\nreference = \"y1\"\n", &["signals.reference", "y1"]),
    ];
    for (extra, needles) in cases {
        let e = parse(extra).expect_err(extra);
        for n in needles {
            assert!(e.contains(n), "{extra:?}: error {e:?} lacks {n:?}");
        }
    }
    // Negative control: the same tables, well formed, load.
    assert!(parse("[fit]\nfree = [\"plant.E[1][0]\", \"plant.C[0][1]\"]\n[fit.bounds]\n\"plant.E[1][0]\" = [-1, 1]\n")
        .is_ok());
}
