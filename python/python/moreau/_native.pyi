"""Type stubs of the extension module ``moreau._native`` (python/src/py.rs). The public API is
the package ``moreau``; these functions return the CLI's JSON as text and samples as raw
little-endian float64 buffers."""
from os import PathLike
from typing import Any, Dict, List, Optional, Tuple, Union

__version__: str

class MoreauError(ValueError):
    """An error of moreau, with the one-line message the ``moreau`` command prints after ``error:``."""

_Path = Union[str, PathLike[str]]
_Model = Union["System", _Path]

class System:
    @staticmethod
    def from_table(
        table: Dict[str, Any],
        samples: Optional[Tuple[List[float], List[List[float]], Optional[float], str, str]] = None,
    ) -> System: ...
    @staticmethod
    def load(path: _Path) -> System: ...
    @staticmethod
    def from_toml(text: str) -> System: ...
    def to_toml(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def n(self) -> int: ...
    @property
    def m(self) -> int: ...
    @property
    def p(self) -> int: ...
    @property
    def A(self) -> List[List[float]]: ...
    @property
    def B(self) -> List[List[float]]: ...
    @property
    def C(self) -> List[List[float]]: ...
    @property
    def E(self) -> List[List[float]]: ...
    @property
    def x0(self) -> List[float]: ...
    @property
    def z0(self) -> List[float]: ...
    @property
    def period(self) -> Optional[float]: ...
    @property
    def mu(self) -> float: ...
    def eig_f(self) -> List[Tuple[float, float]]: ...
    @property
    def theta_kind(self) -> str: ...
    @property
    def theta_description(self) -> str: ...
    def strong_convexity(self) -> Tuple[float, bool]: ...
    @property
    def input_kind(self) -> str: ...
    @property
    def dt(self) -> float: ...
    @property
    def periods(self) -> int: ...
    @property
    def t_end(self) -> Optional[float]: ...
    @property
    def effects(self) -> List[str]: ...
    def input_at(self, t: List[float]) -> bytes: ...

def theta(
    model: _Model, *, measure: bool = True, stationary: bool = True, guidance: bool = True, step_check: bool = False
) -> str: ...
def simulate(
    model: _Model,
    *,
    periods: Optional[int] = None,
    dt: Optional[float] = None,
    t_end: Optional[float] = None,
    integrator: str = "catching-up",
    max_rows: Optional[int] = None,
) -> Tuple[int, int, int, str, float, Dict[str, bytes]]: ...
def periodic(model: _Model, *, dt: Optional[float] = None, periods: int = 60, pairs: int = 3) -> str: ...
def check(
    *,
    only: Optional[str] = None,
    cases: Optional[int] = None,
    seed: int = 0,
    negative_control: bool = False,
    out: Optional[_Path] = None,
) -> Tuple[str, bool]: ...
def diagnose(
    model: _Model,
    *,
    data: Optional[_Path] = None,
    text: Optional[str] = None,
    source_name: str = "<recording>",
    estimation_fraction: float = 0.7,
    max_effects: int = 2,
    input_hold: str = "auto",
    estimate_x0: bool = False,
    metric: str = "auto",
    no_refit: bool = False,
    screen_samples: Optional[int] = None,
    out: Optional[_Path] = None,
) -> Tuple[str, Optional[System], int, Dict[str, bytes]]: ...
def diagnose_recordings(
    model: _Model,
    *,
    data: List[_Path],
    validate_on: List[_Path] = ...,
    estimation_fraction: float = 0.7,
    max_effects: int = 2,
    input_hold: str = "auto",
    estimate_x0: bool = False,
    metric: str = "auto",
    no_refit: bool = False,
    screen_samples: Optional[int] = None,
    out: Optional[_Path] = None,
) -> Tuple[str, Optional[System]]: ...
def figure(
    kind: str,
    input: _Path,
    out: _Path,
    *,
    formats: List[str] = ...,
    size: Optional[str] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    dpi: Optional[float] = None,
    title: bool = True,
    columns: List[str] = ...,
    x: Optional[str] = None,
    t_end: Optional[float] = None,
    dt: Optional[float] = None,
) -> List[str]: ...
def sweep(
    spec: _Path,
    out: _Path,
    *,
    shard: Optional[str] = None,
    threads: Optional[int] = None,
    digits: Optional[int] = None,
    overwrite: bool = False,
    fresh: bool = False,
    retry_failed: bool = False,
) -> Tuple[str, List[str], bool]: ...
def set_allow_large(on: bool) -> None: ...
def allow_large() -> bool: ...

MAX_MODEL_NUMBERS: int
MAX_SAMPLE_NUMBERS: int

def check_model_numbers(numbers: int, detail: str) -> None: ...
def check_sample_numbers(numbers: int, detail: str) -> None: ...
