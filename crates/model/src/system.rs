//! The validated closed-loop system of eqs. (xy), (yz).
use crate::controller::Controller;
use crate::effects::Effects;
use crate::error::ModelError;
use crate::fit::{FitSpec, FreeParam, FreeTarget, PlantMatrix};
use crate::input::Input;
use crate::parameters::{Parameters, Place};
use crate::signals::Signals;
use geometry::{ConvexSet, Shape};
use nalgebra::{Complex, DMatrix, DVector};

/// Simulation defaults stored in a model file (`[simulation]`).
#[derive(Debug, Clone, PartialEq)]
pub struct SimDefaults {
    /// Time step `h` of the catching-up scheme. Default `1e-3`.
    pub dt: f64,
    /// Number of input periods to simulate (periodic inputs). Default `20`.
    pub periods: usize,
    /// Final time for non-periodic inputs. Default: the last sample time, or `100`.
    pub t_end: Option<f64>,
}

impl Default for SimDefaults {
    fn default() -> Self {
        Self { dt: 1e-3, periods: 20, t_end: None }
    }
}

/// `x' = A x + B w + E z`, `y = C x`, `z in y + Theta` (eqs. (xy), (yz)) with input, initial
/// state and simulation defaults. Construct through [`System::builder`] (named fields, so `B`
/// and `E` cannot be swapped silently) or a model file ([`crate::load`]); both validate
/// everything.
///
/// ```
/// use geometry::{Interval, Shape};
/// use model::{Input, System};
/// use nalgebra::dmatrix;
///
/// let sys = System::builder()
///     .A(dmatrix![0.0, 1.0; -2.0, -0.6])
///     .B(dmatrix![0.0; 1.0])
///     .C(dmatrix![1.0, 0.0])
///     .E(dmatrix![0.0; 1.0])
///     .theta(Shape::Interval(Interval::symmetric(0.1).unwrap()))
///     .input(Input::Sine { amplitudes: vec![1.0], omega: 1.0, phase: 0.0 })
///     .build()
///     .unwrap();
/// assert_eq!((sys.n(), sys.m(), sys.p()), (2, 1, 1));
/// // F = A + E C, eq. (F): mu = -0.3
/// assert!((sys.mu() + 0.3).abs() < 1e-12);
/// // a missing matrix is an error naming it, never a panic
/// assert!(System::builder().A(dmatrix![-1.0]).build().is_err());
/// ```
#[derive(Debug, Clone)]
pub struct System {
    pub name: String,
    pub A: DMatrix<f64>,
    pub B: DMatrix<f64>,
    pub C: DMatrix<f64>,
    pub E: DMatrix<f64>,
    /// Backlash set `Theta` (the singleton `{0}` when absent: the linearised system).
    pub theta: Shape,
    pub input: Input,
    pub x0: DVector<f64>,
    pub z0: DVector<f64>,
    pub sim: SimDefaults,
    pub effects: Effects,
    /// `[fit]`: nominal parameters freed for a grey-box refit by `moreau diagnose` (empty:
    /// the nominal is taken as known).
    pub fit: FitSpec,
    /// `[signals]`: units of the recorded signals, for reports (empty: unitless).
    pub signals: Signals,
    /// `[parameters]`: named constants and the numbers above written as expressions of them
    /// (empty: plain numbers). Change one with [`System::set_parameter`].
    pub parameters: Parameters,
    /// `[controller]`: a digital controller closing the loop (`None`: `w` drives the plant
    /// directly). With one, `w` is the controller's reference and `B` takes its output.
    pub controller: Option<Controller>,
}

fn dim_err(key: &str, expected: String, got: &DMatrix<f64>) -> ModelError {
    ModelError::Dimension { key: key.into(), expected, got: format!("{}x{}", got.nrows(), got.ncols()) }
}

/// Named-field construction of a [`System`]; see [`System::builder`]. Required: `A`, `B`, `C`,
/// `E`. Defaults: name `""`, `Theta = {0}` (the linear system), input zero, `x0 = 0`,
/// `z0 = C x0`, [`SimDefaults::default`], no effects.
#[derive(Debug, Clone, Default)]
pub struct SystemBuilder {
    name: String,
    A: Option<DMatrix<f64>>,
    B: Option<DMatrix<f64>>,
    C: Option<DMatrix<f64>>,
    E: Option<DMatrix<f64>>,
    theta: Option<Shape>,
    input: Option<Input>,
    x0: Option<DVector<f64>>,
    z0: Option<DVector<f64>>,
    sim: SimDefaults,
    effects: Effects,
}

