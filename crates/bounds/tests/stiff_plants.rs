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

/// `assemble_memo` (one `BetaMemo` over a plant's reports) gives the reports `assemble` gives,
/// bit for bit, and solves fewer SDPs: at another amplitude (what the guidance and an amplitude
/// sweep ask) every lambda of the grid is answered from the memo.
#[test]
fn the_memo_changes_no_report_and_saves_the_solves() {
    use bounds::{assemble_memo, Memo};
    let sys = model::parse_str(RATIO_1E3).unwrap();
    let mut louder = sys.clone();
    louder.input.wave_mut().expect("a sine").0[0] *= 3.0;
    let s = ThetaSettings::bound_only();
    let mut memo = Memo::new();
    let json = |r: &bounds::ThetaReport| serde_json::to_string(r).unwrap();
    let first = assemble_memo(&sys, &s, &mut memo).unwrap();
    let solves_first = memo.beta.solves();
    assert_eq!(json(&first), json(&assemble(&sys, &s).unwrap()));
    let second = assemble_memo(&louder, &s, &mut memo).unwrap();
    assert_eq!(json(&second), json(&assemble(&louder, &s).unwrap()));
    let solves_second = memo.beta.solves() - solves_first;
    assert!(memo.beta.hits() >= 12, "the grid of the second report comes from the memo: {} hits", memo.beta.hits());
    assert!(solves_second < solves_first, "{solves_second} solves for the second report, {solves_first} for the first");
    // negative control: the reports differ (the amplitude matters), only their SDPs are shared
    assert_ne!(first.theta_best, second.theta_best);
}
