#!/usr/bin/env python3
"""Issue 23: time `usm-study simulate transport-method1 --no-plots` against MuJoCo's
physics-only rollout of the same body, in one invocation on one machine.

1. Runs `usm-study simulate transport-method1 --no-plots --set scenario.log_dt=0.05` once,
   untimed, to log every control period's commands (joint references qref_* and thrusts
   u_*): the replay input. A second untimed run at rtol 1e-12 is our own reference.
2. Builds an MJCF of the run's design from `usm-study design show <design>` (masses,
   inertias, lengths, joints, thrusters: nothing retyped) for several integrator settings,
   and replays those commands with a zero-order hold per control period for the whole run.
3. Times, REPEATS times and interleaved so that both see the same machine load, the plain
   `usm-study simulate transport-method1 --no-plots` (`timing.total_s` and
   `timing.dynamics_s` of its summary.json) and the mj_step loop of every setting (model
   compiled and data reset before the clock starts; one thread).
4. Reports each side's own convergence: the final base position against its own tight
   reference (MuJoCo: RK4 at 0.25 ms; ours: Dormand-Prince at rtol 1e-12), and, for
   orientation only (different hydrodynamics, not an accuracy test), the distance between
   MuJoCo's and our final base positions.

See README.md beside this file for what the MuJoCo model is and is not.
"""
import argparse
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from datetime import datetime, timezone
from pathlib import Path

try:
    import numpy as np
    import mujoco
except ImportError as e:  # a clear message, not a traceback
    sys.exit(f"rollout.py needs the Python packages mujoco and numpy ({e}).\n"
             "Install them in a virtual environment:\n"
             "  python3 -m venv VENV && VENV/bin/pip install mujoco numpy\n"
             "and run this script with VENV/bin/python.")

SCENARIO = "transport-method1"
# The scenario's ideal joint servos: q'' = wn^2 (q_r - q) - 2 zeta wn q'. These are
# usm-study's defaults (src/dynamics/config.rs, docs/assumptions.md); the script checks
# them against the logged joint angles (check_servo) rather than trusting them.
SERVO_WN, SERVO_ZETA = 5.0, 1.0
# Joint armature [kg m^2] that makes MuJoCo's position servos behave like ideal ones: with
# kp = A wn^2 and kv = 2 zeta wn A the joint obeys the filter up to O(M_qq / A) while the
# base feels the reaction -M_12 q'' of the hybrid dynamics (see README.md).
ARMATURE = 1e6
WATER_VISCOSITY = 0.0009  # dynamic viscosity [Pa s], MuJoCo's Stokes term (negligible here)
# (name, integrator, dt [s]); every dt divides the 50 ms control period.
SETTINGS = [
    ("Euler 2 ms", "Euler", 0.002),
    ("Euler 10 ms", "Euler", 0.010),
    ("implicitfast 2 ms", "implicitfast", 0.002),
    ("implicitfast 10 ms", "implicitfast", 0.010),
    ("RK4 2 ms", "RK4", 0.002),
    ("RK4 10 ms", "RK4", 0.010),
    ("RK4 25 ms", "RK4", 0.025),
    ("RK4 50 ms", "RK4", 0.050),
]
REFERENCE = ("RK4 0.25 ms (reference)", "RK4", 0.00025)
OUR_REFERENCE_RTOL = 1e-12  # usm-study's own reference: Dormand-Prince, atol = rtol / 10


def find_usm_study(arg):
    """The usm-study binary: --usm-study, else the repository's release build, else PATH."""
    repo = Path(__file__).resolve().parents[2]
    for cand in ([arg] if arg else [repo / "target/release/usm-study", shutil.which("usm-study")]):
        if cand and Path(cand).is_file() and os.access(cand, os.X_OK):
            return str(cand)
    sys.exit(f"usm-study binary not found ({arg or 'target/release/usm-study or PATH'}): "
             "build it with `cargo build --release` or pass --usm-study PATH")


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"command failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr[-2000:]}")
    return r.stdout


