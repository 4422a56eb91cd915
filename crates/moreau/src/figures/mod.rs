//! Figures for papers (SVG and PNG with an embedded DejaVu font, and pgfplots code + CSV data
//! that LaTeX sets in the paper's own fonts, [`pgf`]; labelled axes):
//! - [`psi`]: Fig. psi1, `psi(gamma)` of eq. (phipsi) with `psi(0)`, `psi(gamma_inf)`, the
//!   limit `-lambda` and the chord whose value at `gamma_1` is `theta` (eq. (theta));
//! - [`tube`]: Fig. loop, the orbit `eta_T` (eq. (etaT)), the tube `eta_T + C Xi_inf + Theta`
//!   (eqs. (Xinfsupp), (d)) and the simulated periodic `z`;
//! - [`trajectory`]: `y` and `z` (and the states) of a simulation against time, and the plot
//!   of `moreau simulate` ([`trajectory::simulation_figure`]);
//! - [`sweep`]: theta and the measured rate against a swept parameter;
//! - [`diagnosis`]: measured vs nominal vs fitted, residuals and zooms of `moreau diagnose`.
//!
//! Every figure is a [`canvas::Figure`] (data only) rendered by [`canvas::write_figure`] (or
//! [`canvas::to_svg`], [`canvas::write_png`]); [`fonts`] embeds the DejaVu font in all of them;
//! [`tex_symbols`] is the one table of TeX's Greek letters and symbols both directions use.
pub mod canvas;
pub mod diagnosis;
pub mod fonts;
pub mod pgf;
pub mod psi;
pub mod sweep;
pub mod tex_symbols;
pub mod trajectory;
pub mod tube;

pub use canvas::{to_pdf, to_png_at_dpi, write_figure, write_figure_as, write_figure_with, Element, Figure, Format};

use thiserror::Error;

/// Why a figure could not be drawn.
#[derive(Debug, Error)]
pub enum FigureError {
    #[error("figure `{figure}`: nothing finite to draw")]
    NoData { figure: String },
    #[error("figure `{figure}`: drawing failed: {reason}")]
    Draw { figure: String, reason: String },
    #[error("cannot write {path}: {reason}")]
    Write { path: std::path::PathBuf, reason: String },
    #[error("theta: {0}")]
    Driver(#[from] bounds::BoundsError),
    #[error("simulation: {0}")]
    Dynamics(#[from] dynamics::DynamicsError),
    #[error("the sweep has no axis `{name}` (axes: {known})")]
    UnknownAxis { name: String, known: String },
    #[error("the sweep has no numeric column `{name}` (columns: {known})")]
    UnknownColumn { name: String, known: String },
    #[error("the model's input has no period: `{kind}` (the figure needs a periodic input)")]
    NoPeriod { kind: &'static str },
}
