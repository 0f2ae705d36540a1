"""Benchmark (issue 27): simulate_many of N parameter sets on JOBS threads against N
sequential simulate calls of the same sets. Prints wall and CPU times and the wall-time ratio.

    python python/bench/simulate_many.py [N=256] [JOBS=2] [ROUNDS=8]

The sets go in ROUNDS chunks, each chunk once sequentially and once as a batch, the order
alternating from chunk to chunk, so that a change in the machine's other load falls on both
sides alike. Not a test: the ratio depends on the machine and its load (docs/python.md gives
the measured figure). CPU time is the process's (all threads): on a machine whose cores are
busy elsewhere the batch cannot get JOBS cores, and the CPU ratio shows what it would with them.
"""

import os
import random
import sys
import time

import usm_study

n = int(sys.argv[1]) if len(sys.argv) > 1 else 256
jobs = int(sys.argv[2]) if len(sys.argv) > 2 else 2
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 8
rng = random.Random(0)
params = [
    {"control.k_psi": rng.uniform(0.2, 1.0), "control.look_ahead": rng.uniform(1.0, 4.0)} for _ in range(n)
]
scenario = "transport-method1"


def sequential(chunk):
    return [usm_study.simulate(scenario, overrides=p).metrics for p in chunk]


def batch(chunk):
    return usm_study.simulate_many(scenario, chunk, jobs=jobs)


def timed(f, chunk):
    t0, c0 = time.perf_counter(), time.process_time()
    out = f(chunk)
    return out, time.perf_counter() - t0, time.process_time() - c0


t_seq = c_seq = t_many = c_many = 0.0
same = True
size = -(-n // rounds)
for r in range(rounds):
    chunk = params[r * size : (r + 1) * size]
    if not chunk:
        break
    order = [("seq", sequential), ("many", batch)]
    if r % 2:
        order.reverse()
    res = {}
    for name, f in order:
        res[name] = timed(f, chunk)
    single, ts, cs = res["seq"]
    df, tm, cm = res["many"]
    t_seq, c_seq, t_many, c_many = t_seq + ts, c_seq + cs, t_many + tm, c_many + cm
    same = same and all(
        df[k][i] == m[k] or (df[k][i] != df[k][i] and m[k] != m[k]) for i, m in enumerate(single) for k in m
    )
print(f"{n} runs of {scenario} on {os.cpu_count()} cores, {rounds} interleaved rounds; load average {os.getloadavg()}")
print(f"sequential simulate: {t_seq:.2f} s wall, {c_seq:.2f} s CPU ({t_seq / n * 1000:.1f} ms per run)")
print(f"simulate_many jobs={jobs}: {t_many:.2f} s wall, {c_many:.2f} s CPU")
print(f"wall ratio: {t_many / t_seq:.3f}; CPU of the batch / {jobs} threads / sequential CPU: {c_many / jobs / c_seq:.3f}")
print(f"rows equal the single runs: {same}")
