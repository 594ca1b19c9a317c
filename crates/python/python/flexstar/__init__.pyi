"""Type stubs of the flexstar package (see flexstar/__init__.py for the docstrings)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
__version__: str

class ConfigError(ValueError):
    """Bad input: file or argument, key and reason."""
    file: str
    key: Optional[str]
    reason: str

class InfeasibleMotion(Exception):
    """The motion leaves the feasible range at time ``t`` [s] (NaN for a pose)."""
    t: float
    reason: str

class SolverError(Exception):
    """A solver failed, or a file could not be written."""

class Experiment:
    @classmethod
    def load(cls, path: _Path) -> "Experiment": ...
    @classmethod
    def from_toml(cls, text: str, source: str = "<toml>") -> "Experiment": ...
    @classmethod
    def from_dict(cls, d: Mapping[str, Any], source: str = "<dict>") -> "Experiment": ...
    def to_dict(self) -> Dict[str, Any]: ...
    def with_values(self, values: Mapping[str, Any]) -> "Experiment": ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...

class Run:
    columns: List[str]
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __contains__(self, name: str) -> bool: ...
    def __len__(self) -> int: ...
    @property
    def meta(self) -> Dict[str, Any]: ...
    @property
    def sensors(self) -> Dict[str, npt.NDArray[np.float64]]: ...
    @property
    def stem(self) -> str: ...
    @property
    def warning(self) -> Optional[str]: ...
    def to_pandas(self) -> Any: ...
    def save(self, out: _Path, figures: bool = False) -> List[str]: ...

class LinearModel:
    A: npt.NDArray[np.float64]
    B: npt.NDArray[np.float64]
    C: npt.NDArray[np.float64]
    D: npt.NDArray[np.float64]
    states: List[str]
    inputs: List[str]
    outputs: List[str]
    input_units: List[str]
    output_units: List[str]
    sliders: str
    loop: str
    modes: int
    sleeves: str
    modal_frequencies_hz: npt.NDArray[np.float64]
    rigid: int
    pose: Dict[str, Any]
    def to_control(self) -> Any: ...

def run(
    exp: Experiment,
    solver: str = "amm",
    *,
    family: Optional[str] = None,
    modes: Optional[int] = None,
    model: Optional[str] = None,
    tol: Optional[float] = None,
    elements: Optional[int] = None,
    dt: Optional[float] = None,
    forces: Any = None,
    progress: bool = False,
) -> Run: ...
def modal(
    exp: Experiment,
    at: Optional[float] = None,
    pose: Optional[Sequence[float]] = None,
    sliders: str = "locked",
    modes: int = 6,
    sleeves: str = "sliding",
) -> Dict[str, Any]: ...
def linearize(
    exp: Experiment,
    at: Optional[float] = None,
    pose: Optional[Sequence[float]] = None,
    modes: int = 20,
    sliders: str = "free",
    loop: Optional[str] = None,
    sleeves: str = "sliding",
) -> LinearModel: ...
def sweep(study: _Path, out: _Path, jobs: Optional[int] = None, progress: bool = False) -> Any: ...
def plan(config: _Path, out: _Path = "out") -> Dict[str, Any]: ...
def compare(config: _Path, out: _Path = "out", families: Sequence[str] = (), modes: Optional[int] = None, figures: bool = False, progress: bool = False, measured: Optional[_Path] = None) -> Dict[str, Any]: ...
def verify(out: _Path = "out/verify", figures: bool = False, n_study: bool = False, progress: bool = False) -> Dict[str, Any]: ...
def freqmap(exp: Experiment, gx: Sequence[float], gy: Sequence[float], theta: float = 0.0, modes: int = 6, solver: str = "amm", sliders: str = "locked") -> Any: ...
