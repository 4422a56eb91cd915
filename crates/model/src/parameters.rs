//! `[parameters]`: named physical constants, and numbers of a model file written as
//! expressions of them, so that a model says what a machine is made of:
//!
//! ```toml
//! [parameters]
//! M = 2.0          # kg
//! c = 0.6          # N s/m
//! k = 4.0          # N/m
//! [plant]
//! A = [[0, 1], ["-k/M", "-c/M"]]
//! B = [0, "1/M"]
//! ```
//!
//! Where an expression may stand: an entry of `[plant]` `A`, `B`, `C`, `E`; of `[initial]`
//! `x0`, `z0`; a numeric key of an `[[effects]]` table (not the indices `state`,
//! `position_state`); a number of `[controller]` (gains, period, entries of `Ac`..`Dc`). Anywhere else a string is an error, as without parameters. A parameter
//! is a number (not an expression of other parameters). `[fit] free = ["M", "c"]` frees
//! parameters for a refit: every number written with them moves together, and a fitted model
//! keeps the expressions with the fitted values in `[parameters]`.
//!
//! Expressions are read by `evalexpr` with every number a float ([`as_floats`]: `evalexpr`
//! alone divides integers, `1/2*M = 0`): `+ - * / ^ %`, parentheses, `-M^2 = -(M^2)`, `1e-3`,
//! the functions [`FUNCTIONS`] and the constant `pi` (not a parameter's name). exmex was tried
//! too and reads `-M^2` as `+M^2` and rejects `1e-3`; meval reads both right but rests on a
//! parser crate that a future Rust will reject.
use crate::fit::PlantMatrix;
use crate::toml_access::describe;
use crate::ModelError;
use evalexpr::{
    ContextWithMutableFunctions, ContextWithMutableVariables, DefaultNumericTypes, EvalexprError, Function,
    HashMapContext, Value,
};
use toml::{Table, Value as Toml};

/// A number of the model file that an expression gives.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Place {
    /// Entry `(row, col)` of a plant matrix (a flat `B = [..]` is the column `col = 0`).
    Plant { matrix: PlantMatrix, row: usize, col: usize },
    /// Component `index` of `x0` (`z0` when `!x0`).
    Initial { x0: bool, index: usize },
    /// Key `key` of `[[effects]]` entry `index` (`element` of an array such as `offset`).
    Effect { index: usize, key: String, element: Option<usize> },
    /// Key `key` of `[controller]` (`element`: `(row, col)` of a matrix, `(i, 0)` of `x0`).
    Controller { key: String, element: Option<(usize, usize)> },
}

impl Place {
    /// The key path as the model file writes it, e.g. `plant.A[1][0]`, `effects[0].level`.
    pub fn key(&self) -> String {
        match self {
            Place::Plant { matrix, row, col } => format!("plant.{}[{row}][{col}]", matrix.name()),
            Place::Initial { x0, index } => format!("initial.{}[{index}]", if *x0 { "x0" } else { "z0" }),
            Place::Effect { index, key, element: None } => format!("effects[{index}].{key}"),
            Place::Effect { index, key, element: Some(e) } => format!("effects[{index}].{key}[{e}]"),
            Place::Controller { key, element: None } => format!("controller.{key}"),
            Place::Controller { key, element: Some((i, _)) } if key == "x0" => format!("controller.{key}[{i}]"),
            Place::Controller { key, element: Some((i, j)) } => format!("controller.{key}[{i}][{j}]"),
        }
    }
}

/// One expression of the file and where its value goes.
#[derive(Debug, Clone)]
pub struct Binding {
    pub place: Place,
    /// The expression as written.
    pub text: String,
    expr: evalexpr::Node<DefaultNumericTypes>,
}

/// The parameters of a model and the expressions written with them (empty: a model of plain
/// numbers).
#[derive(Debug, Clone, Default)]
pub struct Parameters {
    /// Names in the order of the file.
    pub names: Vec<String>,
    pub values: Vec<f64>,
    pub bindings: Vec<Binding>,
    /// `z0` was not stated: it follows `C x0` when a parameter moves `x0`.
    pub z0_follows_x0: bool,
}

