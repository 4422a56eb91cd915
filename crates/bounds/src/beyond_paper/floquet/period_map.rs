//! The period map as a square system (multiple shooting over the phases) and the Krawczyk test
//! that proves it has exactly one zero in a box.
//!
//! Unknowns `u = (x_0, z_0, h_0, .., h_{k-1})` (`N = n + 1 + k`): the state at the section and
//! the durations of all phases but the last (`h_k = T - sum h_j`, `T = 2 pi / omega`). With
//! `X_0 = (x_0, z_0, s_0, c_0, 1)` (exact exosystem state at the section) and `X_{j+1} =
//! e^{h_j G_j} X_j` ([`super::flow`]), the equations are
//! ```text
//! switch j (1..=k):  l_j . X_j = c_j      release: l = y'-row of the engaged phase, c = 0
//!                                         contact: l = q-row (q = z - C x),        c = face
//! periodicity:       X_{k+1}[0..n+1] = (x_0, z_0)
//! ```
//! Its Jacobian by the chain rule (`dX_{j+1} = e^{h_j G_j} dX_j + G_j X_{j+1} dh_j`, and
//! `dh_k = -sum dh_j`), all in interval arithmetic over a box.
//!
//! Krawczyk (Moore's form): for a box `U` with centre `u^`, a point matrix `Y ~ J(u^)^{-1}`,
//! `K(U) = u^ - Y f(u^) + (I - Y J(U)) (U - u^)`. If `K(U)` lies in the interior of `U`, then
//! `f` has exactly one zero in `U`, and it lies in `K(U)`; if `K(U)` and `U` are disjoint, `f`
//! has no zero in `U` (both: Krawczyk 1969, Moore 1977, Neumaier 1990 Thm 5.1.7/5.1.8).
use super::flow::{dot, Generators, PhaseKind};
use super::imat::IMat;
use rounding::interval::PI;
use rounding::Ival;

/// The shooting system of one phase sequence.
#[derive(Debug, Clone)]
pub struct Shooting<'a> {
    pub gens: &'a Generators,
    pub kinds: Vec<PhaseKind>,
    /// Exact `(sin, cos)` of the input phase at the section.
    pub section_sc: (f64, f64),
    /// `T = 2 pi / omega`, enclosed.
    pub T: Ival,
}

/// `f` and (optionally) `J` over a box, with the states and phase flows that produced them.
#[derive(Debug, Clone)]
pub struct Evaluation {
    pub f: Vec<Ival>,
    pub J: Option<IMat>,
    /// `X_0 .. X_{k+1}` (dimension `n + 4` each).
    pub states: Vec<IMat>,
    /// `e^{h_j G_j}` enclosed, `j = 0..=k`.
    pub flows: Vec<IMat>,
    /// `h_0 .. h_k`.
    pub durations: Vec<Ival>,
}

/// How a switch is crossed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum SwitchKind {
    /// Engaged -> resting: `y'` reaches `0`.
    Release,
    /// Resting -> engaged: `q` reaches the face.
    Contact,
}

/// The kind of switch from `a` to `b`, `None` for an impossible pair (two resting or two
/// engaged phases in a row).
pub fn switch_kind(a: PhaseKind, b: PhaseKind) -> Option<SwitchKind> {
    match (a, b) {
        (PhaseKind::Engaged(_), PhaseKind::Resting) => Some(SwitchKind::Release),
        (PhaseKind::Resting, PhaseKind::Engaged(_)) => Some(SwitchKind::Contact),
        _ => None,
    }
}

/// The Krawczyk test's verdict on a box.
#[derive(Debug, Clone, PartialEq)]
pub enum KrawczykVerdict {
    /// `K(U)` inside the interior of `U`: exactly one zero in `U`, and it lies in the box given.
    Unique(Vec<Ival>),
    /// `K(U)` and `U` disjoint in some coordinate: no zero in `U`.
    NoZero { coordinate: usize },
    /// Neither.
    Inconclusive,
}

impl<'a> Shooting<'a> {
    pub fn new(gens: &'a Generators, kinds: Vec<PhaseKind>, section_sc: (f64, f64)) -> Self {
        let T = PI.scale(2.0).div(Ival::point(gens.omega));
        Self { gens, kinds, section_sc, T }
    }
    pub fn switches(&self) -> usize {
        self.kinds.len() - 1
    }
    /// `N = n + 1 + k`.
    pub fn unknowns(&self) -> usize {
        self.gens.n + 1 + self.switches()
    }
    /// The event row and constant of switch `j` (`1..=k`).
    fn event(&self, j: usize) -> Option<(Vec<Ival>, Ival)> {
        let (a, b) = (self.kinds[j - 1], self.kinds[j]);
        match (switch_kind(a, b)?, a, b) {
            (SwitchKind::Release, PhaseKind::Engaged(_), _) => Some((self.gens.ydot_row(a), Ival::point(0.0))),
            (SwitchKind::Contact, _, PhaseKind::Engaged(f)) => Some((self.gens.q_row(), self.gens.face_value(f))),
            _ => None,
        }
    }

