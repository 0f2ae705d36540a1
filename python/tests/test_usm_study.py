"""Tests of the Python package against the command line (issue 27).

The command-line binary is target/release/usm-study at the repository root (built by
`cargo build --release`), or the path in USM_STUDY_BIN. Every comparison is bit for bit.
"""

import json
import math
import os
import random
import subprocess
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import usm_study

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
BIN = Path(os.environ.get("USM_STUDY_BIN", ROOT / "target" / "release" / "usm-study"))


def cli(*args, cwd=None):
    if not BIN.is_file():
        pytest.fail(f"{BIN} not found: run `cargo build --release` first or set USM_STUDY_BIN")
    return subprocess.run([str(BIN), *args], cwd=cwd, capture_output=True, text=True)


def cli_summary(tmp_path, scenario, *sets):
    out = tmp_path / "cli"
    args = ["simulate", scenario, "--out", str(out), "--no-plots"]
    for s in sets:
        args += ["--set", s]
    p = cli(*args)
    assert p.returncode == 0, p.stderr
    return out, json.loads((out / "summary.json").read_text())


def same(a, b):
    """Bit-for-bit equality of two floats (NaN equals NaN)."""
    return np.float64(a).tobytes() == np.float64(b).tobytes()


def json_metric(v):
    # summary.json writes non-finite values as strings ("NaN", "inf").
    return float(v) if not isinstance(v, str) else float(v.lower())


@pytest.mark.parametrize(
    "scenario,sets",
    [
        ("transport-method1", []),
        ("work-setpoint", ["scenario.duration=20"]),
        ("transport-method2", ["control.k_psi=0.3", "scenario.duration=60"]),
    ],
)
def test_metrics_equal_the_cli_summary_bit_for_bit(tmp_path, scenario, sets):
    out, summary = cli_summary(tmp_path, scenario, *sets)
    overrides = {}
    for s in sets:
        k, v = s.split("=")
        overrides[k] = float(v)
    r = usm_study.simulate(scenario, overrides=overrides)
    # summary.json lists the metrics by name; the run in the mode's order.
    assert sorted(r.metrics) == sorted(summary["metrics"])
    for k, v in summary["metrics"].items():
        assert same(r.metrics[k], json_metric(v)), k
    assert r.success == summary["success"]["met"]
    assert r.design == summary["design"]
    assert r.mode == summary["mode"]
    # The time series equals the command's timeseries.parquet, column by column.
    cli_ts = pl.read_parquet(out / "timeseries.parquet")
    assert r.timeseries.columns == cli_ts.columns
    for c in cli_ts.columns:
        assert r.timeseries[c].to_numpy().tobytes() == cli_ts[c].to_numpy().tobytes(), c


def test_scenario_and_design_objects_give_the_same_run():
    sc = usm_study.scenario("transport-method1", **{"scenario.duration": 20.0}, control__k_psi=0.4)
    assert (sc.name, sc.mode, sc.duration, sc.design_name) == ("transport-method1", "transport", 20.0, "usm-paper")
    d = usm_study.design("usm-paper")
    assert d.name == "usm-paper" and d.thrusters > 0 and "[[thruster]]" in d.toml
    a = usm_study.simulate(sc, design=d)
    b = usm_study.simulate("transport-method1", overrides={"scenario.duration": 20.0, "control.k_psi": 0.4})
    assert list(a.metrics) == list(b.metrics)
    assert all(same(a.metrics[k], b.metrics[k]) for k in a.metrics)


def test_simulate_many_of_64_equals_64_single_runs():
    rng = random.Random(7)
    params = [
        {"control.k_psi": rng.uniform(0.2, 1.0), "control.look_ahead": rng.uniform(1.0, 4.0)} for _ in range(64)
    ]
    common = {"scenario.duration": 8.0}
    df = usm_study.simulate_many("transport-method2", params, overrides=common, jobs=2)
    assert df.height == 64
    assert df["control.k_psi"].to_list() == [p["control.k_psi"] for p in params]
    names = [c for c in df.columns if c not in ("control.k_psi", "control.look_ahead", "ok", "failure")]
    for i, p in enumerate(params):
        r = usm_study.simulate("transport-method2", overrides={**common, **p})
        assert names == list(r.metrics)
        for k in names:
            assert same(df[k][i], r.metrics[k]), (i, k)
        assert df["ok"][i] == r.success
    # The same rows for one thread, from a DataFrame of parameters.
    one = usm_study.simulate_many("transport-method2", pl.DataFrame(params), overrides=common, jobs=1)
    assert one.equals(df)


def test_the_readme_grid_succeeds_where_the_readme_says():
    # README.md's simulate_many example as written (issue 42 item 6): 5 of the 6 rows meet every
    # [success] criterion; k_psi 0.3 with a 1 m look-ahead ends 0.12 m off the path (bound 0.1 m).
    grid = [{"control.k_psi": k, "control.look_ahead": d} for k in (0.3, 0.45, 0.6) for d in (1.0, 2.0)]
    df = usm_study.simulate_many("transport-method2", grid, jobs=2)
    assert df["ok"].to_list() == [False, True, True, True, True, True]


