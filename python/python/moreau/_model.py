"""Models: the backlash set Theta, the input w(t) and the system.

A system built here is exactly the model file it describes (``System.to_toml()``): it is
validated by the model-file reader of the Rust crate ``model`` with the same checks and the
same messages, which name the model-file key (``plant.B``, ``theta.half_width``, ...).
"""
from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import MoreauError

ArrayLike = Any
PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "Set",
    "Interval",
    "Ball",
    "Ellipsoid",
    "BallIntersection",
    "Polytope",
    "Box",
    "Point",
    "Input",
    "Sine",
    "Square",
    "Zero",
    "Samples",
    "System",
    "load",
]


def _real_array(key: str, v: ArrayLike, what: str) -> np.ndarray:
    """``v`` as a float64 array: refuses None (a missing argument), complex entries (the
    imaginary part would be dropped) and None entries (they would become NaN), and checks the
    model-size budget of the CLI before the array is converted further."""
    if v is None:
        raise TypeError(f"`{key}` is missing (None): expected {what}")
    try:
        a = np.asarray(v)
    except (ValueError, TypeError) as e:
        raise MoreauError(f"key `{key}`: expected {what}: {e}") from None
    if np.iscomplexobj(a):
        raise TypeError(f"`{key}` is complex (dtype {a.dtype}): expected real numbers; the imaginary part would be dropped")
    if a.dtype == object:
        flat = a.ravel()
        if any(x is None for x in flat):
            raise TypeError(f"`{key}` has a None entry: expected {what} of numbers")
        if any(isinstance(x, complex) for x in flat):
            raise TypeError(f"`{key}` has a complex entry: expected real numbers; the imaginary part would be dropped")
    _native.check_model_numbers(int(a.size), f"`{key}` of shape {a.shape}")
    try:
        return a.astype(float)
    except (ValueError, TypeError) as e:
        raise MoreauError(f"key `{key}`: expected {what}: {e}") from None


def _vector(key: str, v: ArrayLike) -> List[float]:
    a = _real_array(key, v, "a vector")
    if a.ndim == 0:
        a = a.reshape(1)
    if a.ndim != 1:
        raise MoreauError(f"key `{key}`: expected a vector, got an array of shape {a.shape}")
    return [float(x) for x in a]


def _matrix(key: str, m: ArrayLike) -> List[List[float]]:
    a = _real_array(key, m, "a matrix (a 2-D array or a list of equally long rows)")
    if a.ndim == 0:
        a = a.reshape(1, 1)
    if a.ndim != 2:
        raise MoreauError(
            f"key `{key}`: expected a 2-D array (rows x columns), got shape {a.shape}; "
            "write a column as [[a], [b]] or use numpy's reshape(-1, 1)"
        )
    return [[float(x) for x in row] for row in a]


def _real(key: str, x: Any) -> float:
    """A real number: None (missing) and complex values are refused, not turned into NaN or
    stripped of their imaginary part."""
    if x is None:
        raise TypeError(f"`{key}` is missing (None): expected a real number")
    if np.iscomplexobj(x):
        raise TypeError(f"`{key}` = {x!r} is complex: expected a real number (the imaginary part would be dropped)")
    try:
        return float(x)
    except (TypeError, ValueError) as e:
        raise TypeError(f"`{key}`: expected a real number, got {type(x).__name__} ({e})") from None


def _whole(key: str, v: Any) -> Any:
    """An integral count as an int; anything else unchanged, for the model-file reader to
    refuse with the file's message (``periods=2.5`` is not truncated to 2)."""
    if isinstance(v, (bool, np.bool_)):
        return v
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)) and float(v).is_integer():
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v)
    raise TypeError(f"`{key}` must be an integer, got {type(v).__name__}")


def _describe_set(table: Dict[str, Any], p: int) -> "_native.System":
    """A throw-away system x' = -x, y = x, z in y + Theta in R^p: validates the set."""
    eye = np.eye(p).tolist()
    return _native.System.from_table(
        {
            "name": "set",
            "plant": {"A": (-np.eye(p)).tolist(), "B": np.zeros((p, 1)).tolist(), "C": eye, "E": np.zeros((p, p)).tolist()},
            "theta": table,
        }
    )