/// Longest expression in bytes: a physical formula is short, and the expression parser
/// recurses once per nesting level (a 200 kB expression overflowed the stack; 1000 bytes of
/// the deepest forms pass with a 1 MB stack).
pub const MAX_EXPRESSION_BYTES: usize = 500;

/// Names an expression cannot use for a parameter: the constants.
const RESERVED: &[&str] = &["pi"];

/// A function of one argument an expression may call.
pub type UnaryFn = fn(f64) -> f64;

/// The functions of one argument an expression may call.
pub const FUNCTIONS: &[(&str, UnaryFn)] = &[
    ("sqrt", f64::sqrt),
    ("exp", f64::exp),
    ("ln", f64::ln),
    ("log10", f64::log10),
    ("abs", f64::abs),
    ("sin", f64::sin),
    ("cos", f64::cos),
    ("tan", f64::tan),
    ("atan", f64::atan),
    ("tanh", f64::tanh),
];

/// `text` with each integer literal written as a float (`1/2` -> `1.0/2.0`), so that
/// `evalexpr` never divides integers; other literals and names are kept.
pub fn as_floats(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len() + 8);
    let mut i = 0;
    while i < c.len() {
        let in_word = i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_' || c[i - 1] == '.');
        if !c[i].is_ascii_digit() || in_word {
            out.push(c[i]);
            i += 1;
            continue;
        }
        let start = i;
        let digits = |i: &mut usize| {
            while *i < c.len() && c[*i].is_ascii_digit() {
                *i += 1;
            }
        };
        digits(&mut i);
        let mut float = false;
        if i < c.len() && c[i] == '.' {
            float = true;
            i += 1;
            digits(&mut i);
        }
        if i < c.len() && (c[i] == 'e' || c[i] == 'E') {
            float = true;
            i += 1;
            if i < c.len() && (c[i] == '+' || c[i] == '-') {
                i += 1;
            }
            digits(&mut i);
        }
        out.extend(&c[start..i]);
        if !float {
            out.push_str(".0");
        }
    }
    out
}

/// The context of an evaluation: the parameters at `values`, [`FUNCTIONS`] and `pi`.
fn context(names: &[String], values: &[f64]) -> HashMapContext<DefaultNumericTypes> {
    let mut ctx = HashMapContext::<DefaultNumericTypes>::new();
    let mut set = |n: &str, v: f64| ctx.set_value(n.into(), Value::Float(v)).expect("a fresh context takes values");
    set("pi", std::f64::consts::PI);
    for (n, v) in names.iter().zip(values) {
        set(n, *v);
    }
    for (name, f) in FUNCTIONS {
        let f = *f;
        ctx.set_function(
            (*name).into(),
            Function::new(move |a: &Value<DefaultNumericTypes>| Ok(Value::Float(f(a.as_number()?)))),
        )
        .expect("a fresh context takes functions");
    }
    ctx
}

