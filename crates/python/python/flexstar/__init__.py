"""flexstar: the vibration of the flexible 3-PRP star-triangle robot (AMM and FEM) from Python.

Every function calls the same Rust library as the ``flexstar`` command line (``flexstar-api``);
this package adds no physics, only conversions. Units are SI (m, s, N, rad, Hz).

    import flexstar
    exp = flexstar.Experiment.load("configs/case3.toml")
    run = flexstar.run(exp, solver="amm")
    run["w1tip"].max()
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence

import numpy as np

from . import _flexstar
from ._flexstar import ConfigError, InfeasibleMotion, SolverError

__all__ = [
    "ConfigError",
    "InfeasibleMotion",
    "SolverError",
    "Experiment",
    "Run",
    "LinearModel",
    "run",
    "modal",
    "linearize",
    "sweep",
    "compare",
    "verify",
    "freqmap",
    "plan",
    "fit",
]
__version__ = _flexstar.__version__


class Experiment:
    """A checked experiment (robot, time span, trajectory or drive, solver settings).

    Build with :meth:`load`, :meth:`from_toml` or :meth:`from_dict`; every value is checked by
    the library's experiment loader (errors are :class:`ConfigError` naming file, key, reason).
    """

    def __init__(self, inner: Any) -> None:
        self._inner = inner

    @classmethod
    def load(cls, path: "os.PathLike[str] | str") -> "Experiment":
        """Read and check an experiment file (TOML)."""
        return cls(_flexstar._Experiment.load(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, source: str = "<toml>") -> "Experiment":
        """Parse and check TOML text; ``source`` names it in messages."""
        if not isinstance(text, str):
            raise ConfigError(f"text: expected a str of TOML, got {type(text).__name__}")
        return cls(_flexstar._Experiment.from_toml(text, source))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], source: str = "<dict>") -> "Experiment":
        """Build from a dict shaped like the TOML file (sections as nested dicts)."""
        return cls(_flexstar._Experiment.from_json(_to_json("d", d), source))

    def to_dict(self) -> Dict[str, Any]:
        """The experiment's document as a dict (``from_dict(exp.to_dict())`` gives it back)."""
        return json.loads(self._inner.to_json())

    def with_values(self, values: Mapping[str, Any]) -> "Experiment":
        """A copy with values at the dotted keys of sweeps (``{"robot.Lp": 0.04, "amm.tol": 0.2}``),
        checked the same way as the cases of a sweep."""
        if not isinstance(values, Mapping):
            raise ConfigError(f"values: expected a dict of dotted keys, got {type(values).__name__}")
        return Experiment(self._inner.with_values_json(_to_json("values", dict(values))))

    @property
    def name(self) -> str:
        """The experiment's name (its output folder)."""
        return self._inner.name

    @property
    def source(self) -> str:
        """Where the experiment was read from."""
        return self._inner.source

    def __repr__(self) -> str:
        return f"Experiment({self.name!r}, source={self.source!r})"


def _to_json(arg: str, value: Any) -> str:
    try:
        return json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ConfigError(f"{arg}: {e}") from None


class Run:
    """A solver's output: every column (``t`` included) as a numpy array.

    ``run["w1tip"]``, ``run.columns``, ``run.meta`` (the sidecar JSON as a dict),
    ``run.sensors`` (the sensors' readings as a dict of arrays; ``{}`` without sensors),
    ``run.to_pandas()``, ``run.save(dir)`` (the CLI's files, in ``dir/<name>/``).
    """

    def __init__(self, inner: Any) -> None:
        self._inner = inner
        self.columns: List[str] = list(inner.columns())
        self._cache: Dict[str, np.ndarray] = {}
        self._meta: Optional[Dict[str, Any]] = None
        self._sensors: Optional[Dict[str, np.ndarray]] = None

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            self._cache[name] = self._inner.column(name)
        return self._cache[name]

    def __contains__(self, name: str) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return len(self["t"])

    @property
    def meta(self) -> Dict[str, Any]:
        """The sidecar document (provenance, resolved settings, validity, experiment)."""
        if self._meta is None:
            self._meta = json.loads(self._inner.meta_json())
        return self._meta

    @property
    def sensors(self) -> Dict[str, np.ndarray]:
        """The sensors' readings (``[[sensors]]``, docs/sensors.md), as ``<stem>-sensors.csv``.

        A dict of float64 arrays: ``"t"`` (the sensors' own sample times [s], ``rate_hz``) then one
        entry per channel in the file's order (``<name>_x``, ``<name>_y`` of an accelerometer
        [m/s^2]; ``<name>`` of a strain gauge [m/m], an encoder [m], a force cell [N]; the units
        are ``run.meta["column_units"]``). A run without sensors gives an empty dict ``{}``.
        """
        if self._sensors is None:
            self._sensors = dict(self._inner.sensors())
        return self._sensors

    @property
    def stem(self) -> str:
        """The file stem of the run (``amm-enriched``, ``fem-direct``, ...)."""
        return self._inner.stem

    @property
    def warning(self) -> Optional[str]:
        """The small-deflection warning, ``None`` when the run stays in range."""
        return self._inner.warning

    def to_pandas(self) -> "Any":
        """The columns as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame({c: self[c] for c in self.columns})

    def save(self, out: "os.PathLike[str] | str", figures: bool = False) -> List[str]:
        """Write the CLI's files (``<stem>.csv``, ``-shapes.csv``, ``.json``) into ``out/<name>/``."""
        return list(self._inner.save(os.fspath(out), figures))

    def __repr__(self) -> str:
        return f"Run({self.stem!r}, {len(self)} rows, columns={self.columns})"


