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
from ._results import PeriodicResult, Result, ThetaResult, _fmt

Model = Union[System, PathLike]

__all__ = [
    "theta",
    "simulate",
    "periodic",
    "check",
    "diagnose",
    "sweep",
    "sweep_grid",
    "figure",
    "set_allow_large",
    "Trajectory",
    "ThetaResult",
    "PeriodicResult",
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


def theta(
    model: Model, *, measure: bool = True, stationary: bool = True, guidance: bool = True, step_check: bool = False
) -> ThetaResult:
    """The bound theta of eq. (theta) with every quantity: ``moreau theta FILE --json``.

    Parameters
    ----------
    model : System or path-like
        The system, or the path of a model file.
    measure : bool, default True
        Measure the exponent by simulation (``False`` is ``--no-measure``).
    stationary : bool, default True
        Certify the stationary point (``False`` is ``--no-stationary``).
    guidance : bool, default True
        Add design guidance when nothing is certified (``False`` is ``--no-guidance``).
    step_check : bool, default False
        Measure again at a half and a quarter of the step, and at the quarter with a 100 times
        smaller separation, and widen the measured intervals by the changes (``--step-check``;
        eleven times the measurement's work).

    Returns
    -------
    ThetaResult
        The command's JSON object (a dict with exactly its keys, also attributes):
        ``theta_best``, ``theta_best_verified``, ``theta_best_method``, ``theta``,
        ``theta_verified``, ``measured_rate``, ``measured_rate_ci``, ``quantities``, ...; a
        ``guidance`` key only when nothing is certified.

    Raises
    ------
    MoreauError
        Bad model (dimensions, F not Hurwitz, Theta not containing 0, ...), with the CLI's
        one-line message.
    """
    return ThetaResult(
        json.loads(_native.theta(
            _native_model(model), measure=measure, stationary=stationary, guidance=guidance, step_check=step_check
        ))
    )


class Trajectory(Dict[str, np.ndarray]):
    """Samples of a simulation: ``t`` (N,), ``w`` (N, m), ``x`` (N, n), ``y`` (N, p), ``z`` (N, p)
    and ``q = z - y`` (N, p), also as attributes (``tr.y``); ``method`` says how it was
    simulated, ``h`` the step."""

    method: str
    h: float

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("__"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"Trajectory has no column or attribute {name!r} (columns: {', '.join(self)})") from None

    def to_dict(self) -> Dict[str, np.ndarray]:
        """The columns as a plain dict of numpy arrays (copies).

        Returns
        -------
        dict of str to numpy.ndarray
            ``t``, ``w``, ``x``, ``y``, ``z``, ``q``.
        """
        return {k: v.copy() for k, v in self.items()}

    def __repr__(self) -> str:
        t = self["t"]
        span = f"t = {_fmt(t[0])} .. {_fmt(t[-1])}" if len(t) else "empty"
        return f"Trajectory({len(t)} samples, {span}, h = {_fmt(getattr(self, 'h', None))}, {getattr(self, 'method', '?')})"


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

    Parameters
    ----------
    model : System or path-like
        The system, or the path of a model file.
    t_end : float, optional
        Run to this time (any input; default for non-periodic inputs: ``simulation.t_end``,
        else 100).
    dt : float, optional
        Step (default ``simulation.dt``; periodic inputs use ``T / ceil(T / dt)``).
    periods : int, optional
        Periods of a periodic input (default ``simulation.periods``).
    integrator : {"catching-up", "event"}, default "catching-up"
        The catching-up scheme (any Theta; the extended-model simulator for models with
        effects) or the event-driven reference.
    max_rows : int, optional
        Keep every k-th step so that at most this many rows remain (default: every step).

    Returns
    -------
    Trajectory
        ``t`` (N,), ``w`` (N, m), ``x`` (N, n), ``y`` (N, p), ``z`` (N, p), ``q`` (N, p);
        ``method`` and ``h``.
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


def periodic(model: Model, *, dt: Optional[float] = None, periods: int = 60, pairs: int = 3) -> PeriodicResult:
    """The periodic regime and the measured convergence exponent: ``moreau periodic FILE --json``.

    Parameters
    ----------
    model : System or path-like
        The system, or the path of a model file.
    dt : float, optional
        Step (default ``simulation.dt``).
    periods : int, default 60
        Periods simulated per pair of trajectories.
    pairs : int, default 3
        Pairs of trajectories whose distance measures the exponent.

    Returns
    -------
    PeriodicResult
        The command's JSON object: ``periodic_regime`` (Poincare fixed point, residual),
        ``rate`` (``exponent``, ``ci95``, per-pair values), ``localisation`` ((loc) check),
        ``path_length_per_period``, ...
    """
    return PeriodicResult(
        json.loads(
            _native.periodic(_native_model(model), dt=dt, periods=_count("periods", periods), pairs=_count("pairs", pairs))
        )
    )


class CheckResult(Result):
    """``moreau check --json``'s object (``seed``, ``variant``, ``results``); ``passed`` is
    False where the command exits with status 1 (a violated claim, or a negative control
    that produced no counterexample)."""

    passed: bool

    def _parts(self) -> List[str]:
        res = self.get("results", [])
        viol = sum(int(r.get("violations") or 0) for r in res)
        return [f"passed={getattr(self, 'passed', '?')}", f"{len(res)} properties", f"{viol} violations", f"variant={self.get('variant')}"]


def check(
    only: Optional[str] = None,
    cases: Optional[int] = None,
    seed: int = 0,
    *,
    negative_control: bool = False,
    out: Optional[PathLike] = None,
) -> CheckResult:
    """The property campaign over the results of the paper: ``moreau check --json``.

    Parameters
    ----------
    only : str, optional
        One property by name (``"lemma_a2"``) or equation label (``"lem1:2"``); default all.
    cases : int, optional
        Cases per property (default: each property's own).
    seed : int, default 0
        Seed; the campaign is deterministic given ``seed`` and ``cases``.
    negative_control : bool, default False
        Run the negative controls (each must produce a counterexample).
    out : path-like, optional
        Folder for counterexample files (none written without it).

    Returns
    -------
    CheckResult
        ``seed``, ``variant``, ``results`` (per property: cases, violations, min_slack, ...)
        and ``passed``.
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


class Diagnosis(Result):
    """``report.json`` of ``moreau diagnose`` as a dict; ``fitted_model`` is the refitted
    :class:`System` (None if none), ``series`` the curves of its figures: ``t`` (N,),
    ``y``, ``yhat_nominal``, ``yhat_fitted`` (N, p); None for several recordings."""

    fitted_model: Optional[System]
    series: Optional[Dict[str, np.ndarray]]

    def _parts(self) -> List[str]:
        verdict = str(self.get("verdict", ""))
        if len(verdict) > 100:
            verdict = verdict[:97] + "..."
        return [f"verdict={verdict!r}", f"effects={[e.get('kind') for e in self.get('effects', [])]}"]


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
    metric: str = "auto",
    no_refit: bool = False,
    screen_samples: Optional[int] = None,
    out: Optional[PathLike] = None,
    validate_on: Optional[List[PathLike]] = None,
) -> Diagnosis:
    """Compares a model with a recording, locates the mismatch, names the missing physics,
    refits and validates: ``moreau diagnose --model M --data R``. A list of recording paths
    (several recordings of one machine) is ``--data A --data B``: one model fitted jointly,
    selected by leave-one-recording-out validation; ``validate_on`` is ``--validate-on``.

    Parameters
    ----------
    model : System or path-like
        The nominal model (``[fit] free`` parameters are refitted unless ``no_refit``).
    recording : path-like, str, DataFrame, array or list of path-likes
        A CSV file (header ``t,w,y`` or ``t,w1..wm,y1..yp``, optional ``z``), a pandas
        DataFrame with those columns, or a 2-D array with columns ``t, w1..wm, y1..yp[, z1..zp]``;
        or a list of CSV files of one machine (the joint diagnosis).
    estimation_fraction : float, default 0.7
        Fraction of the record used for estimation (the rest validates). Below 0.9, a
        record whose missing effect acts only after it is diagnosed again with 0.9 (the
        report's first note says so).
    max_effects : int, default 2
        Greatest number of effects added by forward selection.
    input_hold : {"auto", "zoh", "foh"}, default "auto"
        The input between samples.
    estimate_x0 : bool, default False
        Estimate the initial state even when the model states it.
    metric : {"auto", "fit", "rmse"}, default "auto"
        Headline of the verdict (the CLI's ``--metric``).
    no_refit : bool, default False
        Keep the parameters the model frees at their values (the CLI's ``--no-refit``).
    screen_samples : int, optional
        A recording longer than twice this is screened on its leading part of this many
        samples, then diagnosed whole with what the screening kept (the CLI's
        ``--screen-samples``; None: the CLI's default, 0: never screen).
    out : path-like, optional
        Write the CLI's report folder (report.md, report.json, fitted.toml, figures).
    validate_on : list of path-likes, optional
        Recordings the fitted model is judged on, never fitted on (``--validate-on``).

    Returns
    -------
    Diagnosis
        ``report.json`` as a dict (``verdict``, ``effects``, ``fit_before``, ``fit_after``,
        ``nominal_refit``, ...), with ``fitted_model`` (a :class:`System` or None) and
        ``series`` (``t``, ``y``, ``yhat_nominal``, ``yhat_fitted``). The joint diagnosis
        (a list, or ``validate_on``): its ``report.json`` (``recordings`` with the RMSE per
        recording, ``own_fits``, ``candidates``, ``selected``, ``verdict``, ...), with
        ``fitted_model`` and ``series`` None.
    """
    nm = _native_model(model)
    kw: Dict[str, Any] = dict(
        estimation_fraction=estimation_fraction,
        max_effects=max_effects,
        input_hold=input_hold,
        estimate_x0=estimate_x0,
        metric=metric,
        no_refit=no_refit,
        screen_samples=screen_samples,
        out=None if out is None else os.fspath(out),
    )
    if isinstance(recording, (list, tuple)) or validate_on is not None:
        recs = list(recording) if isinstance(recording, (list, tuple)) else [recording]
        paths = recs + list(validate_on or [])
        if not all(isinstance(r, (str, os.PathLike)) for r in paths):
            raise TypeError("several recordings are given as paths of CSV files")
        text, fitted = _native.diagnose_recordings(
            nm, data=[os.fspath(r) for r in recs], validate_on=[os.fspath(r) for r in validate_on or []], **kw
        )
        d = Diagnosis(json.loads(text))
        d.fitted_model = None if fitted is None else System._wrap(fitted)
        d.series = None
        return d
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


class SweepResult(Result):
    """``sweep.json`` of ``moreau sweep`` as a dict; ``table`` maps every axis parameter and
    column name to a numpy array over the points (NaN where a point failed), ``files`` are
    the tables written, ``complete`` is False where a point failed (exit status 1)."""

    files: List[str]
    complete: bool

    def _parts(self) -> List[str]:
        axes = [a.get("parameter") for a in self.get("axes", [])]
        pts = self.get("points", [])
        failed = sum(1 for pt in pts if pt.get("status") not in (None, "ok"))
        return [f"axes={axes}", f"{len(pts)} points", f"{failed} failed", f"complete={getattr(self, 'complete', '?')}"]

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
    """A parameter sweep from a spec file: ``moreau sweep SPEC --out DIR --quiet``.

    Parameters
    ----------
    spec : path-like
        The sweep spec (TOML; see docs/sweep-spec.md). For a grid built in Python use
        :func:`sweep_grid`.
    out : path-like
        Output folder (resumable: finished points are kept).
    shard : str, optional
        ``"K/N"``: only the points of shard K of N (a job array).
    threads : int, optional
        Worker threads (default: all cores).
    digits : int, optional
        Significant digits of the tables.
    overwrite, fresh, retry_failed : bool, default False
        The CLI's ``--overwrite``, ``--fresh``, ``--retry-failed``.

    Returns
    -------
    SweepResult
        ``sweep.json`` as a dict, with ``table`` (numpy arrays per axis and column),
        ``files`` and ``complete``.
    """
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


def _toml_value(key: str, v: Any) -> str:
    """A TOML literal of a spec value (string, bool, number, or a list of them)."""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if not np.isfinite(x):
            raise MoreauError(f"`{key}` = {x}: not a finite number")
        return repr(x)
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(key, u) for u in np.asarray(v).tolist()) + "]"
    raise TypeError(f"`{key}`: expected a string, a bool, a number or a list of them, got {type(v).__name__}")


def sweep_grid(
    model: Model,
    axes: Dict[str, Any],
    out: PathLike,
    *,
    evaluate: Optional[Dict[str, Any]] = None,
    columns: Optional[List[str]] = None,
    name: Optional[str] = None,
    threads: Optional[int] = None,
    digits: Optional[int] = None,
    overwrite: bool = False,
    fresh: bool = False,
) -> SweepResult:
    """A parameter sweep over a grid given in Python: the spec file is written for you.

    Parameters
    ----------
    model : System or path-like
        The base model.
    axes : dict of str to array-like
        Axis parameter (``"input.amplitude"``, ``"plant.A[1][0]"``, ``"parameters.M"``, ...;
        see docs/sweep-spec.md) to its values, in axis order.
    out : path-like
        Output folder; the spec (``spec.toml``) and base model (``model.toml``) used are
        written beside the tables, so the sweep can be rerun with ``moreau sweep``.
    evaluate : dict, optional
        The spec's ``[evaluate]`` table, e.g. ``{"measure": False}``.
    columns : list of str, optional
        The spec's ``[table] columns``.
    name : str, optional
        The sweep's name (default: the model's name).
    threads, digits : int, optional
        As for :func:`sweep`.
    overwrite, fresh : bool, default False
        As for :func:`sweep`.

    Returns
    -------
    SweepResult
        As :func:`sweep` returns.
    """
    if not isinstance(axes, dict) or not axes:
        raise MoreauError("`axes` must be a non-empty dict of axis parameter to values, e.g. {'input.amplitude': [0.5, 1.0]}")
    sysm = model if isinstance(model, System) else System.load(model)
    os.makedirs(out, exist_ok=True)
    spec_dir = os.path.join(os.fspath(out), "spec")
    os.makedirs(spec_dir, exist_ok=True)
    sysm.save(os.path.join(spec_dir, "model.toml"))
    lines = [f"name = {_toml_value('name', sysm.name if name is None else name)}", 'model = "model.toml"']
    for param, values in axes.items():
        vals = np.atleast_1d(np.asarray(values, dtype=float))
        lines += ["", "[[axis]]", f"parameter = {_toml_value('axes', str(param))}", f"values = {_toml_value(str(param), vals)}"]
    if evaluate:
        lines += ["", "[evaluate]"] + [f"{k} = {_toml_value('evaluate.' + k, v)}" for k, v in evaluate.items()]
    if columns:
        lines += ["", "[table]", f"columns = {_toml_value('columns', list(columns))}"]
    spec = os.path.join(spec_dir, "spec.toml")
    with open(spec, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return sweep(spec, out, threads=threads, digits=digits, overwrite=overwrite, fresh=fresh)


def figure(
    kind: str,
    source: Union[Model, "SweepResult"],
    out: PathLike,
    *,
    size: Optional[str] = None,
    formats: Union[str, List[str]] = ("svg", "png", "pgf"),
    title: bool = True,
    width: Optional[int] = None,
    height: Optional[int] = None,
    dpi: Optional[float] = None,
    columns: Optional[List[str]] = None,
    x: Optional[str] = None,
    t_end: Optional[float] = None,
    dt: Optional[float] = None,
) -> List[str]:
    """A figure for a paper, as ``moreau figure KIND INPUT --out DIR`` draws it (no matplotlib).

    Parameters
    ----------
    kind : {"psi", "tube", "trajectory", "sweep"}
        Fig. psi1 (psi(gamma) and the chord of eq. (theta)), Fig. loop (the orbit and the
        tube), y, z and x against time, or columns of a sweep against its parameter.
    source : System, path-like or SweepResult
        The model (psi, tube, trajectory), or a sweep: its result, ``sweep.json`` or its folder.
    out : path-like
        Output folder.
    size : {"column", "two-column"}, optional
        Size preset in points (3.5 in or 7.16 in wide, text 8-9 pt); default 900 x 600.
    formats : str or list of str, default ("svg", "png", "pgf")
        Any of ``svg``, ``png``, ``pgf`` (pgfplots .tex + data .csv), ``pdf``.
    title : bool, default True
        Draw the title (a paper's caption usually replaces it).
    width, height : int, optional
        Override the preset's size (points; pixels at 96 dpi for PNG).
    dpi : float, optional
        Rasterise the PNG at this resolution.
    columns : list of str, optional
        sweep: the columns to draw (default theta, theta_best, measured_rate).
    x : str, optional
        sweep: the axis on the horizontal axis (default the first).
    t_end, dt : float, optional
        trajectory: final time and step.

    Returns
    -------
    list of str
        The files written (for ``svg``, read the file for an SVG string).
    """
    import tempfile

    fmts = [formats] if isinstance(formats, str) else list(formats)
    with tempfile.TemporaryDirectory() as tmp:
        if isinstance(source, SweepResult):
            src = os.path.join(tmp, "sweep.json")
            with open(src, "w", encoding="utf-8") as f:
                json.dump(dict(source), f)
        elif isinstance(source, System):
            src = os.path.join(tmp, "model.toml")
            source.save(src)
        elif isinstance(source, (str, os.PathLike)):
            src = os.fspath(source)
        else:
            raise TypeError(f"`source` must be a System, a SweepResult or a path, got {type(source).__name__}")
        files = _native.figure(
            kind,
            src,
            os.fspath(out),
            formats=fmts,
            size=size,
            width=width,
            height=height,
            dpi=dpi,
            title=title,
            columns=list(columns or []),
            x=x,
            t_end=t_end,
            dt=dt,
        )
    return [os.fspath(f) for f in files]


def set_allow_large(on: bool = True) -> None:
    """The CLI's ``--allow-large`` for every later call.

    Parameters
    ----------
    on : bool, default True
        Lift (``True``) or restore (``False``) the soft work limits (integration steps,
        stored samples, check cases, sweep points, theta's n and p).

    Returns
    -------
    None
    """
    _native.set_allow_large(on)