    /// `f(U)` and, with `jacobian`, `J(U)`; `None` for an impossible phase sequence.
    pub fn evaluate(&self, u: &[Ival], jacobian: bool) -> Option<Evaluation> {
        let g = self.gens;
        let (n, dim, k) = (g.n, g.dim, self.switches());
        let N = self.unknowns();
        if self.kinds.len() < 3 || self.kinds[0] != self.kinds[k] || u.len() != N {
            return None;
        }
        let mut X0 = IMat::zeros(dim, 1);
        X0.d[..=n].copy_from_slice(&u[..=n]);
        X0.d[n + 1] = Ival::point(self.section_sc.0);
        X0.d[n + 2] = Ival::point(self.section_sc.1);
        X0.d[n + 3] = Ival::point(1.0);
        let mut durations: Vec<Ival> = u[n + 1..].to_vec();
        let last = durations.iter().fold(self.T, |s, h| s.sub(*h));
        durations.push(last);
        let mut D = IMat::zeros(dim, N);
        for i in 0..=n {
            D.set(i, i, Ival::point(1.0));
        }
        let mut states = vec![X0];
        let mut flows = Vec::with_capacity(k + 1);
        let mut f = Vec::with_capacity(N);
        let mut J = IMat::zeros(N, N);
        for j in 0..=k {
            let kind = self.kinds[j];
            let Ej = g.flow(kind, durations[j]);
            let Xn = Ej.mul(&states[j]);
            if jacobian {
                let GX = g.generator(kind).mul(&Xn);
                let mut Dn = Ej.mul(&D);
                let hcols: Vec<(usize, f64)> =
                    if j < k { vec![(n + 1 + j, 1.0)] } else { (0..k).map(|i| (n + 1 + i, -1.0)).collect() };
                for (col, sgn) in hcols {
                    for r in 0..dim {
                        Dn.set(r, col, Dn.at(r, col).add(GX.at(r, 0).scale(sgn)));
                    }
                }
                D = Dn;
            }
            flows.push(Ej);
            states.push(Xn);
            if j < k {
                let (row, c) = self.event(j + 1)?;
                f.push(dot(&row, &states[j + 1]).sub(c));
                if jacobian {
                    for col in 0..N {
                        let v = (0..dim).fold(Ival::point(0.0), |s, r| s.add(row[r].mul(D.at(r, col))));
                        J.set(j, col, v);
                    }
                }
            }
        }
        let Xe = &states[k + 1];
        for i in 0..=n {
            f.push(Xe.d[i].sub(u[i]));
            if jacobian {
                for col in 0..N {
                    let v = D.at(i, col).sub(Ival::point(if col == i { 1.0 } else { 0.0 }));
                    J.set(k + i, col, v);
                }
            }
        }
        Some(Evaluation { f, J: jacobian.then_some(J), states, flows, durations })
    }

    /// Newton's method from a guess (floating point, not a proof): the midpoints of the
    /// enclosed `f` and `J` at points. `None` when it does not converge or a duration turns
    /// non-positive.
    pub fn newton(&self, u0: &[f64], max_iter: usize) -> Option<Vec<f64>> {
        let mut u = u0.to_vec();
        let N = u.len();
        for _ in 0..max_iter {
            let ev = self.evaluate(&u.iter().map(|v| Ival::point(*v)).collect::<Vec<_>>(), true)?;
            let J = ev.J?.mid();
            if !J.iter().all(|v| v.is_finite()) {
                return None;
            }
            let f = nalgebra::DVector::from_iterator(N, ev.f.iter().map(|v| v.mid()));
            let step = J.lu().solve(&f)?;
            let mut size = 0.0f64;
            for i in 0..N {
                u[i] -= step[i];
                size = size.max(step[i].abs() / (1.0 + u[i].abs()));
            }
            if !u.iter().all(|v| v.is_finite()) {
                return None;
            }
            if size < 1e-15 {
                break;
            }
        }
        let ev = self.evaluate(&u.iter().map(|v| Ival::point(*v)).collect::<Vec<_>>(), false)?;
        // converged: the midpoint residual small against the state's scale (the enclosure's
        // width is the flows' error, judged by the Krawczyk test, not here)
        let scale = 1.0 + u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let ok = ev.durations.iter().all(|h| h.lo > 0.0) && ev.f.iter().all(|v| v.mid().abs() < 1e-9 * scale);
        ok.then_some(u)
    }

    /// The Krawczyk test on the box `u^ +- r`.
    pub fn krawczyk(&self, uhat: &[f64], r: &[f64]) -> Option<KrawczykVerdict> {
        let N = uhat.len();
        let point: Vec<Ival> = uhat.iter().map(|v| Ival::point(*v)).collect();
        let at_centre = self.evaluate(&point, true)?;
        let Y = at_centre.J.as_ref()?.mid().try_inverse()?;
        let U: Vec<Ival> = uhat.iter().zip(r).map(|(c, rr)| Ival::mid_rad(*c, *rr)).collect();
        let over = self.evaluate(&U, true)?;
        let Yi = IMat::from_f64(&Y);
        let Yf = Yi.mul(&IMat::column(&at_centre.f));
        let M = IMat::identity(N).sub(&Yi.mul(over.J.as_ref()?));
        let dU = IMat::column(&U.iter().zip(uhat).map(|(u, c)| u.sub(Ival::point(*c))).collect::<Vec<_>>());
        let MdU = M.mul(&dU);
        let K: Vec<Ival> = (0..N).map(|i| point[i].sub(Yf.d[i]).add(MdU.d[i])).collect();
        if !K.iter().all(|v| v.is_valid()) {
            return Some(KrawczykVerdict::Inconclusive);
        }
        if let Some(i) = (0..N).find(|&i| K[i].intersect(&U[i]).is_none()) {
            return Some(KrawczykVerdict::NoZero { coordinate: i });
        }
        if (0..N).all(|i| K[i].interior_of(&U[i])) {
            Some(KrawczykVerdict::Unique(K))
        } else {
            Some(KrawczykVerdict::Inconclusive)
        }
    }
}