def _forces_array(forces: Any) -> np.ndarray:
    if hasattr(forces, "columns") and hasattr(forces, "to_numpy"):
        missing = [c for c in ("t", "Fa1", "Fa2", "Fa3") if c not in forces.columns]
        if missing:
            raise ConfigError(f"forces: the DataFrame has no column(s) {', '.join(missing)}")
        forces = forces[["t", "Fa1", "Fa2", "Fa3"]].to_numpy()
    try:
        a = np.ascontiguousarray(forces, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ConfigError(f"forces: not an array of numbers: {e}") from None
    if a.ndim != 2:
        raise ConfigError(f"forces: expected a 2-D array (n, 4) of t, Fa1, Fa2, Fa3, got {a.ndim} dimension(s)")
    return a


def _check_count(arg: str, v: Any) -> None:
    if v is not None and (isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1):
        raise ConfigError(f"{arg}: expected a positive whole number, got {v!r}")


def _check_float(arg: str, v: Any) -> None:
    if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer))):
        raise ConfigError(f"{arg}: expected a number, got {v!r}")


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
) -> Run:
    """Run ``solver`` ("amm" or "fem") on ``exp`` with the CLI's overrides (``family``, ``modes``,
    ``model``, ``tol`` [%], ``elements``, ``dt`` [s]). ``forces``: a (n, 4) array or a DataFrame
    with columns t, Fa1, Fa2, Fa3 [s, N] drives the sliders (the direct problem). The GIL is
    released during the solve; Ctrl-C stops it within a second (``KeyboardInterrupt``);
    ``progress=True`` prints a line a second on stderr. Nothing is written (see :meth:`Run.save`)."""
    if not isinstance(exp, Experiment):
        raise ConfigError(f"exp: expected a flexstar.Experiment, got {type(exp).__name__}")
    for arg, v in (("modes", modes), ("elements", elements)):
        _check_count(arg, v)
    for arg, v in (("tol", tol), ("dt", dt)):
        _check_float(arg, v)
    f = None if forces is None else _forces_array(forces)
    return Run(
        _flexstar.run(exp._inner, solver, family, modes, model, tol, elements, dt, f, bool(progress))
    )


def modal(
    exp: Experiment,
    at: Optional[float] = None,
    pose: Optional[Sequence[float]] = None,
    sliders: str = "locked",
    modes: int = 6,
    sleeves: str = "sliding",
) -> Dict[str, Any]:
    """Modes at a pose (``at`` = time of the trajectory [s], or ``pose`` = (Gx, Gy, theta)),
    AMM and FEM side by side: ``{"mode", "amm_hz", "fem_hz", "rigid", "pose", "sleeves"}``; with
    ``sliders="free"`` the three rigid modes (0 Hz) come first (none with ``sleeves="stuck"``:
    each sleeve holding its beam's material point, docs/modes.md). With a ``[damping]`` section
    also ``"zeta_amm"``, ``"zeta_fem"``: each model's damping ratio ``alpha / (2 omega) + beta
    omega / 2`` of the mode."""
    return _flexstar.modal(exp._inner, at, None if pose is None else tuple(pose), sliders, modes, sleeves)


