#![allow(non_snake_case)]
//! Timing probe of the parts of `driver::theta::assemble` (development aid).
use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).expect("model file");
    let sys = model::load(std::path::Path::new(&path)).unwrap();
    let F = sys.F();
    let t0 = Instant::now();
    let k = driver::tube::TubeKernel::new(
        &sys.C,
        &F,
        &sys.E,
        &sys.theta,
        driver::tube::Horizon::Infinite,
        &Default::default(),
    )
    .unwrap();
    println!(
        "tube: {} cells, h {:.3e}, S {:.1}, tail {:.2e}, rem {:.2e}, lip {:.3}, {:?}",
        k.cells(),
        k.h,
        k.s_max,
        k.tail_bound(),
        k.remainder_bound(),
        k.lipschitz(),
        t0.elapsed()
    );
    let mut evals = 0;
    let t1 = Instant::now();
    let b = geometry::sphere_max(
        sys.p(),
        |v| {
            evals += 1;
            k.support_upper(v)
        },
        k.lipschitz(),
        &geometry::SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20000 },
    );
    println!("sphere_max: {b:?} evals {evals} {:?}", t1.elapsed());
    let t2 = Instant::now();
    let mut s = driver::theta::ThetaSettings::bound_only();
    s.measure = None;
    let r = driver::theta::assemble(&sys, &s).unwrap();
    println!("assemble bound-only {:?} theta {}", t2.elapsed(), r.theta);
}
