"""usm_study: the usm-study workbench from Python.

Closed-loop runs of underwater swimming manipulators (``simulate``), batches of runs on a
thread pool (``simulate_many``), studies (``sweep``), optimisation (``optimise``), the static
thruster-matrix analysis (``tcm``) and ask/tell evaluation for outside optimisers
(``Problem``). Every function calls the same library code as the ``usm-study`` command of the
same name: the same inputs give the same numbers, bit for bit, and the same files.

Units are SI throughout: metres, seconds, radians, newtons, newton-metres, joules, watts.
Errors raise :class:`UsmStudyError` (a ``ValueError``) whose message is the library's own,
located ``file:line:col: key: ...`` when the input has a place.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import polars as pl

from . import _native
from ._native import UsmStudyError

__all__ = [
    "UsmStudyError",
    "Design",
    "Scenario",
    "Run",
    "Problem",
    "Evaluation",
    "SweepResult",
    "OptimiseResult",
    "TcmResult",
    "OcpResult",
    "design",
    "scenario",
    "simulate",
    "simulate_many",
    "sweep",
    "optimise",
    "tcm",
    "ocp",
]

Value = Union[bool, int, float, str, Sequence[Any], Mapping[str, Any]]


def _frame(columns: Sequence[Tuple[str, bytes]]) -> pl.DataFrame:
    """Columns of native f64 bytes as a DataFrame (numpy views the bytes without a copy)."""
    return pl.DataFrame({name: np.frombuffer(b, dtype=np.float64) for name, b in columns})


def _path(p: Union[str, "os.PathLike[str]"]) -> str:
    return os.fspath(p)


@dataclass(frozen=True)
class Design:
    """A vehicle design: a preset (``usm-paper``, ``uvms-planar``) or a design file.

    ``toml`` is the design in explicit form (every body, joint and thruster written out,
    SI units), as ``usm-study design show`` prints it.
    """

    source: str
    name: str
    joints: int
    thrusters: int
    toml: str = field(repr=False)


def design(name_or_path: Union[str, "os.PathLike[str]"]) -> Design:
    """Load a design: a preset name (``usm-paper``, ``uvms-planar``) or a design file (TOML).

    Raises UsmStudyError with the located message (``file:line:col: key: ...``) for a bad
    file.
    """
    src = _path(name_or_path)
    if os.path.isfile(src):
        src = os.path.abspath(src)
    d = _native.design(src)
    return Design(source=src, name=d["name"], joints=d["joints"], thrusters=d["thrusters"], toml=d["toml"])


def _overrides(kwargs: Mapping[str, Value]) -> Dict[str, Value]:
    """Keyword overrides: ``control__k_psi=0.3`` stands for ``control.k_psi``."""
    return {k.replace("__", "."): v for k, v in kwargs.items()}


@dataclass(frozen=True)
class Scenario:
    """A scenario (preset or file) with a design and ``--set``-style overrides, validated.

    ``name``, ``mode``, ``duration`` [s], ``dt`` [s], ``control_dt`` [s], ``design_name`` and
    ``allocation`` are those of the validated scenario.
    """

    source: str
    design: Optional[str]
    overrides: Dict[str, Value]
    name: str
    mode: str
    duration: float
    dt: float
    control_dt: float
    design_name: str
    allocation: str


def scenario(
    name_or_path: Union[str, "os.PathLike[str]"],
    design: Union[None, str, Design] = None,
    **overrides: Value,
) -> Scenario:
    """A scenario preset or file with overrides, checked as ``usm-study simulate`` checks it.

    Presets: ``transport-method1``, ``transport-method2``, ``work-setpoint``,
    ``transport-method1-torque-limited``, ``work-setpoint-far``. Overrides take the keys of
    ``--set`` (``scenario(..., **{"control.k_psi": 0.3})``, or ``control__k_psi=0.3``), with
    values in the key's SI unit (e.g. ``scenario.duration`` in s, ``control.look_ahead`` in m).
    """
    src = _path(name_or_path)
    if os.path.isfile(src):
        src = os.path.abspath(src)
    d = design.source if isinstance(design, Design) else design
    ov = _overrides(overrides)
    info = _native.scenario_info(src, d, ov)
    return Scenario(
        source=src,
        design=d,
        overrides=ov,
        name=info["name"],
        mode=info["mode"],
        duration=info["duration"],
        dt=info["dt"],
        control_dt=info["control_dt"],
        design_name=info["design"],
        allocation=info["allocation"],
    )


def _resolve(
    sc: Union[str, "os.PathLike[str]", Scenario],
    design: Union[None, str, Design],
    overrides: Optional[Mapping[str, Value]],
) -> Tuple[str, Optional[str], Dict[str, Value]]:
    if isinstance(sc, Scenario):
        src, d, ov = sc.source, sc.design, dict(sc.overrides)
    else:
        src, d, ov = _path(sc), None, {}
    if design is not None:
        d = design.source if isinstance(design, Design) else _path(design)
    ov.update(overrides or {})
    return src, d, ov


class Run:
    """One closed-loop run.

    ``metrics``: the summary metrics by name, in SI units (``energy_per_metre`` J/m,
    ``cross_track_rms`` m, ``convergence_time`` s, ``peak_thrust`` N, ...), exactly the numbers
    of ``usm-study simulate``'s ``summary.json``. ``success``: every ``[success]`` criterion
    met. ``missed``: the first criterion missed (``criterion: detail``) or None. ``failure``:
    ``(time [s], cause)`` if the run stopped early, else None. ``timeseries``: the logged
    channels as a polars DataFrame (column ``t`` in s, then the channels in SI units).
    """

    def __init__(self, native: "_native.Run") -> None:
        self._native = native
        self._timeseries: Optional[pl.DataFrame] = None

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def mode(self) -> str:
        return self._native.mode

    @property
    def design(self) -> str:
        return self._native.design

    @property
    def metrics(self) -> Dict[str, float]:
        return self._native.metrics

    @property
    def success(self) -> bool:
        return self._native.success

    @property
    def missed(self) -> Optional[str]:
        return self._native.missed

    @property
    def failure(self) -> Optional[Tuple[float, str]]:
        return self._native.failure

    @property
    def timeseries(self) -> pl.DataFrame:
        if self._timeseries is None:
            self._timeseries = _frame(self._native._columns())
        return self._timeseries

    def __repr__(self) -> str:
        return repr(self._native)


def simulate(
    scenario: Union[str, "os.PathLike[str]", Scenario],
    design: Union[None, str, Design] = None,
    overrides: Optional[Mapping[str, Value]] = None,
) -> Run:
    """Run one closed-loop scenario, as ``usm-study simulate SCENARIO --set key=value ...``.

    scenario: a preset (``transport-method1``, ``transport-method2``, ``work-setpoint``, ...), a
    scenario file (TOML) or a :class:`Scenario`. design: a preset, a design file or a
    :class:`Design` replacing the scenario's own. overrides: ``{key: value}`` with the keys of
    ``--set`` (``{"control.k_psi": 0.3, "scenario.duration": 60.0}``), values in the key's SI
    unit. A scenario's ``[uncertainty]`` table is ignored (the nominal run).

    Returns a :class:`Run`: ``metrics`` in SI units (J/m, m, s, N, ...), ``success``,
    ``timeseries`` (polars DataFrame, time ``t`` in s). A run that diverges returns with
    ``failure`` set; bad input raises UsmStudyError with its location. The GIL is released
    while the run goes on.
    """
    src, d, ov = _resolve(scenario, design, overrides)
    return Run(_native.simulate(src, d, ov))


def simulate_many(
    scenario: Union[str, "os.PathLike[str]", Scenario],
    params: Union[Sequence[Mapping[str, Value]], pl.DataFrame],
    design: Union[None, str, Design] = None,
    overrides: Optional[Mapping[str, Value]] = None,
    jobs: int = 0,
) -> pl.DataFrame:
    """Run one scenario once per parameter set, in parallel; one row per set, in input order.

    params: a list of ``{key: value}`` override dicts (``--set`` keys, SI units), or a polars
    DataFrame whose column names are the keys (one run per row). jobs: threads (0: all
    cores; capped at 4 per core, as on the command line); the rows are the same, bit for bit, for any ``jobs`` and equal those of
    ``simulate`` with the same overrides. The GIL is released during the batch.

    Returns a DataFrame: the parameter columns, then every summary metric (SI units), then
    ``ok`` (every ``[success]`` criterion met) and ``failure`` (why a run stopped early, or
    null). Bad input in any set raises UsmStudyError naming the set (``params[3]: ...``)
    before any result is returned.
    """
    if isinstance(params, pl.DataFrame):
        rows: List[Dict[str, Value]] = params.to_dicts()
    else:
        rows = [dict(p) for p in params]
    if jobs < 0:
        raise UsmStudyError(f"jobs: must be >= 0 (0: all cores), got {jobs}")
    src, d, ov = _resolve(scenario, design, overrides)
    names, columns, ok, failure = _native.simulate_many(src, rows, d, ov, jobs)
    keys: List[str] = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    data: Dict[str, Any] = {}
    for k in keys:
        data[k] = [r.get(k) for r in rows]
    for n, b in zip(names, columns):
        if n in data:
            n = f"metric.{n}"
        data[n] = np.frombuffer(b, dtype=np.float64)
    data["ok"] = ok
    data["failure"] = pl.Series("failure", failure, dtype=pl.Utf8)
    return pl.DataFrame(data)


@dataclass(frozen=True)
class SweepResult:
    """The outcome of a sweep: its output directory and case counts (``cases`` loads
    ``cases.parquet``, the table ``docs/columns.md`` describes)."""

    out: str
    counts: Dict[str, Any]

    @property
    def cases(self) -> pl.DataFrame:
        return pl.read_parquet(os.path.join(self.out, "cases.parquet"))


def sweep(
    study: Union[str, "os.PathLike[str]"],
    out: Union[None, str, "os.PathLike[str]"] = None,
    jobs: int = 0,
    resume: bool = False,
    force: bool = False,
    case_timeout: float = 600.0,
) -> SweepResult:
    """Run a study file, as ``usm-study sweep STUDY``: the same files (cases.csv/.parquet,
    summary.md, plots, report.html) in ``out`` (default: the study's ``output``).

    jobs: threads (0: all cores; results do not depend on it). case_timeout: wall-clock
    budget of one case in s (0: none). Returns a :class:`SweepResult`.
    """
    r = _native.sweep(_path(study), None if out is None else _path(out), jobs, resume, force, case_timeout)
    return SweepResult(out=r.pop("out"), counts=r)


@dataclass(frozen=True)
class OptimiseResult:
    """The outcome of ``optimise``: start and best parameter values (physical units of their
    keys), the best objective and constraint violation (0: feasible), the output directory
    (history, best.toml, summary.md, plots, report.html)."""

    out: str
    evaluations: int
    start: Dict[str, float]
    start_objective: float
    best: Dict[str, float]
    objective: float
    violation: float
    feasible: bool


def optimise(
    problem: Union[str, "os.PathLike[str]"],
    out: Union[None, str, "os.PathLike[str]"] = None,
    jobs: int = 0,
    resume: bool = False,
    plots: bool = True,
) -> OptimiseResult:
    """Optimise a problem file, as ``usm-study optimise PROBLEM``: the same solver, the same
    evaluations and the same files in ``out`` (default: the problem's ``study.output``).

    jobs: threads evaluating a batch (0: all cores; results do not depend on it).
    """
    r = _native.optimise(_path(problem), None if out is None else _path(out), jobs, resume, plots)
    return OptimiseResult(
        out=r["out"],
        evaluations=r["evaluations"],
        start=r["start"],
        start_objective=r["start_objective"],
        best=r["best"],
        objective=r["objective"],
        violation=r["violation"],
        feasible=r["feasible"],
    )


@dataclass(frozen=True)
class TcmResult:
    """The static T(q) analysis: ``summary`` is ``summary.json`` (σ_min in N per N of the
    scaled matrix, singular fractions, quantiles, worst configurations with q in rad);
    ``samples`` loads ``samples.parquet`` (written up to 200 000 samples)."""

    out: str
    summary: Dict[str, Any]

    @property
    def samples(self) -> pl.DataFrame:
        return pl.read_parquet(os.path.join(self.out, "samples.parquet"))


def tcm(
    design: Union[str, Design],
    samples: Optional[int] = None,
    seed: int = 0,
    threshold: Optional[float] = None,
    sampling: str = "sobol",
    out: Union[None, str, "os.PathLike[str]"] = None,
    char_length: Optional[float] = None,
    jobs: int = 0,
    mode: str = "transport",
    worst: Optional[int] = None,
) -> TcmResult:
    """Static analysis of the thruster matrix T(q) over joint space, as ``usm-study tcm``.

    samples: joint configurations (default that of the command); sampling: ``sobol``, ``lhs``
    or ``random``; threshold: scaled σ_min below which T counts as singular; char_length: L
    [m] dividing the moment rows (default half the vehicle length); out: default
    ``results/tcm/<design>``.
    """
    d = design.source if isinstance(design, Design) else _path(design)
    text, out_dir = _native.tcm(
        d, samples, seed, threshold, sampling, None if out is None else _path(out), char_length, jobs, mode, worst
    )
    return TcmResult(out=out_dir, summary=json.loads(text))


class Evaluation(NamedTuple):
    """One point's evaluation: ``metrics`` by name (SI units; for a problem of several
    scenarios the keys are ``scenario:metric``), the ``objective`` (lower is better, terms
    normalised by their value at the file's start point) and the summed constraint
    ``violation`` (0: feasible)."""

    metrics: Dict[str, float]
    objective: float
    violation: float


class Problem:
    """A problem file (``usm-study optimise``'s input) for an outside optimiser (ask/tell).

    ``params``: ``[{name, lower, upper, scale ('lin'|'log'), start, integer}]`` in file order,
    bounds in the physical unit of each key. ``evaluate({name: value})`` scores a point with
    the same evaluator and scoring as ``optimise`` (objective scales fixed at the start point,
    evaluated once on first use) and returns an :class:`Evaluation`
    ``(metrics, objective, violation)``. ``last_failure`` holds why the last evaluated run
    failed, or None. The GIL is released during an evaluation, so threads may evaluate in
    parallel.
    """

    def __init__(self, path: Union[str, "os.PathLike[str]"]) -> None:
        self._native = _native.Problem(_path(path))
        self.last_failure: Optional[str] = None

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def params(self) -> List[Dict[str, Any]]:
        return self._native.params

    @property
    def start(self) -> Dict[str, float]:
        """The file's start point."""
        return {p["name"]: p["start"] for p in self.params}

    @property
    def metric_names(self) -> List[str]:
        return self._native.metric_names

    @property
    def max_evals(self) -> int:
        """The file's own evaluation budget (``[solver] max_evals``)."""
        return self._native.max_evals

    def evaluate(self, params: Mapping[str, float]) -> Evaluation:
        """Evaluate ``{name: value}`` (every parameter, within its bounds)."""
        rows, objective, violation, failure = self._native._evaluate(dict(params))
        self.last_failure = failure
        names = self._native.scenarios
        metrics: Dict[str, float] = {}
        if len(rows) == 1:
            metrics = dict(rows[0])
        else:
            for scen, row in zip(names, rows):
                for k, v in row:
                    metrics[f"{scen}:{k}"] = v
        return Evaluation(metrics, objective, violation)

    def __repr__(self) -> str:
        return f"Problem({self.name!r}, {len(self.params)} params)"


@dataclass(frozen=True)
class OcpResult:
    """An optimal-control solve (docs/ocp.md): ``trajectory`` is ``trajectory.csv`` as a polars
    DataFrame (N + 1 rows, ``simulate``'s time-series column names; the controls of row k act
    over [t_k, t_{k+1}], the last row has none), ``summary`` is ``summary.json`` (status,
    objective and its terms, KKT residuals, iterations, time per phase, every start of a
    multi-start and their spread)."""

    out: str
    trajectory: pl.DataFrame
    summary: Dict[str, Any]

    @property
    def status(self) -> str:
        return self.summary["status"]

    @property
    def objective(self) -> float:
        return self.summary["objective"]


def ocp(
    problem: Union[str, "os.PathLike[str]"],
    out: Union[str, "os.PathLike[str]"],
) -> OcpResult:
    """Solve an optimal-control problem file, as ``usm-study ocp PROBLEM --out OUT``: the same
    solver and the same files in ``out``. A solve that does not converge is not an error: its
    ``status`` says how it ended (``converged``, ``max_iterations``, ``infeasible``,
    ``diverged``, ``stalled``)."""
    o, summary = _native.ocp(_path(problem), _path(out))
    trajectory = pl.read_csv(os.path.join(o, "trajectory.csv"))
    return OcpResult(out=o, trajectory=trajectory, summary=json.loads(summary))