class Set:
    """A convex compact set Theta containing 0 (the ``[theta]`` table of a model file).

    Sets are checked when created if their dimension is known (an interval; a ball or an
    ellipsoid with a centre or semi-axes), otherwise when the system is built.
    """

    _table: Dict[str, Any]
    _dim: Optional[int]

    def __init__(self, table: Dict[str, Any], dim: Optional[int]) -> None:
        self._table = {k: v for k, v in table.items() if v is not None}
        self._dim = dim
        self._checked: Optional[_native.System] = _describe_set(self._table, dim) if dim is not None else None

    @property
    def table(self) -> Dict[str, Any]:
        """The ``[theta]`` table of the model file."""
        return dict(self._table)

    @property
    def dim(self) -> Optional[int]:
        """The dimension p (``None`` until the system fixes it)."""
        return self._dim

    def _system(self) -> "_native.System":
        return self._checked if self._checked is not None else _describe_set(self._table, 1)

    def describe(self) -> str:
        """The set as the CLI describes it (``moreau validate``)."""
        return self._system().theta_description

    @property
    def R(self) -> float:
        """Upper bound of the strong-convexity constant R of eq. (R) (``inf`` if not strongly convex)."""
        return self._system().strong_convexity()[0]

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._table.items() if k != "shape")
        return f"{type(self).__name__}({args})"


class Interval(Set):
    """Interval ``[-half_width, half_width]`` (``Interval(h)``) or ``[lo, hi]`` (``Interval(lo, hi)``), p = 1."""

    def __init__(self, a: float, b: Optional[float] = None) -> None:
        if b is None:
            super().__init__({"shape": "interval", "half_width": _real("theta.half_width", a)}, 1)
        else:
            super().__init__({"shape": "interval", "lo": _real("theta.lo", a), "hi": _real("theta.hi", b)}, 1)


class Ball(Set):
    """Euclidean ball of the given radius (centre 0 unless given); R = radius."""

    def __init__(self, radius: float, centre: Optional[ArrayLike] = None) -> None:
        c = None if centre is None else _vector("theta.centre", centre)
        super().__init__({"shape": "ball", "radius": _real("theta.radius", radius), "centre": c}, None if c is None else len(c))


class Ellipsoid(Set):
    """Ellipsoid ``(x - c)^T M^{-1} (x - c) <= 1`` from its semi-axes (axis-aligned) or its SPD shape matrix M."""

    def __init__(
        self,
        semi_axes: Optional[ArrayLike] = None,
        *,
        matrix: Optional[ArrayLike] = None,
        centre: Optional[ArrayLike] = None,
    ) -> None:
        if (semi_axes is None) == (matrix is None):
            raise MoreauError("keys `theta.semi_axes` and `theta.matrix` exclude each other: give exactly one")
        a = None if semi_axes is None else _vector("theta.semi_axes", semi_axes)
        m = None if matrix is None else _matrix("theta.matrix", matrix)
        c = None if centre is None else _vector("theta.centre", centre)
        dim = len(c) if c is not None else (len(a) if a is not None else len(m or []))
        super().__init__({"shape": "ellipsoid", "semi_axes": a, "matrix": m, "centre": c}, dim)


class BallIntersection(Set):
    """Intersection of balls (centres as rows, radii): strongly convex with R = max radius."""

    def __init__(self, centres: ArrayLike, radii: ArrayLike) -> None:
        c = _matrix("theta.centres", centres)
        super().__init__({"shape": "ball_intersection", "centres": c, "radii": _vector("theta.radii", radii)}, len(c[0]) if c else None)


class Polytope(Set):
    """Polytope ``{x : normals x <= offsets}`` (not strongly convex: R = inf, theta certifies nothing)."""

    def __init__(self, normals: ArrayLike, offsets: ArrayLike) -> None:
        nm = _matrix("theta.normals", normals)
        super().__init__({"shape": "polytope", "normals": nm, "offsets": _vector("theta.offsets", offsets)}, len(nm[0]) if nm else None)


class Box(Set):
    """Box ``lower <= x <= upper`` (a polytope)."""

    def __init__(self, lower: ArrayLike, upper: ArrayLike) -> None:
        lo = _vector("theta.lower", lower)
        super().__init__({"shape": "box", "lower": lo, "upper": _vector("theta.upper", upper)}, len(lo))


class Point(Set):
    """The singleton {0}: the linear system (also the default when no set is given)."""

    def __init__(self) -> None:
        super().__init__({"shape": "point"}, None)


class Input:
    """The input w(t) (the ``[input]`` table of a model file)."""

    _table: Dict[str, Any]

    def __init__(self, table: Dict[str, Any]) -> None:
        self._table = {k: v for k, v in table.items() if v is not None}

    @property
    def table(self) -> Dict[str, Any]:
        return dict(self._table)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._table.items() if k != "kind")
        return f"{type(self).__name__}({args})"


