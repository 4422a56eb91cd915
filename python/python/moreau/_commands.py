"""The commands of the ``moreau`` CLI as functions: each takes a :class:`System` or the path of a
model file and returns what the command prints with ``--json`` (as a dict), or numpy arrays.
Long computations release the GIL."""
from __future__ import annotations

import io
import json
import os
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _native
from ._model import PathLike, System, _native_model
from ._native import MoreauError

Model = Union[System, PathLike]

__all__ = [
    "theta",
    "simulate",
    "periodic",
    "check",
    "diagnose",
    "sweep",
    "set_allow_large",
    "Trajectory",
    "CheckResult",
    "Diagnosis",
    "SweepResult",
]


def _count(name: str, v: Any) -> int:
    """A whole count (``periods``, ``pairs``) as an int: ``periods=2.5`` is refused naming the
    argument (the CLI's ``--periods`` takes whole numbers), ``3.0`` is 3."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer, float, np.floating)):
        raise TypeError(f"`{name}` must be a whole number, got {type(v).__name__}")
    if isinstance(v, (float, np.floating)) and not float(v).is_integer():
        raise MoreauError(f"`{name}` = {v}: must be a whole number")
    return int(v)


def _f64(b: bytes, shape: Any) -> np.ndarray:
    return np.frombuffer(b, dtype="<f8").reshape(shape).copy()


def theta(model: Model, *, measure: bool = True, stationary: bool = True, guidance: bool = True) -> Dict[str, Any]:
    """The bound theta of eq. (theta) with every quantity: ``moreau theta FILE --json``.

    Returns the command's JSON object as a dict, with exactly its keys (``theta``,
    ``theta_verified``, ``theta_best``, ``measured_rate``, ``quantities``, ...). As in the CLI,
    a ``guidance`` key (design guidance: which term blocks, sensitivities, smallest
    certifying amplitude) is added only when nothing is certified; ``guidance=False`` is
    ``--no-guidance``. ``measure=False`` is ``--no-measure`` (no simulated pairs),
    ``stationary=False`` is ``--no-stationary``.
    """
    return json.loads(_native.theta(_native_model(model), measure=measure, stationary=stationary, guidance=guidance))


class Trajectory(Dict[str, np.ndarray]):
    """Samples of a simulation: ``t`` (N,), ``w`` (N, m), ``x`` (N, n), ``y`` (N, p), ``z`` (N, p)
    and ``q = z - y`` (N, p); ``method`` says how it was simulated, ``h`` the step."""

    method: str
    h: float


def simulate(
    model: Model,
    t_end: Optional[float] = None,
    dt: Optional[float] = None,
    *,
    periods: Optional[int] = None,
    integrator: str = "catching-up",
    max_rows: Optional[int] = None,
) -> Trajectory:
    """Simulates the closed loop as ``moreau simulate FILE`` does, returning the samples.

    Periodic inputs run ``periods`` periods (default: the model's ``simulation.periods``) at
    the step ``T / ceil(T / dt)``; ``t_end`` instead runs to that time (for any input; for
    non-periodic inputs the default is ``simulation.t_end``, else 100). ``dt`` defaults to
    ``simulation.dt``. ``integrator`` is ``"catching-up"`` (any Theta; the extended-model
    simulator for models with effects) or ``"event"`` (the event-driven reference).
    ``max_rows`` keeps every k-th step (default: every step).
    """
    n, m, p, method, h, cols = _native.simulate(
        _native_model(model),
        periods=None if periods is None else _count("periods", periods),
        dt=dt,
        t_end=t_end,
        integrator=integrator,
        max_rows=max_rows,
    )
    t = _f64(cols["t"], (-1,))
    k = len(t)
    out = Trajectory(
        t=t,
        w=_f64(cols["w"], (k, m)),
        x=_f64(cols["x"], (k, n)),
        y=_f64(cols["y"], (k, p)),
        z=_f64(cols["z"], (k, p)),
        q=_f64(cols["q"], (k, p)),
    )
    out.method = method
    out.h = h
    return out


def periodic(model: Model, *, dt: Optional[float] = None, periods: int = 60, pairs: int = 3) -> Dict[str, Any]:
    """The periodic regime (Poincare fixed point, residual, (loc) check) and the measured
    convergence exponent: ``moreau periodic FILE --json`` (same keys)."""
    return json.loads(
        _native.periodic(_native_model(model), dt=dt, periods=_count("periods", periods), pairs=_count("pairs", pairs))
    )


class CheckResult(Dict[str, Any]):
    """``moreau check --json``'s object (``seed``, ``variant``, ``results``); ``passed`` is
    False where the command exits with status 1 (a violated claim, or a negative control
    that produced no counterexample)."""

    passed: bool


def check(
    only: Optional[str] = None,
    cases: Optional[int] = None,
    seed: int = 0,
    *,
    negative_control: bool = False,
    out: Optional[PathLike] = None,
) -> CheckResult:
    """The property campaign over the results of the paper: ``moreau check --json``.

    ``only`` selects one property by name (``lemma_a2``) or equation label (``lem1:2``);
    ``cases`` per property (default: each property's own); deterministic given ``seed`` and
    ``cases``. Counterexample files are written to ``out`` only when it is given.
    """
    text, bad = _native.check(
        only=only,
        cases=cases,
        seed=seed,
        negative_control=negative_control,
        out=None if out is None else os.fspath(out),
    )
    r = CheckResult(json.loads(text))
    r.passed = not bad
    return r


class Diagnosis(Dict[str, Any]):
    """``report.json`` of ``moreau diagnose`` as a dict; ``fitted_model`` is the refitted
    :class:`System` (None if none), ``series`` the curves of its figures: ``t`` (N,),
    ``y``, ``yhat_nominal``, ``yhat_fitted`` (N, p)."""

    fitted_model: Optional[System]
    series: Dict[str, np.ndarray]


def _recording_text(model: Model, rec: Any) -> str:
    """CSV text of a pandas DataFrame (its column names) or of an array whose columns are
    ``t, w1..wm, y1..yp`` and optionally ``z1..zp`` (m and p from the model)."""
    if hasattr(rec, "to_csv") and hasattr(rec, "columns"):
        return str(rec.to_csv(index=False))
    if rec is None:
        raise TypeError("`recording` is missing (None): expected a path, CSV text, a DataFrame or an array")
    a0 = np.asarray(rec)
    if np.iscomplexobj(a0):
        raise TypeError(f"`recording` is complex (dtype {a0.dtype}): recordings are real; the imaginary part would be dropped")
    a = a0.astype(float)
    if a.ndim != 2:
        raise MoreauError(f"recording: expected a 2-D array (samples x columns t, w, y), got shape {a.shape}")
    sysm = model if isinstance(model, System) else System.load(model)
    m, p = sysm.m, sysm.p
    if a.shape[1] == 1 + m + p:
        names = ["t"] + [f"w{i + 1}" for i in range(m)] + [f"y{i + 1}" for i in range(p)]
    elif a.shape[1] == 1 + m + 2 * p:
        names = ["t"] + [f"w{i + 1}" for i in range(m)] + [f"y{i + 1}" for i in range(p)] + [f"z{i + 1}" for i in range(p)]
    else:
        raise MoreauError(
            f"recording: {a.shape[1]} columns, expected 1 + m + p = {1 + m + p} (t, w1..w{m}, y1..y{p}) "
            f"or 1 + m + 2p = {1 + m + 2 * p} (with z1..z{p}) for this model"
        )
    buf = io.StringIO()
    np.savetxt(buf, a, delimiter=",", fmt="%.17g", header=",".join(names), comments="")
    return buf.getvalue()


def diagnose(
    model: Model,
    recording: Any,
    *,
    estimation_fraction: float = 0.7,
    max_effects: int = 2,
    input_hold: str = "auto",
    estimate_x0: bool = False,
    out: Optional[PathLike] = None,
) -> Diagnosis:
    """Compares a model with a recording, locates the mismatch, names the missing physics,
    refits and validates: ``moreau diagnose --model M --data R``.

    ``recording`` is the path of a CSV file (header ``t,w,y`` or ``t,w1..wm,y1..yp``,
    optional ``z``), a pandas DataFrame with those columns, or a 2-D array with columns
    ``t, w1..wm, y1..yp[, z1..zp]``. ``input_hold`` is ``"auto"``, ``"zoh"`` or ``"foh"``
    (the input between samples); an initial state the model states (``[initial] x0``, or
    ``x0=`` of :class:`System`) is taken as known unless ``estimate_x0``. ``out`` writes the
    CLI's report directory (report.md, report.json, fitted.toml, figures).
    """
    nm = _native_model(model)
    kw: Dict[str, Any] = dict(
        estimation_fraction=estimation_fraction,
        max_effects=max_effects,
        input_hold=input_hold,
        estimate_x0=estimate_x0,
        out=None if out is None else os.fspath(out),
    )
    if isinstance(recording, (str, os.PathLike)):
        text, fitted, p, cols = _native.diagnose(nm, data=os.fspath(recording), **kw)
    else:
        source = "<DataFrame>" if hasattr(recording, "to_csv") else "<array>"
        text, fitted, p, cols = _native.diagnose(nm, text=_recording_text(model, recording), source_name=source, **kw)
    d = Diagnosis(json.loads(text))
    d.fitted_model = None if fitted is None else System._wrap(fitted)
    t = _f64(cols["t"], (-1,))
    d.series = {"t": t}
    for k in ("y", "yhat_nominal", "yhat_fitted"):
        d.series[k] = _f64(cols[k], (len(t), max(p, 1)))
    return d


class SweepResult(Dict[str, Any]):
    """``sweep.json`` of ``moreau sweep`` as a dict; ``table`` maps every axis parameter and
    column name to a numpy array over the points (NaN where a point failed), ``files`` are
    the tables written, ``complete`` is False where a point failed (exit status 1)."""

    files: List[str]
    complete: bool

    @property
    def table(self) -> Dict[str, np.ndarray]:
        pts = self["points"]
        out: Dict[str, np.ndarray] = {}
        for i, ax in enumerate(self["axes"]):
            out[ax["parameter"]] = np.array([_num(pt["params"][i]) for pt in pts], dtype=float)
        for j, col in enumerate(self["columns"]):
            vals = [pt["values"][j] if pt.get("values") else None for pt in pts]
            kind = col.get("kind")
            if kind == "flag":
                out[col["name"]] = np.array([None if v is None else bool(v) for v in vals], dtype=object if None in vals else bool)
            elif kind == "text":
                out[col["name"]] = np.array(vals, dtype=object)
            else:
                out[col["name"]] = np.array([_num(v) for v in vals], dtype=float)
        out["status"] = np.array([pt.get("status") for pt in pts], dtype=object)
        return out


def _num(v: Any) -> float:
    if v is None:
        return float("nan")
    if isinstance(v, str):
        return float({"NaN": "nan"}.get(v, v))
    return float(v)


def sweep(
    spec: PathLike,
    out: PathLike,
    *,
    shard: Optional[str] = None,
    threads: Optional[int] = None,
    digits: Optional[int] = None,
    overwrite: bool = False,
    fresh: bool = False,
    retry_failed: bool = False,
) -> SweepResult:
    """A parameter sweep from a spec file: ``moreau sweep SPEC --out DIR --quiet`` (the same
    command: resumable, ``shard="K/N"``, tables in CSV, JSON, Markdown and LaTeX in ``out``)."""
    text, files, ok = _native.sweep(
        os.fspath(spec),
        os.fspath(out),
        shard=shard,
        threads=threads,
        digits=digits,
        overwrite=overwrite,
        fresh=fresh,
        retry_failed=retry_failed,
    )
    r = SweepResult(json.loads(text))
    r.files = [os.fspath(f) for f in files]
    r.complete = ok
    return r


def set_allow_large(on: bool = True) -> None:
    """The CLI's ``--allow-large`` for every later call: lifts the soft work limits
    (integration steps, stored samples, check cases, sweep points, theta's n and p)."""
    _native.set_allow_large(on)