class LinearModel:
    """x' = A x + B u, y = C x + D u about a pose. ``states``, ``inputs`` and ``outputs`` name
    the rows and columns of the matrices (as ``statespace.json``): states ``eta1..etaN`` then
    ``etad1..etadN`` (modal amplitudes, rigid modes first with free sliders); inputs ``Fa1..Fa3``
    [N] (sliders free), ``sdd1..sdd3`` [m/s^2] (sliders locked) or ``s1ref..s3ref``,
    ``sd1ref..sd3ref``, ``ff1..ff3`` (servo loop closed); outputs ``s1..s3`` (sliders free),
    ``w1tip..w3tip``, ``w1G..w3G`` [m] and, closed loop, ``e1..e3`` [m]. With locked sliders and
    stuck sleeves the states end with the sliders ``s1..s3`` [m], ``sd1..sd3`` [m/s]
    (docs/modes.md, Eqs. S4-S6)."""

    def __init__(self, d: Dict[str, Any]) -> None:
        self.A: np.ndarray = d["A"]
        self.B: np.ndarray = d["B"]
        self.C: np.ndarray = d["C"]
        self.D: np.ndarray = d["D"]
        self.states: List[str] = d["states"]
        self.inputs: List[str] = d["inputs"]
        self.outputs: List[str] = d["outputs"]
        self.input_units: List[str] = d["input_units"]
        self.output_units: List[str] = d["output_units"]
        self.sliders: str = d["sliders"]
        self.loop: str = d["loop"]
        self.modes: int = d["modes"]
        self.sleeves: str = d["sleeves"]
        self.modal_frequencies_hz: np.ndarray = d["modal_frequencies_hz"]
        self.rigid: int = d["rigid"]
        self.pose: Dict[str, Any] = d["pose"]

    def to_control(self) -> "Any":
        """A python-control ``StateSpace`` with the model's state, input and output names (needs
        the ``control`` package)."""
        import control

        return control.ss(self.A, self.B, self.C, self.D, inputs=self.inputs, outputs=self.outputs, states=self.states)


def linearize(
    exp: Experiment,
    at: Optional[float] = None,
    pose: Optional[Sequence[float]] = None,
    modes: int = 20,
    sliders: str = "free",
    loop: Optional[str] = None,
    sleeves: str = "sliding",
) -> LinearModel:
    """The linear state-space model about a pose (see :class:`LinearModel`), as ``flexstar
    linearize``: ``modes`` elastic modes, ``sliders="free"|"locked"``, ``loop="open"|"closed"``
    (default: closed when the experiment's drive is a servo and the sliders are free),
    ``sleeves="sliding"|"stuck"`` (docs/modes.md, stuck sleeves)."""
    _check_count("modes", modes)
    return LinearModel(
        _flexstar.linearize(exp._inner, at, None if pose is None else tuple(pose), modes, sliders, loop, sleeves)
    )


def sweep(
    study: "os.PathLike[str] | str", out: "os.PathLike[str] | str", jobs: Optional[int] = None, progress: bool = False
) -> "Any":
    """Run a design study file (as ``flexstar sweep``) into ``out/<name>/``; returns results.csv
    as a pandas DataFrame (needs pandas). Ctrl-C stops it between cases (``KeyboardInterrupt``; the
    rows done stay, a rerun resumes); ``progress=True`` prints the share of cases done on stderr."""
    import pandas as pd

    path = _flexstar.sweep(os.fspath(study), os.fspath(out), jobs, bool(progress))
    return pd.read_csv(path)


def compare(
    config: "os.PathLike[str] | str",
    out: "os.PathLike[str] | str" = "out",
    families: Sequence[str] = (),
    modes: Optional[int] = None,
    figures: bool = False,
    progress: bool = False,
    measured: "os.PathLike[str] | str | None" = None,
) -> Dict[str, Any]:
    """Compare the AMM with the FEM on an experiment file (as ``flexstar compare``): writes
    ``out/<name>/``; returns the folder, compare.csv, the behaviour of G and the closest family.
    ``measured``: a recording laid over the runs (as ``--measured``, docs/measured.md).
    Ctrl-C stops it within a second (nothing is written); ``progress=True`` prints the share done
    on stderr. Errors: ConfigError, InfeasibleMotion, SolverError."""
    _check_count("modes", modes)
    rec = None if measured is None else os.fspath(measured)
    return _flexstar.compare(os.fspath(config), os.fspath(out), list(families), modes, figures, progress, rec)