def test_errors_raise_with_the_location(tmp_path):
    assert issubclass(usm_study.UsmStudyError, ValueError)
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nmode = "transport"\nduration = "long"\n')
    with pytest.raises(usm_study.UsmStudyError) as e:
        usm_study.simulate(bad)
    assert str(e.value).startswith(f"{bad}:3:1: scenario.duration: invalid type")
    # The command says the same.
    p = cli("simulate", str(bad), "--out", str(tmp_path / "x"))
    assert p.returncode == 2 and str(e.value) in p.stderr
    design = tmp_path / "design.toml"
    design.write_text('name = "d"\n\n[[body]]\nlength = -1.0\n')
    with pytest.raises(usm_study.UsmStudyError, match=rf"^{design}:\d+:\d+: "):
        usm_study.design(design)
    with pytest.raises(usm_study.UsmStudyError, match=r"control.k_psii: unknown field `k_psii`"):
        usm_study.simulate("transport-method1", overrides={"control.k_psii": 0.3})
    with pytest.raises(usm_study.UsmStudyError, match=r"^params\[1\]: .*scenario.duration: must be a finite number > 0"):
        usm_study.simulate_many("transport-method1", [{"scenario.duration": 5.0}, {"scenario.duration": -1.0}])


def test_ask_tell_random_search_of_10_evaluations(tmp_path):
    problem = usm_study.Problem(DATA / "tune_short.toml")
    names = [p["name"] for p in problem.params]
    assert names == ["control.k_psi", "control.look_ahead", "control.k_1p"]
    # The objective's terms are normalised by their start values: the start scores 1 + 0.5.
    start = problem.evaluate(problem.start)
    assert start.objective == 1.5 and start.violation == 0.0
    rng = random.Random(1)
    best = None
    for _ in range(10):
        x = {}
        for p in problem.params:
            lo, hi = p["lower"], p["upper"]
            u = rng.random()
            x[p["name"]] = lo * (hi / lo) ** u if p["scale"] == "log" else lo + u * (hi - lo)
        metrics, objective, violation = problem.evaluate(x)
        assert set(metrics) == {"energy_per_metre", "overshoot", "completed", "peak_thrust"}
        assert violation >= 0.0 and not math.isnan(objective)
        if best is None or (violation, objective) < (best[2], best[1]):
            best = (x, objective, violation)
    # An evaluation is a function of the point.
    assert problem.evaluate(best[0])[1:] == best[1:]
    with pytest.raises(usm_study.UsmStudyError, match="unknown parameter 'control.kpsi'"):
        problem.evaluate({**problem.start, "control.kpsi": 1.0})
    with pytest.raises(usm_study.UsmStudyError, match="outside its bounds"):
        problem.evaluate({**problem.start, "control.k_psi": 10.0})


def test_optimise_and_ask_tell_score_alike(tmp_path):
    res = usm_study.optimise(DATA / "tune_short.toml", out=tmp_path / "opt", jobs=2, plots=False)
    assert res.evaluations == 20 and res.start_objective == 1.5
    assert (tmp_path / "opt" / "best.toml").is_file() and (tmp_path / "opt" / "report.html").is_file()
    ev = usm_study.Problem(DATA / "tune_short.toml").evaluate(res.best)
    assert ev.objective == res.objective and ev.violation == res.violation


def test_tcm_equals_the_cli(tmp_path):
    r = usm_study.tcm("usm-paper", samples=256, out=tmp_path / "py", jobs=2)
    p = cli("tcm", "usm-paper", "--samples", "256", "--out", str(tmp_path / "cli"))
    assert p.returncode == 0, p.stderr
    cli_summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    for k in ("singular_fraction", "sigma_min", "kappa", "worst", "samples", "seed"):
        assert r.summary[k] == cli_summary[k], k
    assert r.samples.height == 256


def test_sweep_writes_the_cli_outputs(tmp_path):
    study = DATA / "sweep_small.toml"
    r = usm_study.sweep(study, out=tmp_path / "py", jobs=2)
    assert r.counts["cases"] == 4 and r.counts["ok"] + r.counts["unsuccessful"] == 4
    p = cli("sweep", str(study), "--out", str(tmp_path / "cli"), "--jobs", "1")
    assert p.returncode in (0, 1), p.stderr
    cli_cases = pl.read_parquet(tmp_path / "cli" / "cases.parquet")
    # The case table holds no wall times: the same rows, bit for bit (NaN equal to NaN).
    assert r.cases.height == 4 and r.cases.equals(cli_cases)
    for f in ("cases.csv", "summary.md", "manifest.json", "report.html"):
        assert (tmp_path / "py" / f).is_file(), f


def test_ocp_returns_the_trajectory_and_equals_the_cli(tmp_path):
    problem = DATA / "ocp_small.toml"
    r = usm_study.ocp(problem, out=tmp_path / "py")
    assert r.status == "converged" and r.summary["kkt"]["primal"] <= 1e-6
    assert isinstance(r.trajectory, pl.DataFrame) and r.trajectory.height == 7
    assert "u_1" in r.trajectory.columns and "q_1" in r.trajectory.columns
    p = cli("ocp", str(problem), "--out", str(tmp_path / "cli"))
    assert p.returncode == 0, p.stderr
    cli_csv = (tmp_path / "cli" / "trajectory.csv").read_text()
    assert (tmp_path / "py" / "trajectory.csv").read_text() == cli_csv
    cli_summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert r.objective == cli_summary["objective"]
    terms = r.summary["objective_terms"]["path_costs"]["values"]
    assert terms["thruster_energy_static"] > 0.0
