//! Stiff plants (issue 29 item 1): `assemble` answers (a verified bound, certified or not) on
//! plants with a fast pole 1e3-1e4 times the slow ones, where the tube quadrature and the
//! Lyapunov certificate used to end in errors; with negative controls.
#![allow(non_snake_case)]
use bounds::{assemble, ThetaSettings};

/// `stiff_benchmark` seed 31337, ratio 1e3, n = 4, #0 (fast pole -625, slow -0.54 +- 1.10 i).
const RATIO_1E3: &str = r#"
name = "stiff ratio 1e3 n 4"

[plant]
A = [[804.4245244604037, -1482.5771980897339, -1085.2074027483857, -1742.7608871958914], [204.2442351158431, -381.9562973629998, -279.5368818561413, -448.83564344039917], [313.17939105952166, -575.7851721899362, -421.22160579527105, -675.4824072775235], [291.2383932627469, -533.9244943423316, -391.0857734173187, -628.46982323646]]
B = [[-0.810872672827534], [0.4998871362126194], [0.7978887546608087], [0.7182625914251841]]
C = [[0.82379117591757, 0.06293621988412268, 0.296617908173799, 0.13194075254627854]]
E = [[-0.369983046064311], [0.23172788766948327], [0.6599969672665311], [0.2439814983009967]]

[theta]
hi = 0.1
lo = -0.1
shape = "interval"

[input]
amplitudes = [21.455796763682404]
kind = "sine"
omega = 1.0
phase = 0.0

[initial]
x0 = [0.0, 0.0, 0.0, 0.0]
z0 = [0.0]

[simulation]
dt = 0.001
periods = 20
"#;

#[test]
fn a_stiff_plant_gets_a_verified_answer_not_an_error() {
    let sys = model::parse_str(RATIO_1E3).unwrap();
    let rep = assemble(&sys, &ThetaSettings::bound_only()).expect("an answer, not an error");
    assert!(rep.theta_best_verified, "the bound is verified (certified or not): {}", rep.theta_best);
    assert!(rep.d.is_finite() && rep.d > 0.0 && rep.d_ftheta.is_finite(), "d {} D {}", rep.d, rep.d_ftheta);
    assert!(rep.notes.iter().any(|n| n.contains("margin raised")), "{:?}", rep.notes);
    // Negative control: the default lambda search alone finds no certificate on this plant
    // (what the retry with a larger (ALI) margin repairs), so this test sees the change.
    let s = ThetaSettings::bound_only();
    let plain = lmi::optimise_lambda(&sys.F(), &sys.E, &sys.C, |l, b| l + b, &s.lambda);
    assert!(matches!(plain, Err(lmi::LmiError::NoCertificate { .. })), "{:?}", plain.map(|p| p.optimum.value));
}
