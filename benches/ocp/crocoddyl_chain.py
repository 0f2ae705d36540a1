"""Issue 40's rigid-chain benchmark in Crocoddyl (FDDP, soft terminal weight).

Not part of any test run. Setup (PyPI; Crocoddyl crashes with Pinocchio 4.1):
    python3 -m venv /tmp/ocp-peers
    /tmp/ocp-peers/bin/pip install crocoddyl pin==4.0.0 libpinocchio==4.0.0
    /tmp/ocp-peers/bin/python benches/ocp/crocoddyl_chain.py [terminal_weight]

The model is studies/designs/rigid_chain5.toml: five solid cylinders (CG at the centre,
Ixx = m r²/2, Iyy = Izz = m (3r² + l²)/12), free-flyer root at the tail face of L0, joints
at the front faces alternating yaw (z) / pitch (y), tip at the front face of L4, gravity
off. Controls: the full generalised force (6-D base wrench in the base frame + 4 joint
torques). Symplectic Euler (IntegratedActionModelEuler), N = 100, T = 10 s.
J = Σ dt ‖u‖² (control residual weight 2: Crocoddyl's cost is ½ w ‖r‖² dt).
"""

import sys
import time

import numpy as np
import pinocchio as pin
import crocoddyl

MASSES = [14.3, 12.7, 9.8, 12.7, 7.8]
LENGTHS = [0.62, 0.584, 0.726, 0.584, 0.37]
RADIUS = 0.085
T, N = 10.0, 100
DISPLACEMENT = np.array([0.0, 0.3, -0.2])


def chain():
    model = pin.Model()
    parent = 0
    for i, (m, l) in enumerate(zip(MASSES, LENGTHS)):
        if i == 0:
            jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
        else:
            joint = pin.JointModelRZ() if i % 2 == 1 else pin.JointModelRY()
            place = pin.SE3(np.eye(3), np.array([LENGTHS[i - 1], 0.0, 0.0]))
            jid = model.addJoint(parent, joint, place, f"j{i}")
        side = m * (3 * RADIUS**2 + l**2) / 12
        inertia = np.diag([m * RADIUS**2 / 2, side, side])
        model.appendBodyToJoint(jid, pin.Inertia(m, np.array([l / 2, 0.0, 0.0]), inertia),
                                pin.SE3.Identity())
        parent = jid
    tip_place = pin.SE3(np.eye(3), np.array([LENGTHS[-1], 0.0, 0.0]))
    try:
        frame = pin.Frame("tip", parent, 0, tip_place, pin.FrameType.OP_FRAME)
    except TypeError:
        frame = pin.Frame("tip", parent, tip_place, pin.FrameType.OP_FRAME)
    tip = model.addFrame(frame)
    model.gravity.setZero()
    return model, tip


def main():
    w_term = float(sys.argv[1]) if len(sys.argv) > 1 else 1e6
    model, tip = chain()
    data = model.createData()
    q0 = pin.neutral(model)
    pin.framesForwardKinematics(model, data, q0)
    target = data.oMf[tip].translation + DISPLACEMENT
    state = crocoddyl.StateMultibody(model)
    act = crocoddyl.ActuationModelFull(state)
    nu = act.nu
    dt = T / N
    run_costs = crocoddyl.CostModelSum(state, nu)
    run_costs.addCost("u", crocoddyl.CostModelResidual(state, crocoddyl.ResidualModelControl(state, nu)), 2.0)
    term_costs = crocoddyl.CostModelSum(state, nu)
    term_costs.addCost("tip", crocoddyl.CostModelResidual(
        state, crocoddyl.ResidualModelFrameTranslation(state, tip, target, nu)), w_term)
    x0 = np.concatenate([q0, np.zeros(model.nv)])
    weights = np.concatenate([np.zeros(model.nv), np.ones(model.nv)])
    term_costs.addCost("v", crocoddyl.CostModelResidual(
        state, crocoddyl.ActivationModelWeightedQuad(weights),
        crocoddyl.ResidualModelState(state, x0, nu)), w_term)
    running = crocoddyl.IntegratedActionModelEuler(
        crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, run_costs), dt)
    terminal = crocoddyl.IntegratedActionModelEuler(
        crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, term_costs), 0.0)
    problem = crocoddyl.ShootingProblem(x0, [running] * N, terminal)
    solver = crocoddyl.SolverFDDP(problem)
    solver.th_stop = 1e-12
    c0, w0 = time.process_time(), time.perf_counter()
    solver.solve([], [], 2000)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    j = sum(dt * float(u @ u) for u in solver.us)
    xn = solver.xs[-1]
    pin.framesForwardKinematics(model, data, xn[: model.nq])
    tip_err = np.linalg.norm(data.oMf[tip].translation - target)
    print(f"crocoddyl FDDP: terminal weight {w_term:g}, iterations {solver.iter}, "
          f"CPU {cpu:.3f} s (wall {wall:.3f} s), J = {j:.6f}, tip error {tip_err * 1e3:.4f} mm, "
          f"max |v_N| {np.abs(xn[model.nq:]).max():.2e}")


if __name__ == "__main__":
    main()