impl SystemBuilder {
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }
    /// Plant matrix `A` (`n x n`).
    pub fn A(mut self, A: DMatrix<f64>) -> Self {
        self.A = Some(A);
        self
    }
    /// Input matrix `B` (`n x m`).
    pub fn B(mut self, B: DMatrix<f64>) -> Self {
        self.B = Some(B);
        self
    }
    /// Output matrix `C` (`p x n`).
    pub fn C(mut self, C: DMatrix<f64>) -> Self {
        self.C = Some(C);
        self
    }
    /// Backlash feedback matrix `E` (`n x p`).
    pub fn E(mut self, E: DMatrix<f64>) -> Self {
        self.E = Some(E);
        self
    }
    /// The backlash set `Theta` (eq. (yz)).
    pub fn theta(mut self, theta: Shape) -> Self {
        self.theta = Some(theta);
        self
    }
    pub fn input(mut self, input: Input) -> Self {
        self.input = Some(input);
        self
    }
    pub fn x0(mut self, x0: DVector<f64>) -> Self {
        self.x0 = Some(x0);
        self
    }
    pub fn z0(mut self, z0: DVector<f64>) -> Self {
        self.z0 = Some(z0);
        self
    }
    pub fn sim(mut self, sim: SimDefaults) -> Self {
        self.sim = sim;
        self
    }
    pub fn effects(mut self, effects: Effects) -> Self {
        self.effects = effects;
        self
    }
    /// Validates (see [`System`]) and builds.
    pub fn build(self) -> Result<System, ModelError> {
        let missing = |key: &str| ModelError::Missing { key: format!("plant.{key}") };
        let A = self.A.ok_or_else(|| missing("A"))?;
        let B = self.B.ok_or_else(|| missing("B"))?;
        let C = self.C.ok_or_else(|| missing("C"))?;
        let E = self.E.ok_or_else(|| missing("E"))?;
        let (n, m, p) = (A.nrows(), B.ncols(), C.nrows());
        let theta = self.theta.unwrap_or_else(|| Shape::origin(p));
        let input = self.input.unwrap_or(Input::Zero { m });
        let x0 = self.x0.unwrap_or_else(|| DVector::zeros(n));
        let z0 = match self.z0 {
            Some(z0) => z0,
            None if C.ncols() == x0.len() => &C * &x0,
            None => DVector::zeros(p),
        };
        System::validated(self.name, A, B, C, E, theta, input, x0, z0, self.sim, self.effects)
    }
}

/// Fewest steps per input period accepted by [`check_step`]: with fewer, a sine is sampled
/// at too few phases (with `dt = T` or `T/2` at its zeros only) and every result is wrong.
pub const MIN_STEPS_PER_PERIOD: f64 = 4.0;

/// Checks a time step against the input period and the final time: at least
/// [`MIN_STEPS_PER_PERIOD`] steps per period, and no step longer than `t_end`. `key` names
/// the setting in the error (`simulation.dt`, `--dt`).
pub fn check_step(dt: f64, period: Option<f64>, t_end: Option<f64>, key: &str) -> Result<(), ModelError> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(ModelError::Invalid { key: key.into(), value: dt, reason: "must be positive and finite".into() });
    }
    if let Some(T) = period {
        let limit = T / MIN_STEPS_PER_PERIOD;
        if dt > limit * (1.0 + 1e-12) {
            return Err(ModelError::Invalid {
                key: key.into(),
                value: dt,
                reason: format!(
                    "the step must be at most T/{MIN_STEPS_PER_PERIOD} = {limit} (input period T = {T}); a coarser step samples the input at too few phases"
                ),
            });
        }
    }
    if let Some(te) = t_end {
        if dt > te {
            return Err(ModelError::Invalid {
                key: key.into(),
                value: dt,
                reason: format!("the step is longer than the final time t_end = {te}"),
            });
        }
    }
    Ok(())
}

/// The plant's dimensions `(n, p)`: `A` square, `B` with `n` rows, `C` with `n` columns, `E`
/// `n x p`, every entry finite.
fn plant_dimensions(
    A: &DMatrix<f64>,
    B: &DMatrix<f64>,
    C: &DMatrix<f64>,
    E: &DMatrix<f64>,
) -> Result<(usize, usize), ModelError> {
    let n = A.nrows();
    if A.ncols() != n || n == 0 {
        return Err(dim_err("plant.A", "a square n x n matrix".into(), A));
    }
    if B.nrows() != n {
        return Err(dim_err("plant.B", format!("{n} rows (n)"), B));
    }
    if C.ncols() != n {
        return Err(dim_err("plant.C", format!("{n} columns (n)"), C));
    }
    let p = C.nrows();
    if E.nrows() != n || E.ncols() != p {
        return Err(dim_err("plant.E", format!("{n}x{p} (n x p)"), E));
    }
    for (k, m) in [("plant.A", A), ("plant.B", B), ("plant.C", C), ("plant.E", E)] {
        if let Some(&value) = m.iter().find(|x| !x.is_finite()) {
            return Err(ModelError::NotFinite { key: k.into(), value });
        }
    }
    Ok((n, p))
}

