#!/usr/bin/env python3
"""Robust tuning of single designs of the main study, scored in the study's own worlds.

The main study tunes each design in its nominal world (`[tune]` has no worlds) and then scores
the tuned gains in 16 sampled worlds. This experiment asks what a design costs when its gains are
tuned against perturbed worlds too: for each (design, tuning seed) it

1. writes an `optimise` problem from studies/thrusters.toml: the design fixed, the study's
   `[tune]` as the problem's `[[param]]`/`[objective]`/`[[constraint]]`, `[solver]` = Bayesian
   optimisation with 75 evaluations, and `[uncertainty]` with WORLDS worlds sampled from the
   tuning seed (not the study's seed 2024, so the tuning worlds are not the scoring worlds);
   every constraint must hold in every tuning world, the objective is the mean `mission_cost`;
2. runs `usm-study optimise` on it;
3. writes a one-case sweep of studies/thrusters.toml at the best gains (no `[tune]`, the gains in
   `[control]`) and runs it: the nominal world, the study's 16 worlds, the validation variants
   and the single faults, exactly as the main study scores a tuned design.

    cargo build --release
    python3 benches/robust_tuning/run.py [--bin target/release/usm-study] [--out /tmp/robust]

Prints one row per run and writes results.csv in the output folder. Nothing is deleted: a
rerun overwrites the files the tool wrote in its own `optimise-*` and `score-*` folders. About 40 s per row on one
core (75 evaluations x 8 worlds of the 140 s scenario, then the scoring sweep).
"""
import argparse
import csv
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
STUDY = os.path.join(HERE, "..", "..", "studies", "thrusters.toml")
GAINS = ["k_psi", "look_ahead", "k_6p", "k_6d"]
# (rule, links, offset): the committed verdict's leader family and the nominal cheapest design.
DESIGNS = [("ends", 4, "0.14"), ("paper", 4, "0.06")]
SEEDS = [7, 11]
WORLDS = 8


def cut(s, start, end):
    a = s.index(start)
    return s[:a] + s[s.index(end, a):]


def problem(src, rule, links, off, seed, worlds):
    s = src.replace("seed = 2024", f"seed = {seed}", 1)
    s = s.replace('output = "results/thrusters"\n', "", 1)
    s = s.replace('pareto = ["mission_cost", "tcm_singular_fraction_commanded"]\n', "", 1)
    s = s.replace(
        "[design.generator]\nlinks = 5\n",
        f'[design.generator]\nlinks = {links}\nthruster_rule = "{rule}"\nlongitudinal_offset = {off}\n',
        1,
    )
    s = cut(s, "\n[faults]\n", "\n[allocation]\n")
    s = cut(s, "\n[[axis]]\n", "\n# ---- uncertain worlds")
    s = s[: s.index("# ---- held-out validation")]
    s = s.replace("[tune]\nstarts = 3\n", "")
    for a, b in [
        ("[[tune.param]]", "[[param]]"),
        ("[tune.objective]", "[objective]"),
        ("[[tune.objective.term]]", "[[objective.term]]"),
        ("[[tune.constraint]]", "[[constraint]]"),
    ]:
        s = s.replace(a, b)
    s, n = re.subn(r"\[tune\.solver\]\n(?:[a-z_]+ = [^\n]*\n)+", '[solver]\nmethod = "bayes"\nmax_evals = 75\n', s)
    if n != 1 or "worlds = 16" not in s:
        sys.exit("studies/thrusters.toml no longer has the sections this script edits")
    return s.replace("worlds = 16", f"worlds = {worlds}", 1)


def scoring(src, rule, links, off, gains):
    s = src.replace('output = "results/thrusters"\n', "", 1)
    a, b = s.index("\n[tune]\n"), s.index("\n[[axis]]\n")
    control = "".join(f"{k} = {v}\n" for k, v in zip(GAINS, gains))
    s = s[:a] + "\n[control]\n" + control + s[b:]
    s = s.replace('values = ["paper", "distributed", "ends"]', f'values = ["{rule}"]', 1)
    s = s.replace("range = { start = 3, stop = 9, steps = 7 }", f"values = [{links}]", 1)
    return s.replace("values = [0.06, 0.10, 0.14]", f"values = [{off}]", 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(HERE, "..", "..", "target", "release", "usm-study"))
    ap.add_argument("--out", default="/tmp/robust_tuning")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    src = open(STUDY).read()
    rows = []
    for rule, links, off in DESIGNS:
        for seed in SEEDS:
            tag = f"{rule}{links}-{off}-s{seed}"
            p = os.path.join(a.out, f"problem-{tag}.toml")
            open(p, "w").write(problem(src, rule, links, off, seed, WORLDS))
            o = os.path.join(a.out, f"optimise-{tag}")
            r = subprocess.run([a.bin, "optimise", p, "--out", o, "--no-plots", "--jobs", "1"],
                               capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"optimise {p}: {r.stderr}")
            feasible = "feasible)" in r.stdout + r.stderr and "infeasible)" not in r.stdout + r.stderr
            best = open(os.path.join(o, "best.toml")).read()
            gains = [re.search(rf"#   control\.{k} = (\S+)", best).group(1) for k in GAINS]
            sp = os.path.join(a.out, f"score-{tag}.toml")
            open(sp, "w").write(scoring(src, rule, links, off, gains))
            so = os.path.join(a.out, f"score-{tag}")
            r = subprocess.run([a.bin, "sweep", sp, "--out", so], capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"sweep {sp}: {r.stderr}")
            case = next(csv.DictReader(open(os.path.join(so, "cases.csv"))))
            row = {"design": f"{rule}/{links}/{off}", "tuning_seed": seed, "tuning_feasible": feasible}
            row.update({k: float(g) for k, g in zip(GAINS, gains)})
            for k in ["mission_cost", "mission_cost_mean", "mission_cost_p95", "success_probability", "fault_tolerance"]:
                row[k] = float(case[k])
            rows.append(row)
            print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()), flush=True)
    with open(os.path.join(a.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
