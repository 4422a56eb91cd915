//! theta of eq. (theta) from Rust in about ten lines: the worked example of NOTES.md built in
//! code, the certified bound and every labelled quantity.
//!
//! `cargo run --release -p bounds --example theta_in_ten_lines`
use bounds::{assemble, ThetaSettings};
use geometry::{Interval, Shape};
use model::{Input, System};
use nalgebra::dmatrix;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sys = System::builder()
        .A(dmatrix![0.0, 1.0; -2.0, -0.6])
        .B(dmatrix![0.0; 1.0])
        .C(dmatrix![1.0, 0.0])
        .E(dmatrix![0.0; 1.0])
        .theta(Shape::Interval(Interval::symmetric(0.1)?))
        .input(Input::Sine { amplitudes: vec![1.0], omega: 1.0, phase: 0.0 })
        .build()?;
    let report = assemble(&sys, &ThetaSettings::default())?;
    for q in report.quantities() {
        println!(
            "{:<30} {:<16} {:>12.6}  {:<12} verified: {}",
            q.symbol,
            q.label,
            q.value,
            q.kind.as_str(),
            q.verified
        );
    }
    println!(
        "theta = {:.6} (verified: {}), converges: {}",
        report.theta, report.theta_verified, report.convergence_guaranteed
    );
    Ok(())
}
