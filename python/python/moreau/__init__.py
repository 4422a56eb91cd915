"""moreau: convergence to periodic regimes with a strongly convex backlash, from Python.

Bindings of the Rust workspace (the same numbers as the ``moreau`` command):

>>> import numpy as np, moreau
>>> sys = moreau.System(np.array([[0.0, 1.0], [-2.0, -0.6]]), [[0.0], [1.0]], [[1.0, 0.0]], [[0.0], [1.0]],
...                     theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0))
>>> rep = moreau.theta(sys)            # `moreau theta FILE --json`: a dict, keys also attributes
>>> rep.theta_best, rep["theta_verified"]  # doctest: +SKIP
(-0.2067..., True)

Every error is a :class:`MoreauError` (a ``ValueError``) carrying the one-line message the
command prints after ``error:``.
"""
from ._native import MoreauError, __version__
from ._model import (
    Ball,
    BallIntersection,
    Box,
    Ellipsoid,
    Input,
    Interval,
    Multisine,
    Point,
    Polytope,
    Samples,
    Set,
    Sine,
    Square,
    System,
    Zero,
    load,
)
from ._commands import (
    CheckResult,
    Diagnosis,
    SweepResult,
    Trajectory,
    check,
    diagnose,
    figure,
    periodic,
    set_allow_large,
    simulate,
    sweep,
    sweep_grid,
    theta,
)
from ._results import PeriodicResult, Result, ThetaResult

__all__ = [
    "MoreauError",
    "__version__",
    "Set",
    "Interval",
    "Ball",
    "Ellipsoid",
    "BallIntersection",
    "Polytope",
    "Box",
    "Point",
    "Input",
    "Multisine",
    "Sine",
    "Square",
    "Zero",
    "Samples",
    "System",
    "load",
    "theta",
    "simulate",
    "periodic",
    "check",
    "diagnose",
    "sweep",
    "sweep_grid",
    "figure",
    "set_allow_large",
    "Result",
    "ThetaResult",
    "PeriodicResult",
    "Trajectory",
    "CheckResult",
    "Diagnosis",
    "SweepResult",
]