class Sine(Input):
    """``w_i(t) = a_i sin(omega t + phase)``, period ``2 pi / omega``."""

    def __init__(self, amplitudes: ArrayLike, omega: float, phase: float = 0.0) -> None:
        super().__init__({"kind": "sine", "amplitudes": _vector("input.amplitudes", amplitudes), "omega": _real("input.omega", omega), "phase": _real("input.phase", phase)})


class Square(Input):
    """``w_i(t) = a_i sign(sin(omega t + phase))``, period ``2 pi / omega``."""

    def __init__(self, amplitudes: ArrayLike, omega: float, phase: float = 0.0) -> None:
        super().__init__({"kind": "square", "amplitudes": _vector("input.amplitudes", amplitudes), "omega": _real("input.omega", omega), "phase": _real("input.phase", phase)})


class Multisine(Input):
    """``w_i(t) = a_i sum_j c_j sin(k_j (omega t + phase) + phi_j)``, period ``2 pi / omega``.

    ``harmonics`` are the whole multiples ``k_j`` of ``omega`` (distinct, at least 1),
    ``weights`` the ``c_j`` (default 1 each), ``phases`` the ``phi_j`` (default 0 each).
    """

    def __init__(
        self,
        amplitudes: ArrayLike,
        omega: float,
        harmonics: ArrayLike,
        weights: Optional[ArrayLike] = None,
        phases: Optional[ArrayLike] = None,
        phase: float = 0.0,
    ) -> None:
        super().__init__({
            "kind": "multisine",
            "amplitudes": _vector("input.amplitudes", amplitudes),
            "omega": _real("input.omega", omega),
            "phase": _real("input.phase", phase),
            "harmonics": _vector("input.harmonics", harmonics),
            "weights": None if weights is None else _vector("input.weights", weights),
            "phases": None if phases is None else _vector("input.phases", phases),
        })


class Zero(Input):
    """``w = 0`` (the default; no period)."""

    def __init__(self) -> None:
        super().__init__({"kind": "zero"})


def _real_sample_array(key: str, v: ArrayLike) -> np.ndarray:
    """Sample values as float64: None and complex values are refused (as in ``_real_array``)."""
    if v is None:
        raise TypeError(f"input samples `{key}` is None: expected an array")
    a = np.asarray(v)
    if np.iscomplexobj(a) or (a.dtype == object and any(isinstance(x, complex) for x in a.ravel())):
        raise TypeError(f"input samples `{key}` are complex: the input is real; the imaginary part would be dropped")
    if a.dtype == object and any(x is None for x in a.ravel()):
        raise TypeError(f"input samples `{key}` have a None entry")
    return a.astype(float)


class Samples(Input):
    """Samples ``(t_k, w_k)``, linearly interpolated (``hold="foh"``) or each held until the
    next (``hold="zoh"``), held outside; periodic if ``period`` is given.

    ``w`` is an array of shape (len(t), m) (or (len(t),) for m = 1). Checked like an input CSV.
    """

    def __init__(
        self, t: ArrayLike, w: ArrayLike, period: Optional[float] = None, name: str = "<samples>", hold: str = "foh"
    ) -> None:
        super().__init__({"kind": "samples"})
        ta = _real_sample_array(f"{name}: t", t)
        wa = _real_sample_array(f"{name}: w", w)
        _native.check_sample_numbers(int(ta.size + wa.size), f"t and w of {name}")
        self.t = ta.ravel()
        if wa.ndim == 1:
            wa = wa.reshape(-1, 1)
        if wa.ndim != 2:
            raise MoreauError(f"input CSV {name}: w must be an array of shape (len(t), m), got shape {wa.shape}")
        self.w = wa
        self.period = None if period is None else _real("input.period", period)
        self.name = name
        self.hold = str(hold)

    def _spec(self) -> Tuple[List[float], List[List[float]], Optional[float], str, str]:
        return ([float(x) for x in self.t], self.w.tolist(), self.period, self.name, self.hold)

    def __repr__(self) -> str:
        return f"Samples(<{len(self.t)} samples, m = {self.w.shape[1]}>, period={self.period!r})"