def simulate(usm, out, *extra):
    run([usm, "simulate", SCENARIO, "--no-plots", "--out", str(out), *extra])
    return json.loads((out / "summary.json").read_text())


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    return {n: data[:, i] for i, n in enumerate(names)}


# ---------------------------------------------------------------- the MJCF of the design
def v(x):
    return " ".join(repr(float(c)) for c in x)


def check_neutral(design):
    """Gravity 0 stands for neutral buoyancy only if weight = buoyancy and CB = CG per body."""
    rho = design["fluid"]["rho"]
    for b in design["body"]:
        if abs(b["mass"] - rho * b["volume"]) > 1e-9 * b["mass"] or b["cg"] != b["cb"]:
            sys.exit(f"body {b['name']} is not neutrally buoyant with CB at CG: "
                     "gravity 0 would not model it; extend rollout.py")
    if any(design["fluid"].get("current", [0, 0, 0])):
        sys.exit("the design has a water current: rollout.py models still water only")


def mjcf(design, integrator, dt, init_pos, init_quat):
    rho = design["fluid"]["rho"]
    bodies, joints = design["body"], design["joint"]
    kp = ARMATURE * SERVO_WN ** 2
    kv = 2.0 * SERVO_ZETA * SERVO_WN * ARMATURE

    def body_xml(i, pos, indent):
        b = bodies[i]
        I = b["inertia"]
        pad = "  " * indent
        s = [f'{pad}<body name="{b["name"]}" pos="{v(pos)}"'
             + (f' quat="{v(init_quat)}">' if i == 0 else ">")]
        if i == 0:
            s.append(f'{pad}  <freejoint name="base"/>')
        else:
            j = joints[i - 1]
            lo, hi = (math.radians(a) for a in j["limits_deg"])
            s.append(f'{pad}  <joint name="{j["name"]}" type="hinge" axis="{v(j["axis"])}" '
                     f'range="{lo!r} {hi!r}" limited="true" armature="{ARMATURE!r}"/>')
        s.append(f'{pad}  <inertial pos="{v(b["cg"])}" mass="{b["mass"]!r}" fullinertia="'
                 f'{v([I[0][0], I[1][1], I[2][2], I[0][1], I[0][2], I[1][2]])}"/>')
        # The link as a cylinder along body x; MuJoCo's fluid model sees the ellipsoid of
        # semi-axes (r, r, l/2) inscribed in it.
        s.append(f'{pad}  <geom type="cylinder" fromto="0 0 0 {b["length"]!r} 0 0" '
                 f'size="{b["radius"]!r}" fluidshape="ellipsoid" contype="0" conaffinity="0"/>')
        for t in design["thruster"]:
            if t["body"] == b["name"]:
                s.append(f'{pad}  <site name="{t["name"]}" pos="{v(t["position"])}"/>')
        if i + 1 < len(bodies):
            s += body_xml(i + 1, joints[i]["position"], indent + 1)
        s.append(f"{pad}</body>")
        return s

    acts = [f'    <general name="servo_{j["name"]}" joint="{j["name"]}" ctrllimited="false" '
            f'gaintype="fixed" gainprm="{kp!r}" biastype="affine" biasprm="0 {-kp!r} {-kv!r}"/>'
            for j in joints]
    acts += [f'    <motor name="{t["name"]}" site="{t["name"]}" gear="{v(t["direction"])} 0 0 0" '
             f'ctrllimited="true" ctrlrange="{t["u_min"]!r} {t["u_max"]!r}"/>'
             for t in design["thruster"]]
    return "\n".join([
        f'<mujoco model="{design["name"]}">',
        '  <compiler angle="radian" inertiafromgeom="false"/>',
        f'  <option timestep="{dt!r}" integrator="{integrator}" gravity="0 0 0" '
        f'density="{rho!r}" viscosity="{WATER_VISCOSITY!r}">',
        '    <flag contact="disable"/>',
        '  </option>',
        '  <worldbody>',
        *body_xml(0, init_pos, 2),
        '  </worldbody>',
        '  <actuator>', *acts, '  </actuator>',
        '</mujoco>'])


