"""Tune studies/tune_transport.toml with Optuna's TPE through usm_study's ask/tell Problem.

    python3 -m venv v && v/bin/pip install ./python optuna
    v/bin/python python/examples/optuna_tpe.py [PROBLEM] [TRIALS] [SEED]

The same budget as the file's own Nelder–Mead (`[solver] max_evals`, the start point among
them), the start point enqueued first, the summed constraint violation handed to TPE
as the trial's constraint (`Trial.set_constraint`, Optuna >= 5; <= 0 is feasible). A run whose
objective is NaN (a metric undefined, e.g. no convergence) is infeasible already (the violation
counts it) and reports a large finite value, which TPE accepts. docs/python.md gives the result beside `usm-study
optimise`'s.
"""

import math
import sys
import time

import optuna

import usm_study

path = sys.argv[1] if len(sys.argv) > 1 else "studies/tune_transport.toml"
problem = usm_study.Problem(path)
trials = int(sys.argv[2]) if len(sys.argv) > 2 else problem.max_evals
seed = int(sys.argv[3]) if len(sys.argv) > 3 else 0


def objective(trial: optuna.Trial) -> float:
    x = {
        p["name"]: trial.suggest_float(p["name"], p["lower"], p["upper"], log=p["scale"] == "log")
        for p in problem.params
    }
    metrics, value, violation = problem.evaluate(x)
    trial.set_constraint("violation", violation)
    trial.set_user_attr("violation", violation)
    for k, v in metrics.items():
        trial.set_user_attr(k, v)
    return value if math.isfinite(value) else 1e6


optuna.logging.set_verbosity(optuna.logging.WARNING)
sampler = optuna.samplers.TPESampler(seed=seed)
study = optuna.create_study(direction="minimize", sampler=sampler)
study.enqueue_trial(problem.start)
t0 = time.perf_counter()
study.optimize(objective, n_trials=trials)
elapsed = time.perf_counter() - t0

feasible = [t for t in study.trials if t.user_attrs["violation"] == 0.0]
best = min(feasible, key=lambda t: t.value) if feasible else min(study.trials, key=lambda t: t.user_attrs["violation"])
start = study.trials[0]
print(f"{problem.name}: TPE (seed {seed}), {len(study.trials)} evaluations in {elapsed:.1f} s, {len(feasible)} feasible")
print(f"objective {start.value:.4f} -> {best.value:.4f} (trial {best.number}, violation {best.user_attrs['violation']})")
for p in problem.params:
    print(f"  {p['name']:<22} {p['start']:>10.4f} -> {best.params[p['name']]:.4f}")
for k in ("energy_per_metre", "cross_track_rms", "convergence_time"):
    if k in best.user_attrs:
        print(f"  {k:<22} {start.user_attrs[k]:>10.4f} -> {best.user_attrs[k]:.4f}")