class System:
    """The closed loop ``x' = A x + B w + E z, y = C x, z in y + Theta`` (eqs. (xy), (yz)).

    ``A`` is n x n, ``B`` n x m, ``C`` p x n, ``E`` n x p (2-D arrays or nested lists);
    ``theta`` a :class:`Set` in R^p (default {0}), ``input`` an :class:`Input` (default zero),
    ``x0`` (default 0) and ``z0`` (default ``C x0``) the initial state, ``dt``, ``periods``,
    ``t_end`` the simulation defaults of the ``[simulation]`` table, ``effects`` a list of
    ``[[effects]]`` tables (models outside the paper's class, as written by ``diagnose``).
    """

    _native: "_native.System"

    def __init__(
        self,
        A: ArrayLike,
        B: ArrayLike,
        C: ArrayLike,
        E: ArrayLike,
        theta: Optional[Set] = None,
        input: Optional[Input] = None,
        *,
        x0: Optional[ArrayLike] = None,
        z0: Optional[ArrayLike] = None,
        name: str = "system",
        dt: Optional[float] = None,
        periods: Optional[int] = None,
        t_end: Optional[float] = None,
        effects: Optional[Sequence[Dict[str, Any]]] = None,
    ) -> None:
        if theta is not None and not isinstance(theta, Set):
            raise TypeError(f"theta must be a moreau set (Interval, Ball, Ellipsoid, ...), got {type(theta).__name__}")
        if input is not None and not isinstance(input, Input):
            raise TypeError(f"input must be a moreau input (Sine, Square, Zero, Samples), got {type(input).__name__}")
        table: Dict[str, Any] = {
            "name": str(name),
            "plant": {"A": _matrix("plant.A", A), "B": _matrix("plant.B", B), "C": _matrix("plant.C", C), "E": _matrix("plant.E", E)},
        }
        if theta is not None:
            table["theta"] = theta.table
        samples = None
        if isinstance(input, Samples):
            samples = input._spec()
        elif input is not None:
            table["input"] = input.table
        initial = {}
        if x0 is not None:
            initial["x0"] = _vector("initial.x0", x0)
        if z0 is not None:
            initial["z0"] = _vector("initial.z0", z0)
        if initial:
            table["initial"] = initial
        sim: Dict[str, Any] = {}
        if dt is not None:
            sim["dt"] = _real("simulation.dt", dt)
        if periods is not None:
            sim["periods"] = _whole("simulation.periods", periods)
        if t_end is not None:
            sim["t_end"] = _real("simulation.t_end", t_end)
        if sim:
            table["simulation"] = sim
        if effects:
            table["effects"] = [dict(e) for e in effects]
        self._native = _native.System.from_table(table, samples)

    @classmethod
    def _wrap(cls, native: "_native.System") -> "System":
        s = cls.__new__(cls)
        s._native = native
        return s

    @classmethod
    def load(cls, path: PathLike) -> "System":
        """Reads a model file (TOML), as ``moreau validate FILE``.

        Parameters
        ----------
        path : path-like
            The model file.

        Returns
        -------
        System
            The validated system; an error names the key and the value (:class:`MoreauError`).
        """
        return cls._wrap(_native.System.load(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str) -> "System":
        """Parses model-file text (``csv`` inputs relative to the working directory).

        Parameters
        ----------
        text : str
            The text of a model file.

        Returns
        -------
        System
            The validated system.
        """
        return cls._wrap(_native.System.from_toml(text))

    @classmethod
    def from_statespace(
        cls,
        ss: Any,
        E: ArrayLike,
        theta: Optional[Set] = None,
        input: Optional[Input] = None,
        **kwargs: Any,
    ) -> "System":
        """From a continuous-time state-space model such as python-control's ``StateSpace``
        (python-control itself is not needed).

        The loop of the paper has no feedthrough: a nonzero ``D`` is an error, and so is a
        discrete-time model (``ss.dt`` other than 0 or None). The name defaults to ``ss.name``.

        Parameters
        ----------
        ss : object
            Anything with attributes ``A``, ``B``, ``C`` (and optionally ``D``, ``dt``, ``name``).
        E : array-like
            How the backlash output acts on the state (n x p).
        theta : Set, optional
            The backlash set (default {0}).
        input : Input, optional
            The input (default zero).
        **kwargs
            Further keywords of :class:`System` (``x0``, ``name``, ``dt``, ...).

        Returns
        -------
        System
        """
        for k in ("A", "B", "C"):
            if not hasattr(ss, k):
                raise TypeError(f"from_statespace needs an object with attributes A, B, C (a state-space model); {type(ss).__name__} has no {k}")
        D = getattr(ss, "D", None)
        if D is not None and np.size(D) and np.any(_real_array("D", D, "a matrix") != 0):
            raise MoreauError(
                "the state-space model has a direct feedthrough D != 0; the loop of the paper has y = C x (D = 0)"
            )
        dt = getattr(ss, "dt", 0)
        if dt not in (0, None) and not (isinstance(dt, float) and dt == 0.0):
            raise MoreauError(f"the state-space model is discrete-time (dt = {dt}); moreau needs a continuous-time plant")
        if "name" not in kwargs:
            nm = getattr(ss, "name", None)
            if isinstance(nm, str) and nm:
                kwargs["name"] = nm
        return cls(ss.A, ss.B, ss.C, E, theta, input, **kwargs)

    # -- the system's data
    @property
    def name(self) -> str:
        return self._native.name

    @property
    def n(self) -> int:
        """State dimension."""
        return self._native.n

    @property
    def m(self) -> int:
        """Input dimension."""
        return self._native.m

    @property
    def p(self) -> int:
        """Output and backlash dimension."""
        return self._native.p

    @property
    def A(self) -> np.ndarray:
        return np.array(self._native.A, dtype=float)

    @property
    def B(self) -> np.ndarray:
        return np.array(self._native.B, dtype=float)

    @property
    def C(self) -> np.ndarray:
        return np.array(self._native.C, dtype=float)

    @property
    def E(self) -> np.ndarray:
        return np.array(self._native.E, dtype=float)

    @property
    def F(self) -> np.ndarray:
        """``F = A + E C``, eq. (F)."""
        return self.A + self.E @ self.C

    @property
    def x0(self) -> np.ndarray:
        return np.array(self._native.x0, dtype=float)

    @property
    def z0(self) -> np.ndarray:
        return np.array(self._native.z0, dtype=float)

    @property
    def period(self) -> Optional[float]:
        """Period T of the input (None if not periodic)."""
        return self._native.period

    @property
    def mu(self) -> float:
        """``mu = max Re eig(F)`` (eq. (stab), estimate)."""
        return self._native.mu

    def eig_F(self) -> np.ndarray:
        """Eigenvalues of F by decreasing real part.

        Returns
        -------
        numpy.ndarray
            Complex eigenvalues of ``F = A + E C``, shape (n,).
        """
        return np.array([complex(re, im) for re, im in self._native.eig_f()])

    @property
    def theta(self) -> str:
        """Theta as the CLI describes it."""
        return self._native.theta_description

    @property
    def R(self) -> float:
        """Upper bound of the strong-convexity constant R of Theta (eq. (R); inf if not strongly convex)."""
        return self._native.strong_convexity()[0]

    @property
    def input_kind(self) -> str:
        return self._native.input_kind

    def w(self, t: ArrayLike) -> np.ndarray:
        """The input w(t) at the given times.

        Parameters
        ----------
        t : array-like
            Times.

        Returns
        -------
        numpy.ndarray
            Shape (len(t), m).
        """
        ts = np.atleast_1d(np.asarray(t, dtype=float)).ravel()
        return np.frombuffer(self._native.input_at([float(x) for x in ts]), dtype="<f8").reshape(len(ts), self.m).copy()

    @property
    def dt(self) -> float:
        return self._native.dt

    @property
    def periods(self) -> int:
        return self._native.periods

    @property
    def t_end(self) -> Optional[float]:
        return self._native.t_end

    @property
    def effects(self) -> List[str]:
        """Kinds of the ``[[effects]]`` (empty for the paper's class)."""
        return list(self._native.effects)

    def to_toml(self) -> str:
        """The model file of this system.

        Returns
        -------
        str
            TOML text (a ``Samples`` input is written as a ``csv`` input naming its source; an
            ``x0`` or ``z0`` never given is not written, so it reads back as the same default).
        """
        return self._native.to_toml()

    def save(self, path: PathLike) -> None:
        """Writes the model file (``moreau theta PATH`` then reads the same system).

        The file is written beside its target and renamed into place, so an interrupted save
        leaves no half-written model.

        Parameters
        ----------
        path : path-like
            Where to write.

        Returns
        -------
        None
        """
        text = self.to_toml()
        target = os.fspath(path)
        tmp = f"{target}.{os.getpid()}.tmp"
        try:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(tmp, target)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)

    def __repr__(self) -> str:
        per = "none" if self.period is None else f"{self.period:.6g}"
        return (
            f"<moreau.System {self.name!r}: n = {self.n}, m = {self.m}, p = {self.p}, "
            f"Theta = {self.theta}, input {self.input_kind} (T = {per}), mu = {self.mu:.6g}>"
        )


def load(path: PathLike) -> System:
    """Reads a model file (TOML), as ``moreau validate FILE``.

    Parameters
    ----------
    path : path-like
        The model file.

    Returns
    -------
    System
        The validated system.
    """
    return System.load(path)


def _native_model(model: Union[System, PathLike]) -> Any:
    """The argument the native functions take: the native system, or the path as a string."""
    if isinstance(model, System):
        return model._native
    if isinstance(model, (str, os.PathLike)):
        return os.fspath(model)
    raise TypeError(f"expected a moreau.System or the path of a model file, got {type(model).__name__}")
