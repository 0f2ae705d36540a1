#!/usr/bin/env python3
"""MuJoCo check of `usm-study design export --format mjcf` (docs/urdf.md "MJCF").

Loads the MJCF export of a design (default usm-paper) with the PyPI `mujoco` package and
compares MuJoCo's joint-space mass matrix with usm-study's rigid-body one (`inspect --state S
--format json --rigid`) at random configurations (base pose and joint angles within the limits).

MuJoCo's free joint velocity is [linear velocity of the body origin in the world frame; angular
velocity in the body frame], usm-study's is the base twist [v; w] in F_b, so
M_ours = J^T M_mujoco J with J = blockdiag(R, I3, I_n).

Usage: benches/mujoco_check.py [--bin target/release/usm-study] [--design usm-paper]
                               [--samples 20] [--seed 1] [--tol 1e-9]
Exit 0 when every sample agrees (or mujoco/numpy is absent: a printed reason, skipped),
1 when one does not.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.environ.get("USM_STUDY", "target/release/usm-study"))
    ap.add_argument("--design", default="usm-paper")
    ap.add_argument("--samples", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--tol", type=float, default=1e-9)
    a = ap.parse_args()
    try:
        import mujoco
        import numpy as np
    except ImportError as e:
        print(f"mujoco_check: SKIPPED: {e} (pip install mujoco numpy to run it)")
        return 0
    rng = np.random.default_rng(a.seed)
    with tempfile.TemporaryDirectory() as tmp:
        xml = os.path.join(tmp, "design.xml")
        subprocess.run([a.bin, "design", "export", a.design, "--format", "mjcf", "--out", xml],
                       check=True, capture_output=True)
        model = mujoco.MjModel.from_xml_path(xml)
        data = mujoco.MjData(model)
        n = model.nv - 6
        lo = model.jnt_range[1:, 0]
        hi = model.jnt_range[1:, 1]
        worst = 0.0
        for k in range(a.samples):
            q = rng.uniform(lo, hi)
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            pos = rng.uniform(-5, 5, size=3)
            data.qpos[:] = np.concatenate([pos, quat, q])
            mujoco.mj_forward(model, data)
            m_mj = np.zeros((model.nv, model.nv))
            try:
                mujoco.mj_fullM(model, data, m_mj)  # mujoco >= 3.4 / 4.x
            except TypeError:
                mujoco.mj_fullM(model, m_mj, data.qM)  # older releases
            r = np.zeros(9)
            mujoco.mju_quat2Mat(r, quat)
            r = r.reshape(3, 3)
            state = os.path.join(tmp, "state.json")
            with open(state, "w") as f:
                json.dump({"base_position": pos.tolist(), "base_rotation": r.tolist(),
                           "joint_angles": q.tolist()}, f)
            out = subprocess.run([a.bin, "inspect", a.design, "--state", state, "--format",
                                  "json", "--rigid"], check=True, capture_output=True, text=True)
            m_us = np.array(json.loads(out.stdout)["mass_matrix"])
            j = np.eye(model.nv)
            j[:3, :3] = r
            m_cmp = j.T @ m_mj @ j
            err = np.abs(m_cmp - m_us).max() / max(1.0, np.abs(m_us).max())
            worst = max(worst, err)
            if err > a.tol:
                print(f"mujoco_check: FAILED at sample {k}: max relative error {err:.3e} > {a.tol}")
                return 1
        print(f"mujoco_check: ok: {a.design}, {a.samples} random configurations, {6 + n} dof, "
              f"max |M_ours - J^T M_mujoco J| / max|M| = {worst:.3e} (tol {a.tol}); "
              f"mujoco {mujoco.__version__}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