def plan(config: "os.PathLike[str] | str", out: "os.PathLike[str] | str" = "out") -> Dict[str, Any]:
    """Plan a rest-to-rest motion (as ``flexstar plan``; docs/motions.md section 4): the file's
    ``[plan]`` (and ``[limits]``) give the move; writes ``out/<name>/`` (plan.toml, plan.csv,
    plan.json, plan.md, the plain, ZVD-shaped and planned runs on the AMM and the FEM, figures).
    Returns the folder, the paths of plan.toml and plan.csv, the move time, the search's
    evaluations (AMM runs), ``tangent_columns`` (the Jacobian columns the tangent-linear AMM
    carried in them, docs/motions.md 4.9) and stop reason, and ``residual_G_peak_m``: for ``plain``, ``zvd`` and
    ``planned`` the ``(AMM, FEM)`` residual peaks of |dG| after the move [m]. A whole cycle
    (``[plan] points``, docs/motions.md 4.12) is planned as the command plans it: the dict then
    has ``moves`` (per move: ``t_start``, ``t_move``, ``evaluations``, ``reason``, ``warnings``)
    and ``dwells`` (per dwell: ``dwell``, ``t_start``, ``t_end``, ``plain`` and ``planned`` as
    ``(AMM, FEM)`` residual peaks of |dG| in the dwell [m], ``ratio_fem``). Errors: ConfigError
    (naming file and key), SolverError."""
    return _flexstar.plan(os.fspath(config), os.fspath(out))


def fit(
    config: "os.PathLike[str] | str",
    measured: "os.PathLike[str] | str",
    out: "os.PathLike[str] | str" = "out",
) -> Dict[str, Any]:
    """Calibrate the physical parameters of the file's ``[fit]`` on a recording (as ``flexstar
    fit``; docs/measured.md section 4): ``measured`` is a CSV of ``t`` and the sensors' columns on
    the run's sensor times. Writes ``out/<name>/`` (fit.json, fit.md, report.html, the figures and,
    when the fit converged to identifiable estimates, fit.toml). Returns the content of fit.json
    as a dict (``converged``, ``calibrated``, ``parameters`` with estimates, standard errors and
    95 % intervals, ``correlation``, ``channels``, ``identifiability``, ...) with ``dir``,
    ``fit_toml`` (its path, or None) and ``experiment``: the calibrated Experiment (or None).
    Errors: ConfigError (naming file and key), SolverError."""
    r = _flexstar.fit(os.fspath(config), os.fspath(measured), os.fspath(out))
    d: Dict[str, Any] = json.loads(r["fit_json"])
    d["dir"] = r["dir"]
    d["fit_toml"] = r["fit_toml"]
    d["experiment"] = Experiment(r["calibrated"]) if r["calibrated"] is not None else None
    return d


def verify(
    out: "os.PathLike[str] | str" = "out/verify", figures: bool = False, n_study: bool = False, progress: bool = False
) -> Dict[str, Any]:
    """Reproduce and check Table I (as ``flexstar verify``): the table as Markdown, the number of
    checks and the failed ones. Ctrl-C stops it within a second; ``progress=True`` prints the
    share done on stderr."""
    return _flexstar.verify(os.fspath(out), figures, n_study, progress)


def freqmap(
    exp: Experiment,
    gx: Sequence[float],
    gy: Sequence[float],
    theta: float = 0.0,
    modes: int = 6,
    solver: str = "amm",
    sliders: str = "locked",
) -> "Any":
    """The first ``modes`` elastic frequencies over a grid ``gx``, ``gy`` = (min, max, n) [m] at
    ``theta`` [rad], the sliders ``"locked"`` or ``"free"`` (then the three rigid modes at 0 Hz
    are left out): a DataFrame (Gx, Gy, theta, f1..fK [Hz], reason) when pandas is installed,
    else the dict of lists."""
    d = _flexstar.freqmap(exp._inner, tuple(gx), tuple(gy), theta, modes, solver, sliders)
    try:
        import pandas as pd
    except ImportError:
        return d
    df = pd.DataFrame({"Gx": d["Gx"], "Gy": d["Gy"], "theta": d["theta"]})
    for k in range(modes):
        df[f"f{k + 1}"] = [f[k] if f is not None else float("nan") for f in d["f_hz"]]
    df["reason"] = d["reason"]
    return df
