//! The loop closed by a digital controller (`[controller]`) against an independent reference:
//! the cascade written out by hand (no state-space form), the plant integrated by classical
//! Runge-Kutta on a grid 500 times finer than the ticks.
use dynamics::extended::ExtendedModel;

/// Mass `M` with viscous friction `c` driven by a force `u / M`; cascade `kp`, `kv`, `ki`,
/// velocity filter `tau`, computation delay `d` ticks, `sub` samples per tick.
fn model_text(d: usize, period: f64, tau: f64) -> String {
    format!(
        r#"
[parameters]
M = 1.5
c = 4.0
[plant]
A = [[0, 1], [0, "-c/M"]]
B = [0, "1/M"]
C = [[1, 0]]
E = [0, 0]
[controller]
period = {period}
delay = {d}
kind = "cascade"
kp = 40
kv = 300
ki = 2000
velocity_filter = {tau}
"#
    )
}

/// The reference: the cascade by hand, RK4 with `fine` steps per sample of `dt`.
fn reference(w: &[f64], dt: f64, ratio: usize, d: usize, tau: f64, fine: usize) -> Vec<f64> {
    let (m, c, kp, kv, ki) = (1.5, 4.0, 40.0, 300.0, 2000.0);
    let period = dt * ratio as f64;
    let a = if tau > 0.0 { (-period / tau).exp() } else { 0.0 };
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let (mut yp, mut vf, mut integ) = (0.0, 0.0, 0.0);
    let mut issued: Vec<f64> = Vec::new();
    let mut force = 0.0;
    let mut y = Vec::new();
    for (k, &wk) in w.iter().enumerate() {
        y.push(x);
        if k % ratio == 0 {
            let vhat = (x - yp) / period;
            vf = a * vf + (1.0 - a) * vhat;
            yp = x;
            let ev = kp * (wk - x) - vf;
            issued.push(kv * ev + ki * integ);
            integ += period * ev;
            let j = issued.len() - 1;
            force = if j >= d { issued[j - d] } else { 0.0 };
        }
        let h = dt / fine as f64;
        let f = |_x: f64, v: f64| (v, (force - c * v) / m);
        for _ in 0..fine {
            let (k1x, k1v) = f(x, v);
            let (k2x, k2v) = f(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
            let (k3x, k3v) = f(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
            let (k4x, k4v) = f(x + h * k3x, v + h * k3v);
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
    }
    y
}

fn reference_signal(ns: usize, dt: f64) -> Vec<f64> {
    (0..ns).map(|k| k as f64 * dt).map(|t| 0.01 * (t * 9.0).sin() + 0.004 * (t * 31.0).sin().signum()).collect()
}

fn max_rel_err(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn the_sampled_cascade_matches_a_fine_step_reference() {
    let dt = 1e-3;
    let ns = 1500;
    let w = reference_signal(ns, dt);
    for (d, ratio, tau) in [(1, 1, 0.0), (0, 1, 3e-4), (2, 2, 0.0)] {
        let sys = model::parse_str(&model_text(d, dt * ratio as f64, tau)).unwrap();
        let ext = ExtendedModel::new(&sys, &[], dt, 3).unwrap();
        assert!(ext.has_controller());
        let out = ext.simulate(&w, dt, &[0.0, 0.0]);
        assert!(out.finite);
        let yref = reference(&w, dt, ratio, d, tau, 500);
        let err = max_rel_err(&out.y, &yref);
        eprintln!("delay {d}, ratio {ratio}, filter {tau}: max relative error {err:e}");
        // exact between ticks: only rounding and the reference's RK4 error remain
        assert!(err < 1e-9, "delay {d}, ratio {ratio}: {err:e}");
        // negative control: one tick of computation delay more is seen
        let off = reference(&w, dt, ratio, d + 1, tau, 500);
        assert!(max_rel_err(&out.y, &off) > 1e-3, "delay {d}: the harness cannot tell a delay");
    }
}

#[test]
fn a_period_off_the_sample_grid_is_an_error_naming_both() {
    let sys = model::parse_str(&model_text(1, 1.5e-3, 0.0)).unwrap();
    let msg = ExtendedModel::new(&sys, &[], 1e-3, 1).unwrap_err().to_string();
    assert!(msg.contains("controller.period = 0.0015") && msg.contains("dt = 0.001"), "{msg}");
    // negative control: a multiple of the spacing compiles
    assert!(ExtendedModel::new(&sys, &[], 5e-4, 1).is_ok());
}

#[test]
fn coulomb_friction_inside_the_ticks_converges_with_the_substeps() {
    let dt = 1e-3;
    let text = model_text(1, dt, 0.0) + "[[effects]]\nkind = \"coulomb_friction\"\nstate = 1\nlevel = 0.3\n";
    let sys = model::parse_str(&text).unwrap();
    let w = reference_signal(1500, dt);
    let run = |sub: usize| ExtendedModel::new(&sys, &[], dt, sub).unwrap().simulate(&w, dt, &[0.0, 0.0]).y;
    let (y4, y8, y64) = (run(4), run(8), run(64));
    let (e4, e8) = (max_rel_err(&y4, &y64), max_rel_err(&y8, &y64));
    eprintln!("Coulomb in the loop: 4 sub-steps {e4:e}, 8 sub-steps {e8:e} from 64");
    assert!(e8 < e4 && e8 < 1e-2, "{e4:e} {e8:e}");
    // the friction acts: without it the run differs
    let free = ExtendedModel::new(&model::parse_str(&model_text(1, dt, 0.0)).unwrap(), &[], dt, 8)
        .unwrap()
        .simulate(&w, dt, &[0.0, 0.0])
        .y;
    assert!(max_rel_err(&free, &y64) > 10.0 * e8);
}

#[test]
fn the_closed_loop_decay_rate_is_that_of_the_simulation() {
    // Free response from x0 = (1 mm, 0) with w = 0: the envelope decays at the rate mu.
    let dt = 1e-3;
    let sys = model::parse_str(&model_text(1, dt, 0.0)).unwrap();
    let mu = dynamics::extended::closed_loop_mu(&sys).unwrap();
    assert!(mu < 0.0, "{mu}");
    let ns = 4000;
    let y = ExtendedModel::new(&sys, &[], dt, 1).unwrap().simulate(&vec![0.0; ns], dt, &[1e-3, 0.0]).y;
    let peak = |a: usize, b: usize| y[a..b].iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let rate = (peak(3000, 3500) / peak(1000, 1500)).ln() / 2.0;
    eprintln!("closed-loop mu {mu}, measured decay {rate}");
    assert!((rate / mu - 1.0).abs() < 0.1, "{rate} against {mu}");
    // negative control: a loop made unstable by a large velocity gain has mu > 0
    let hot = model::parse_str(&model_text(1, dt, 0.0).replace("kv = 300", "kv = 3000")).unwrap();
    assert!(dynamics::extended::closed_loop_mu(&hot).unwrap() > 0.0);
    // no controller: none
    let plain = model::parse_str(model_text(1, dt, 0.0).split("[controller]").next().unwrap()).unwrap();
    assert!(dynamics::extended::closed_loop_mu(&plain).is_none());
}