impl Parameters {
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The value of parameter `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.names.iter().position(|n| n == name).map(|i| self.values[i])
    }

    /// Reads `[parameters]` from `root` and replaces every expression in the places listed in
    /// the module documentation by its value (the parser then reads plain numbers).
    pub(crate) fn take_from(root: &mut Table) -> Result<Self, ModelError> {
        let mut params = Self::default();
        match root.remove("parameters") {
            None => {}
            Some(Toml::Table(t)) => {
                for (name, v) in &t {
                    let key = format!("parameters.{name}");
                    check_name(name, &key)?;
                    params.names.push(name.clone());
                    params.values.push(crate::toml_access::number(v, &key)?);
                }
            }
            Some(other) => {
                return Err(ModelError::WrongType {
                    key: "parameters".into(),
                    expected: "a table",
                    found: describe(&other),
                })
            }
        }
        params.substitute(root)?;
        Ok(params)
    }

    /// Every string in an expression place of `root` becomes its value; the bindings record
    /// them.
    fn substitute(&mut self, root: &mut Table) -> Result<(), ModelError> {
        if let Some(Toml::Table(plant)) = root.get_mut("plant") {
            for (name, matrix, column_if_flat) in [
                ("A", PlantMatrix::A, false),
                ("B", PlantMatrix::B, true),
                ("C", PlantMatrix::C, false),
                ("E", PlantMatrix::E, true),
            ] {
                let Some(Toml::Array(rows)) = plant.get_mut(name) else { continue };
                let flat = rows.iter().all(|r| !matches!(r, Toml::Array(_)));
                for (i, r) in rows.iter_mut().enumerate() {
                    match r {
                        Toml::Array(row) => {
                            for (j, v) in row.iter_mut().enumerate() {
                                self.bind(v, Place::Plant { matrix, row: i, col: j })?;
                            }
                        }
                        v if flat => {
                            let (row, col) = if column_if_flat { (i, 0) } else { (0, i) };
                            self.bind(v, Place::Plant { matrix, row, col })?;
                        }
                        _ => {}
                    }
                }
            }
        }
        let mut z0_stated = false;
        if let Some(Toml::Table(init)) = root.get_mut("initial") {
            z0_stated = init.contains_key("z0");
            for (name, x0) in [("x0", true), ("z0", false)] {
                match init.get_mut(name) {
                    Some(Toml::Array(a)) => {
                        for (index, v) in a.iter_mut().enumerate() {
                            self.bind(v, Place::Initial { x0, index })?;
                        }
                    }
                    Some(v) => self.bind(v, Place::Initial { x0, index: 0 })?,
                    None => {}
                }
            }
        }
        self.z0_follows_x0 = !z0_stated;
        if let Some(Toml::Array(items)) = root.get_mut("effects") {
            for (index, it) in items.iter_mut().enumerate() {
                let Toml::Table(t) = it else { continue };
                for (key, v) in t.iter_mut() {
                    if matches!(key.as_str(), "kind" | "location" | "state" | "position_state") {
                        continue;
                    }
                    match v {
                        Toml::Array(a) => {
                            for (e, x) in a.iter_mut().enumerate() {
                                self.bind(x, Place::Effect { index, key: key.clone(), element: Some(e) })?;
                            }
                        }
                        _ => self.bind(v, Place::Effect { index, key: key.clone(), element: None })?,
                    }
                }
            }
        }
        if let Some(Toml::Table(t)) = root.get_mut("controller") {
            for (key, v) in t.iter_mut() {
                if key == "kind" {
                    continue;
                }
                match v {
                    Toml::Array(rows) => {
                        let flat = rows.iter().all(|r| !matches!(r, Toml::Array(_)));
                        for (i, r) in rows.iter_mut().enumerate() {
                            match r {
                                Toml::Array(row) => {
                                    for (j, x) in row.iter_mut().enumerate() {
                                        self.bind(x, Place::Controller { key: key.clone(), element: Some((i, j)) })?;
                                    }
                                }
                                x if flat => {
                                    // a flat array: x0 (component i) or a one-row matrix
                                    let e = if key == "x0" { (i, 0) } else { (0, i) };
                                    self.bind(x, Place::Controller { key: key.clone(), element: Some(e) })?;
                                }
                                _ => {}
                            }
                        }
                    }
                    _ => self.bind(v, Place::Controller { key: key.clone(), element: None })?,
                }
            }
        }
        Ok(())
    }

    /// A string at `place` is an expression: replaced by its value and recorded.
    fn bind(&mut self, v: &mut Toml, place: Place) -> Result<(), ModelError> {
        let Toml::String(text) = v else { return Ok(()) };
        let key = place.key();
        if text.len() > MAX_EXPRESSION_BYTES {
            return Err(ModelError::TooLong { key, bytes: text.len(), limit: MAX_EXPRESSION_BYTES });
        }
        let expr = evalexpr::build_operator_tree::<DefaultNumericTypes>(&as_floats(text))
            .map_err(|e| ModelError::Expression { key: key.clone(), text: text.clone(), reason: e.to_string() })?;
        let binding = Binding { place, text: text.clone(), expr };
        let x = self.evaluate_in(&binding, &context(&self.names, &self.values))?;
        *v = Toml::Float(x);
        self.bindings.push(binding);
        Ok(())
    }

    /// The value of `b`'s expression with the parameters at `values`; an unknown symbol, a
    /// non-finite or out-of-range result is an error naming key and expression.
    pub fn evaluate(&self, b: &Binding, values: &[f64]) -> Result<f64, ModelError> {
        self.evaluate_in(b, &context(&self.names, values))
    }

    fn evaluate_in(&self, b: &Binding, ctx: &HashMapContext<DefaultNumericTypes>) -> Result<f64, ModelError> {
        let key = b.place.key();
        let x = b.expr.eval_number_with_context(ctx).map_err(|e| {
            let reason = match e {
                EvalexprError::VariableIdentifierNotFound(s) => format!(
                    "unknown symbol `{s}` (parameters: {})",
                    if self.names.is_empty() {
                        "none; declare it in [parameters]".into()
                    } else {
                        self.names.join(", ")
                    }
                ),
                EvalexprError::FunctionIdentifierNotFound(s) => format!(
                    "unknown function `{s}` (functions: {})",
                    FUNCTIONS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                ),
                other => other.to_string(),
            };
            ModelError::Expression { key: key.clone(), text: b.text.clone(), reason }
        })?;
        if !x.is_finite() || x.abs() > crate::MAX_MAGNITUDE {
            return Err(ModelError::Expression {
                key,
                text: b.text.clone(),
                reason: format!("evaluates to {x}, not a finite number of magnitude <= {:e}", crate::MAX_MAGNITUDE),
            });
        }
        Ok(x)
    }

    /// The value of every binding with the parameters `set` (name, value) changed and the
    /// others unchanged, in the order of [`Parameters::bindings`]; `self` is updated only when
    /// every expression evaluates.
    pub(crate) fn values_with(&mut self, set: &[(&str, f64)]) -> Result<Vec<f64>, ModelError> {
        let mut values = self.values.clone();
        for (name, v) in set {
            let i = self
                .names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| ModelError::UnknownParameter { name: name.to_string(), known: self.names.join(", ") })?;
            values[i] = *v;
        }
        let ctx = context(&self.names, &values);
        let out = self.bindings.iter().map(|b| self.evaluate_in(b, &ctx)).collect::<Result<Vec<_>, _>>()?;
        self.values = values;
        Ok(out)
    }

    /// Whether `name` can name a parameter: letters, digits and `_`, starting with a letter or
    /// `_` (the sweep's `parameters.NAME` axes use the same rule).
    pub fn is_name(name: &str) -> bool {
        let mut chars = name.chars();
        chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
    }

    /// The expression of `place`, if one gives it.
    pub fn binding_at(&self, place: &Place) -> Option<&Binding> {
        self.bindings.iter().find(|b| &b.place == place)
    }

    /// `[parameters]` for the writer.
    pub(crate) fn to_table(&self) -> Option<Table> {
        (!self.is_empty())
            .then(|| self.names.iter().zip(&self.values).map(|(n, v)| (n.clone(), Toml::Float(*v))).collect())
    }
}

fn check_name(name: &str, key: &str) -> Result<(), ModelError> {
    if !Parameters::is_name(name) {
        return Err(ModelError::WrongType {
            key: key.into(),
            expected: "a parameter name of letters, digits and '_' starting with a letter",
            found: format!("{name:?}"),
        });
    }
    if RESERVED.contains(&name) {
        return Err(ModelError::WrongType {
            key: key.into(),
            expected: "a name other than the constant pi",
            found: format!("{name:?}"),
        });
    }
    Ok(())
}