/// `Theta` in R^p, the input with `m` (columns of `B`) components, `x0` in R^n, `z0` in R^p.
fn initial_dimensions(
    theta: &Shape,
    input: &Input,
    m: usize,
    x0: &DVector<f64>,
    z0: &DVector<f64>,
    n: usize,
    p: usize,
) -> Result<(), ModelError> {
    if theta.dim() != p {
        return Err(ModelError::Dimension {
            key: "theta".into(),
            expected: format!("a set in R^{p} (p = rows of C)"),
            got: format!("a set in R^{}", theta.dim()),
        });
    }
    if input.m() != m {
        return Err(ModelError::Dimension {
            key: "input".into(),
            expected: format!("m = {m} components (columns of B)"),
            got: format!("{}", input.m()),
        });
    }
    ModelError::check_length("initial.x0", x0.len(), "n", n)?;
    ModelError::check_length("initial.z0", z0.len(), "p", p)?;
    Ok(())
}

/// `Theta` contains 0 (to `1e-12` relative) and `z0 - C x0` (to `1e-9` relative); each error
/// gives the distance.
fn theta_holds_initial(
    theta: &Shape,
    C: &DMatrix<f64>,
    x0: &DVector<f64>,
    z0: &DVector<f64>,
) -> Result<(), ModelError> {
    let scale = 1.0 + theta.deviation_from_origin().upper;
    let zero = vec![0.0; C.nrows()];
    if !theta.contains(&zero, 1e-12 * scale) {
        let proj = geometry::convex_set::project_vec(theta, &zero);
        return Err(ModelError::ThetaMissesOrigin { distance: geometry::linalg::norm(&proj), theta: theta.describe() });
    }
    let q0: Vec<f64> = (z0 - C * x0).iter().copied().collect();
    let tol = 1e-9 * (scale + geometry::linalg::norm(&q0));
    if !theta.contains(&q0, tol) {
        let proj = geometry::convex_set::project_vec(theta, &q0);
        return Err(ModelError::InitialOutsideTheta { distance: geometry::linalg::dist(&q0, &proj), q0 });
    }
    Ok(())
}

