"""Result objects of the commands: each is the command's JSON object (a ``dict`` with exactly
its keys, so ``r["theta"]`` and ``json.dumps(r)`` work as before), readable as attributes
(``r.theta_best``), with a one-line ``repr`` that leads with the verdict and ``to_dict()``
for a plain copy."""
from __future__ import annotations

import copy
import math
from typing import Any, Dict, Iterable, List, Tuple

__all__ = ["Result", "ThetaResult", "PeriodicResult"]


def _fmt(v: Any) -> str:
    """A number in 4 significant digits (``None`` as ``-``), other values as ``repr``."""
    if v is None:
        return "-"
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, (int, float)):
        x = float(v)
        if math.isnan(x):
            return "nan"
        return f"{x:.4g}"
    if isinstance(v, (list, tuple)) and len(v) == 2 and all(isinstance(u, (int, float)) for u in v):
        return f"[{_fmt(v[0])}, {_fmt(v[1])}]"
    return repr(v)


class Result(Dict[str, Any]):
    """A command's JSON object with attribute access.

    Parameters
    ----------
    *args, **kwargs
        As for ``dict``: the command's JSON object.

    Notes
    -----
    Keys are also attributes (``r.theta`` is ``r["theta"]``); a key that is no identifier is
    read with ``r["key"]``. ``to_dict()`` returns a plain, deep copy. Subclasses name the keys
    of their one-line ``repr`` in ``_summary``.
    """

    _summary: Tuple[str, ...] = ()

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError:
            raise AttributeError(
                f"{type(self).__name__} has no key or attribute {name!r} (keys: {', '.join(sorted(self))})"
            ) from None

    def __dir__(self) -> Iterable[str]:
        return sorted(set(super().__dir__()) | {k for k in self if k.isidentifier()})

    def to_dict(self) -> Dict[str, Any]:
        """A plain ``dict`` with the same keys and values (a deep copy).

        Returns
        -------
        dict
            The command's JSON object, without the result's extra attributes.
        """
        return copy.deepcopy(dict(self))

    def _parts(self) -> List[str]:
        return [f"{k}={_fmt(self.get(k))}" for k in self._summary if k in self]

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(self._parts())}; {len(self)} keys)"

    def _repr_pretty_(self, p: Any, cycle: bool) -> None:  # IPython
        p.text(repr(self))


class ThetaResult(Result):
    """``moreau theta --json``: the bound theta of eq. (theta), the sharper bounds beyond the
    paper and the measured exponent.

    Attributes
    ----------
    theta_best, theta_best_verified, theta_best_method
        The sharpest certified bound, whether it is verified, and which bound it is.
    theta, theta_verified
        The paper's bound (eq. (theta)).
    measured_rate, measured_rate_ci
        The exponent measured by simulation and its 95 % interval (``None`` without
        ``measure``).
    quantities
        Every quantity of the bound with its direction and whether it is verified.

    Every other key of ``moreau theta --json`` is an attribute too.
    """

    _summary = ("name", "theta_best", "theta_best_verified", "theta_best_method", "theta", "measured_rate")


class PeriodicResult(Result):
    """``moreau periodic --json``: the periodic regime (Poincare fixed point, residual, (loc)
    check) and the measured convergence exponent.

    Every key of ``moreau periodic --json`` is an attribute.
    """

    _summary = ("name", "measured_rate", "measured_rate_ci", "residual")