def quat_from_rpy(roll, pitch, yaw):
    """(w, x, y, z) of R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return [cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy]


# ---------------------------------------------------------------- the rollout
def rollout(m, d, ctrl, per_period, record=False):
    """Zero-order hold: ctrl[k] for per_period steps, k = 0 .. len(ctrl)-1. The timed part
    is this loop alone (mj_step's own nstep loop runs in C). Returns (seconds, qpos log)."""
    mujoco.mj_resetData(m, d)
    log = np.empty((len(ctrl) + 1, m.nq)) if record else None
    if record:
        log[0] = d.qpos
    t0 = time.perf_counter()
    for k in range(len(ctrl)):
        d.ctrl[:] = ctrl[k]
        mujoco.mj_step(m, d, nstep=per_period)
        if record:
            log[k + 1] = d.qpos
    return time.perf_counter() - t0, log


def check_servo(ts, control_dt):
    """Our logged joint angles must be the ideal filter's response to the logged references
    (exact ZOH discretisation), else SERVO_WN / SERVO_ZETA are not the scenario's."""
    wn, z = SERVO_WN, SERVO_ZETA
    A = np.array([[0.0, 1.0], [-wn * wn, -2 * z * wn]])
    # exp(A h) and its input integral by a fine Taylor series (h = 50 ms, |A h| < 1).
    h, E, G, term = control_dt, np.eye(2), np.eye(2) * control_dt, np.eye(2)
    for n in range(1, 30):
        term = term @ A * h / n
        E = E + term
        G = G + term * h / (n + 1)
    b = G @ np.array([0.0, wn * wn])
    worst = 0.0
    for j in range(1, 100):
        if f"q_{j}" not in ts:
            break
        x = np.array([ts[f"q_{j}"][0], ts[f"qd_{j}"][0]])
        for k in range(len(ts["t"]) - 1):
            x = E @ x + b * ts[f"qref_{j}"][k]
            worst = max(worst, abs(x[0] - ts[f"q_{j}"][k + 1]))
    if worst > 1e-6:
        sys.exit(f"the scenario's joints do not follow an ideal servo with wn = {wn}, "
                 f"zeta = {z} (max |q - filter| = {worst:.2e} rad): update SERVO_WN/SERVO_ZETA")
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--usm-study", help="path of the usm-study binary")
    ap.add_argument("--repeats", type=int, default=10)
    ap.add_argument("--json", default=str(Path(__file__).with_name("rollout.json")),
                    help="where to write the results (default: rollout.json beside this file)")
    args = ap.parse_args()
    usm = find_usm_study(args.usm_study)
    tmp = Path(tempfile.mkdtemp(prefix="usm-mujoco-"))

    # The replay input: every control period's commands (an extra, untimed run that logs at
    # the control rate instead of the preset's 10 Hz).
    s = simulate(usm, tmp / "commands", "--set", "scenario.log_dt=0.05")
    ts = read_csv(tmp / "commands" / "timeseries.csv")
    t = ts["t"]
    control_dt = float(np.round(t[1] - t[0], 12))
    design = tomllib.loads(run([usm, "design", "show", s["design"]]))
    check_neutral(design)
    servo_err = check_servo(ts, control_dt)
    nq, nu = len(design["joint"]), len(design["thruster"])
    periods = len(t) - 1
    ctrl = np.column_stack([ts[f"qref_{j + 1}"] for j in range(nq)]
                           + [ts[f"u_{j + 1}"] for j in range(nu)])[:periods]
    init_pos = [ts["base_x"][0], ts["base_y"][0], ts["base_z"][0]]
    init_quat = quat_from_rpy(ts["base_roll"][0], ts["base_pitch"][0], ts["base_yaw"][0])
    ours_final = np.array([ts["base_x"][-1], ts["base_y"][-1], ts["base_z"][-1]])
    q_ours = np.column_stack([ts[f"q_{j + 1}"] for j in range(nq)])
    # Our own convergence, the same measure as MuJoCo's below: the final base position of the
    # default run against one at tolerances five decades tighter (untimed).
    tight = simulate(usm, tmp / "tight", "--set", f"physics.rtol={OUR_REFERENCE_RTOL}",
                     "--set", f"physics.atol={OUR_REFERENCE_RTOL / 10}", "--set",
                     "scenario.log_dt=0.05")
    tts = read_csv(tmp / "tight" / "timeseries.csv")
    ours_ref = np.array([tts["base_x"][-1], tts["base_y"][-1], tts["base_z"][-1]])

    # MuJoCo models (compiled once, outside any timing), their trajectories and accuracy.
    mj, ref_final = [], None
    for name, integ, dt in [REFERENCE] + SETTINGS:
        m = mujoco.MjModel.from_xml_string(mjcf(design, integ, dt, init_pos, init_quat))
        d = mujoco.MjData(m)
        per = round(control_dt / dt)
        assert abs(per * dt - control_dt) < 1e-12, (name, dt)
        wall, log = rollout(m, d, ctrl, per, record=True)
        final = log[-1, :3].copy()
        if ref_final is None:
            ref_final = final
            print(f"{name}: {wall:.1f} s", file=sys.stderr)
            continue
        mj.append((m, d, per, {
            "setting": name, "integrator": integ, "dt_s": dt, "steps": per * periods,
            "final_base_position": final.tolist(),
            "error_vs_reference_m": float(np.linalg.norm(final - ref_final)),
            "distance_from_usm_study_final_m": float(np.linalg.norm(final - ours_final)),
            "max_joint_deviation_from_usm_study_rad":
                float(np.max(np.abs(log[:, 7:7 + nq] - q_ours))),
        }, []))

    # The loop's floor: the same Python loop (2800 ctrl writes and mj_step calls) on a 1-DOF
    # model, i.e. what of each MuJoCo time is the per-period Python side, not physics.
    floor_m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint name="s" type="slide"/><geom size=".1"/></body>'
        '</worldbody><actuator>' + '<motor joint="s"/>' * ctrl.shape[1] + '</actuator></mujoco>')
    floor_d, floor = mujoco.MjData(floor_m), []

    # Timing: each repeat runs our closed loop once, then every MuJoCo setting once, so that
    # both see the same machine load.
    ours = []
    for r in range(args.repeats):
        ours.append(simulate(usm, tmp / f"run{r}")["timing"])
        for m, d, per, _, times in mj:
            times.append(rollout(m, d, ctrl, per)[0])
        floor.append(rollout(floor_m, floor_d, ctrl, 1)[0])
        print(f"repeat {r + 1}/{args.repeats}: usm-study {ours[-1]['total_s'] * 1e3:.1f} ms, "
              + ", ".join(f"{row['setting']} {times[-1] * 1e3:.0f} ms" for *_, row, times in mj),
              file=sys.stderr)
    mujoco_results = []
    for *_, row, times in mj:
        row["wall_min_s"], row["wall_median_s"] = min(times), statistics.median(times)
        mujoco_results.append(row)
    mujoco_results.insert(0, {"setting": REFERENCE[0], "integrator": REFERENCE[1],
                              "dt_s": REFERENCE[2], "steps": round(control_dt / REFERENCE[2]) * periods,
                              "final_base_position": ref_final.tolist(),
                              "distance_from_usm_study_final_m":
                                  float(np.linalg.norm(ref_final - ours_final))})

    tot = [o["total_s"] for o in ours]
    dyn = [o["dynamics_s"] for o in ours]
    result = {
        "issue": 23,
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "machine": {"platform": platform.platform(), "processor": cpu_name(),
                    "cpus": os.cpu_count(), "load_average_1min_at_end": os.getloadavg()[0],
                    "python": platform.python_version(), "mujoco": mujoco.__version__,
                    "usm_study": run([usm, "--version"]).strip()},
        "scenario": SCENARIO, "design": design["name"], "simulated_s": float(t[-1]),
        "control_dt_s": control_dt, "repeats": args.repeats,
        "usm_study": {
            "what": "closed loop: physics (adaptive Dormand-Prince 5(4)), LOS guidance, control, "
                    "QP allocation, metrics, logging (timing.total_s of summary.json)",
            "total_min_s": min(tot), "total_median_s": statistics.median(tot),
            "dynamics_min_s": min(dyn), "dynamics_median_s": statistics.median(dyn),
            "physics_evaluations": ours[0]["physics_evaluations"],
            "physics_steps": ours[0]["physics_steps"],
            "final_base_position": ours_final.tolist(),
            "reference": f"Dormand-Prince rtol {OUR_REFERENCE_RTOL:g}, "
                         f"{tight['timing']['physics_steps']} steps",
            "error_vs_reference_m": float(np.linalg.norm(ours_final - ours_ref)),
        },
        "mujoco": {
            "what": "physics only: replay of the run's joint references and thrusts "
                    "(zero-order hold per control period), mj_step loop timed",
            "model": {"fluid": "MuJoCo ellipsoid model (fluidshape=ellipsoid), "
                               f"density {design['fluid']['rho']}, viscosity {WATER_VISCOSITY}",
                      "gravity": 0.0, "armature_kg_m2": ARMATURE,
                      "servo_wn": SERVO_WN, "servo_zeta": SERVO_ZETA,
                      "servo_check_max_error_rad": servo_err},
            "settings": mujoco_results,
            "loop_floor": {"what": "the same per-period Python loop on a 1-DOF model "
                                   "(ctrl write + one mj_step call per control period)",
                           "wall_min_s": min(floor), "wall_median_s": statistics.median(floor)},
        },
    }
    Path(args.json).write_text(json.dumps(result, indent=2) + "\n")
    print(table(result))
    shutil.rmtree(tmp, ignore_errors=True)


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def table(r):
    u = r["usm_study"]
    lines = [
        "| run | min [ms] | median [ms] | steps | final base position vs own reference [m] |",
        "|---|---:|---:|---:|---:|",
        f"| usm-study closed loop, `timing.total_s` | {u['total_min_s'] * 1e3:.1f} | "
        f"{u['total_median_s'] * 1e3:.1f} | {u['physics_steps']} ({u['physics_evaluations']} evals) | "
        f"{u['error_vs_reference_m']:.1e} (vs rtol {OUR_REFERENCE_RTOL:g}) |",
        f"| usm-study, of which `timing.dynamics_s` | {u['dynamics_min_s'] * 1e3:.1f} | "
        f"{u['dynamics_median_s'] * 1e3:.1f} | | |",
    ]
    for s in r["mujoco"]["settings"]:
        if "wall_min_s" not in s:
            continue  # the reference: run once, untimed
        lines.append(f"| MuJoCo {s['setting']} | {s['wall_min_s'] * 1e3:.1f} | "
                     f"{s['wall_median_s'] * 1e3:.1f} | {s['steps']} | "
                     f"{s['error_vs_reference_m']:.1e} (vs RK4 0.25 ms) |")
    f = r["mujoco"]["loop_floor"]
    lines.append(f"| loop floor (Python loop, 1-DOF model) | {f['wall_min_s'] * 1e3:.1f} | "
                 f"{f['wall_median_s'] * 1e3:.1f} | {r['simulated_s'] / r['control_dt_s']:.0f} | |")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