/// The simulation defaults: a positive finite step, at least one period.
fn sim_checked(sim: &SimDefaults) -> Result<(), ModelError> {
    if !(sim.dt > 0.0 && sim.dt.is_finite()) {
        return Err(ModelError::OutOfRange {
            key: "simulation.dt".into(),
            value: sim.dt,
            reason: "must be positive and finite",
        });
    }
    if sim.periods == 0 {
        return Err(ModelError::OutOfRange {
            key: "simulation.periods".into(),
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    Ok(())
}

impl System {
    /// Named-field construction ([`SystemBuilder`]).
    pub fn builder() -> SystemBuilder {
        SystemBuilder::default()
    }

    /// Builds and validates: dimensions of `A (n x n), B (n x m), C (p x n), E (n x p)`,
    /// `Theta` in R^p containing 0, `x0 in R^n`, `z0 - C x0 in Theta` (to `1e-9` relative),
    /// finiteness, `m` of the input equal to the columns of `B`.
    pub(crate) fn validated(
        name: impl Into<String>,
        A: DMatrix<f64>,
        B: DMatrix<f64>,
        C: DMatrix<f64>,
        E: DMatrix<f64>,
        theta: Shape,
        input: Input,
        x0: DVector<f64>,
        z0: DVector<f64>,
        sim: SimDefaults,
        effects: Effects,
    ) -> Result<Self, ModelError> {
        let (n, p) = plant_dimensions(&A, &B, &C, &E)?;
        initial_dimensions(&theta, &input, B.ncols(), &x0, &z0, n, p)?;
        theta_holds_initial(&theta, &C, &x0, &z0)?;
        sim_checked(&sim)?;
        Ok(Self {
            name: name.into(),
            A,
            B,
            C,
            E,
            theta,
            input,
            x0,
            z0,
            sim,
            effects,
            fit: Default::default(),
            signals: Default::default(),
            parameters: Default::default(),
            controller: None,
        })
    }

    /// State dimension `n`.
    pub fn n(&self) -> usize {
        self.A.nrows()
    }
    /// Input dimension `m`.
    pub fn m(&self) -> usize {
        self.B.ncols()
    }
    /// Output / backlash dimension `p`.
    pub fn p(&self) -> usize {
        self.C.nrows()
    }
    /// `F = A + E C`, the matrix of the linearised system, eq. (F).
    pub fn F(&self) -> DMatrix<f64> {
        &self.A + &self.E * &self.C
    }
    /// Eigenvalues of `F`, sorted by real part (descending).
    pub fn eig_F(&self) -> Vec<Complex<f64>> {
        let mut ev: Vec<Complex<f64>> = self.F().complex_eigenvalues().iter().copied().collect();
        ev.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
        ev
    }
    /// Spectral abscissa `mu = max Re eig(F)`, eq. (stab) (floating-point estimate; the `lmi`
    /// crate certifies Hurwitz stability).
    pub fn mu(&self) -> f64 {
        self.eig_F().iter().map(|c| c.re).fold(f64::NEG_INFINITY, f64::max)
    }
    /// The period of the input, if periodic.
    pub fn period(&self) -> Option<f64> {
        self.input.period()
    }
    /// Copy with another input (e.g. a different amplitude in a sweep).
    pub fn with_input(&self, input: Input) -> Self {
        Self { input, ..self.clone() }
    }
    /// The plant matrix `which` (`A`, `B`, `C` or `E`).
    pub fn plant_matrix(&self, which: PlantMatrix) -> &DMatrix<f64> {
        match which {
            PlantMatrix::A => &self.A,
            PlantMatrix::B => &self.B,
            PlantMatrix::C => &self.C,
            PlantMatrix::E => &self.E,
        }
    }
    /// The plant matrix `which`, mutable.
    pub fn plant_matrix_mut(&mut self, which: PlantMatrix) -> &mut DMatrix<f64> {
        match which {
            PlantMatrix::A => &mut self.A,
            PlantMatrix::B => &mut self.B,
            PlantMatrix::C => &mut self.C,
            PlantMatrix::E => &mut self.E,
        }
    }
}

/// Parameters of `[parameters]` in a system.
impl System {
    /// Sets parameter `name` to `v` and every number written as an expression of it (plant
    /// entries, initial state, effect keys; `z0 = C x0` where `z0` was not stated). On an error
    /// (an unknown name, an expression that does not evaluate, an effect key out of its range)
    /// the system is unchanged.
    pub fn set_parameter(&mut self, name: &str, v: f64) -> Result<(), ModelError> {
        self.set_parameters(&[(name, v)])
    }

    /// [`System::set_parameter`] for several parameters at once (one evaluation of the
    /// expressions).
    pub fn set_parameters(&mut self, set: &[(&str, f64)]) -> Result<(), ModelError> {
        let mut params = self.parameters.clone();
        let values = params.values_with(set)?;
        let mut next = self.clone();
        let mut effects: Vec<(usize, &str, Option<usize>, f64)> = Vec::new();
        for (b, x) in params.bindings.iter().zip(values) {
            match &b.place {
                Place::Plant { matrix, row, col } => next.plant_matrix_mut(*matrix)[(*row, *col)] = x,
                Place::Initial { x0: true, index } => next.x0[*index] = x,
                Place::Initial { x0: false, index } => next.z0[*index] = x,
                Place::Effect { index, key, element } => effects.push((*index, key, *element, x)),
                Place::Controller { key, element } => {
                    let (m, p) = (next.m(), next.p());
                    if let Some(c) = next.controller.as_ref() {
                        next.controller = Some(c.with_number(key, *element, x, m, p)?);
                    }
                }
            }
        }
        if params.z0_follows_x0 && params.bindings.iter().any(|b| matches!(b.place, Place::Initial { x0: true, .. })) {
            next.z0 = &next.C * &next.x0;
        }
        for (index, key, element, x) in effects {
            let prefix = format!("effects[{index}]");
            let e = next.effects.list[index].with_number(&prefix, key, element, x, next.n(), next.p())?;
            next.effects.list[index] = e;
        }
        next.parameters = params;
        *self = next;
        Ok(())
    }
}

/// A freed parameter ([`crate::fit`]) read and written in a system.
impl FreeParam {
    /// The parameter's value in `sys`.
    pub fn get(&self, sys: &System) -> f64 {
        match self.target {
            FreeTarget::Entry { matrix, row, col } => sys.plant_matrix(matrix)[(row, col)],
            FreeTarget::Parameter => sys.parameters.value(&self.name).unwrap_or(f64::NAN),
        }
    }
    /// Sets the parameter in `sys` (a named parameter moves every expression written with
    /// it; an error leaves `sys` unchanged).
    pub fn set(&self, sys: &mut System, v: f64) -> Result<(), ModelError> {
        match self.target {
            FreeTarget::Entry { matrix, row, col } => {
                sys.plant_matrix_mut(matrix)[(row, col)] = v;
                Ok(())
            }
            FreeTarget::Parameter => sys.set_parameter(&self.name, v),
        }
    }
}
