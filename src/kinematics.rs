//! Forward kinematics, geometric Jacobians and the thruster configuration matrix (docs/model.md §3,
//! USM-1 … USM-18, USM-25/26).
//!
//! All functions write into a preallocated [`KinWorkspace`] or output buffer: nothing here
//! allocates once the workspace exists. Names say the frame: `g_b[i]` is body `i` in the base
//! frame `F_b`, `g_be` the end-effector in `F_b`.

use crate::model::{Joint, Vehicle};
use crate::spatial::{rot_axis_angle, stack, Mat3, Se3, Vec3, Vec6};
use faer::Mat;
use nalgebra::{Matrix6xX, UnitQuaternion};

/// The pose of the base frame in the inertial frame: `g_Ib = (R_Ib, p_Ib)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasePose {
    /// Orientation (maps base-frame vectors to the inertial frame).
    pub orientation: UnitQuaternion<f64>,
    /// Position of the base origin in the inertial frame [m].
    pub position: Vec3,
}

impl Default for BasePose {
    fn default() -> Self {
        Self {
            orientation: UnitQuaternion::identity(),
            position: Vec3::zeros(),
        }
    }
}

impl BasePose {
    /// As a transform `g_Ib`.
    pub fn to_se3(&self) -> Se3 {
        Se3::new(
            *self.orientation.to_rotation_matrix().matrix(),
            self.position,
        )
    }
}

/// The structure of joint `k`'s transform `g_(k)(k+1)(q) = placement · Rot(axis, q)` that the
/// position pass and the dynamics passes exploit (issue 23).
///
/// When the placement is a pure translation along the parent's x axis and the axis is a
/// coordinate axis `e_a` (every preset and generated design), `g = (Rot(e_a, q), (x, 0, 0))`:
/// the rotation has a unit entry and four exact zeros, the translation two exact zeros.
/// Products with it skip the multiplications by those zeros and ones. They sum the same
/// nonzero terms in the same order as the dense products, so every result is the dense
/// result bit for bit (a skipped `±0` can only change the sign of a result that is zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointShape {
    /// Any other placement or axis: the dense products.
    General,
    /// Placement `(I, (x, 0, 0))`, axis `e_a` with `a` = 0, 1, 2 for x, y, z.
    Axial(usize),
}

impl JointShape {
    /// The shape of `joint` (exact comparisons: only exact zeros and ones are skipped).
    pub fn of(joint: &Joint) -> Self {
        let pl = &joint.placement;
        if pl.r != Mat3::identity() || pl.p.y != 0.0 || pl.p.z != 0.0 {
            return JointShape::General;
        }
        (0..3)
            .find(|&a| joint.axis == Vec3::ith(a, 1.0))
            .map_or(JointShape::General, JointShape::Axial)
    }
}

/// The two axes after `a` in cyclic order: `Rot(e_a, θ)` has `cos θ` at `(b, b)` and `(c, c)`,
/// `−sin θ` at `(b, c)` and `sin θ` at `(c, b)`.
#[inline(always)]
pub(crate) const fn cyclic(a: usize) -> (usize, usize) {
    ((a + 1) % 3, (a + 2) % 3)
}

/// `Rot(e_a, angle)` with exactly the bits of [`rot_axis_angle`]`(e_a, angle)` for a finite
/// `angle`: Rodrigues' `I + k̂ s + k̂²(1 − c)` with `k̂ = ê_a` gives `1` at `(a, a)`,
/// `1 − (1 − c)` on the other two diagonal entries, `0 ∓ s` off them and `+0` elsewhere.
#[inline(always)]
fn axial_rotation<const A: usize>(angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let d = 1.0 - (1.0 - c);
    let (b, c_) = cyclic(A);
    let mut r = Mat3::identity();
    r[(b, b)] = d;
    r[(c_, c_)] = d;
    r[(b, c_)] = 0.0 - s;
    r[(c_, b)] = 0.0 + s;
    r
}

/// `g_b ∘ g` for `g = (Rot(e_a, q), (x, 0, 0))` of an [`JointShape::Axial`] joint: column `a`
/// of the rotation is `g_b`'s, the other two mix two columns; `p = R_b (x, 0, 0) + p_b`.
#[inline(always)]
fn compose_axial<const A: usize>(gb: &Se3, g: &Se3) -> Se3 {
    let (a, (b, c)) = (A, cyclic(A));
    let (rb, r) = (&gb.r, &g.r);
    let mut out = Mat3::zeros();
    for i in 0..3 {
        out[(i, a)] = rb[(i, a)];
        out[(i, b)] = rb[(i, b)] * r[(b, b)] + rb[(i, c)] * r[(c, b)];
        out[(i, c)] = rb[(i, b)] * r[(b, c)] + rb[(i, c)] * r[(c, c)];
    }
    let x = g.p.x;
    let p = Vec3::new(
        rb[(0, 0)] * x + gb.p.x,
        rb[(1, 0)] * x + gb.p.y,
        rb[(2, 0)] * x + gb.p.z,
    );
    Se3::new(out, p)
}

/// The position pass of joint `k`, an axial joint about `e_A` at angle `q` (finite): `g_up`,
/// `g_b` and the joint twist in `F_b`, `[p × R e_A; R e_A]` of `g_b = (R, p)`.
#[inline(always)]
fn axial_joint<const A: usize>(j: &Joint, q: f64, k: usize, ws: &mut KinWorkspace) {
    let g = Se3::new(
        axial_rotation::<A>(q),
        Vec3::new(0.0 + j.placement.p.x, 0.0, 0.0),
    );
    ws.g_up[k + 1] = g;
    let gb = compose_axial::<A>(&ws.g_b[k], &g);
    let w = Vec3::new(gb.r[(0, A)], gb.r[(1, A)], gb.r[(2, A)]);
    ws.joint_twist_b[k] = stack(&gb.p.cross(&w), &w);
    ws.g_b[k + 1] = gb;
}

/// Configuration-dependent kinematic quantities, refreshed by [`forward_kinematics`]
/// (Pinocchio's `Data` placements: one forward pass fills them, every later algorithm —
/// Jacobians, `T(q)`, the dynamics passes — reuses them).
///
/// A workspace belongs to the vehicle it was built for: the joints' [`JointShape`]s are
/// resolved then.
#[derive(Clone, Debug)]
pub struct KinWorkspace {
    /// Body `i` frame in its parent body's frame, `g_(i-1)i(q) = placement · Rot(axis, q)`
    /// (body 0: in the base frame `F_b`, `g_b0`) — Pinocchio's `liMi`.
    pub g_up: Vec<Se3>,
    /// Body `i` frame in the base frame, `g_bi = g_b(i-1) g_(i-1)i` — Pinocchio's `oMi`.
    pub g_b: Vec<Se3>,
    /// End-effector frame in the base frame, `g_be`.
    pub g_be: Se3,
    /// Unit twist of joint `k` expressed in the base frame, `Ad_{g_b,k+1} [0; axis_k]`.
    pub joint_twist_b: Vec<Vec6>,
    /// The structure of each joint's transform `g_up[k + 1]` (resolved from the vehicle).
    pub(crate) shape: Vec<JointShape>,
}

impl KinWorkspace {
    /// A workspace sized for `v`, at the zero configuration.
    pub fn new(v: &Vehicle) -> Self {
        let mut ws = Self {
            g_up: vec![Se3::identity(); v.bodies.len()],
            g_b: vec![Se3::identity(); v.bodies.len()],
            g_be: Se3::identity(),
            joint_twist_b: vec![Vec6::zeros(); v.joints.len()],
            shape: v.joints.iter().map(JointShape::of).collect(),
        };
        let q = vec![0.0; v.joints.len()];
        forward_kinematics(v, &q, &mut ws);
        ws
    }

    /// The same workspace with every joint treated as [`JointShape::General`] (the dense
    /// products; for tests of the structured ones).
    #[cfg(test)]
    pub(crate) fn dense(mut self) -> Self {
        self.shape.fill(JointShape::General);
        self
    }
}

/// Forward kinematics (USM-1…16), the one position pass of the crate (Pinocchio's
/// `forwardKinematics`): the parent-to-child placements
/// `g_(k)(k+1)(q) = placement_k · Rot(axis_k, q)` into `ws.g_up`, their products
/// `g_bi = g_b(i-1) g_(i-1)i` (so `g_bi = g_b0 g_01(q_1) ⋯ g_(i-1)i(q_i)`) into `ws.g_b`, the
/// joint unit twists in the base frame `F_b` and the end-effector `g_be`. `q` in radians, one
/// per joint. Axial joints ([`JointShape`]) skip the products with exact zeros and ones.
///
/// # Panics
/// If `q.len()` differs from the joint count (a programming error; inputs from users are
/// checked where they are parsed).
pub fn forward_kinematics(v: &Vehicle, q: &[f64], ws: &mut KinWorkspace) {
    assert_eq!(q.len(), v.joints.len(), "joint vector length");
    assert_eq!(
        ws.shape.len(),
        v.joints.len(),
        "workspace of another vehicle"
    );
    let g0 = v.base.inverse();
    ws.g_up[0] = g0;
    ws.g_b[0] = g0;
    for (k, j) in v.joints.iter().enumerate() {
        match ws.shape[k] {
            // A non-finite angle takes the dense route, whose NaNs fill the whole rotation.
            JointShape::Axial(0) if q[k].is_finite() => axial_joint::<0>(j, q[k], k, ws),
            JointShape::Axial(1) if q[k].is_finite() => axial_joint::<1>(j, q[k], k, ws),
            JointShape::Axial(2) if q[k].is_finite() => axial_joint::<2>(j, q[k], k, ws),
            _ => {
                let rot = Se3::new(rot_axis_angle(&j.axis, q[k]), Vec3::zeros());
                let g = j.placement.compose(&rot);
                ws.g_up[k + 1] = g;
                let gb = ws.g_b[k].compose(&g);
                ws.joint_twist_b[k] = gb.twist_to_parent(&stack(&Vec3::zeros(), &j.axis));
                ws.g_b[k + 1] = gb;
            }
        }
    }
    let last = v.bodies.len() - 1;
    ws.g_be = ws.g_b[last].compose(&v.end_effector);
}

/// Geometric Jacobian of a frame `F_f` rigidly attached to body `body` at `g_bf` (in the
/// base frame), so that `V_f = J ζ` with `V_f` in `F_f` (USM-17/18):
/// `J = [Ad_{g_bf}⁻¹, Ad_{g_bf}⁻¹ J_body]`, the joint columns of joints beyond `body` zero.
/// `out` must be 6×(6+n).
pub fn frame_jacobian(ws: &KinWorkspace, body: usize, g_bf: &Se3, out: &mut Mat<f64>) {
    let n = ws.joint_twist_b.len();
    debug_assert_eq!(out.nrows(), 6);
    debug_assert_eq!(out.ncols(), 6 + n);
    for c in 0..6 {
        let mut e = Vec6::zeros();
        e[c] = 1.0;
        let col = g_bf.twist_to_child(&e);
        for r in 0..6 {
            out[(r, c)] = col[r];
        }
    }
    for k in 0..n {
        // Joint k moves body k+1 and everything after it.
        let col = if k < body {
            g_bf.twist_to_child(&ws.joint_twist_b[k])
        } else {
            Vec6::zeros()
        };
        for r in 0..6 {
            out[(r, 6 + k)] = col[r];
        }
    }
}

/// Geometric Jacobian of body `i` in its own frame (USM-17). `out` is 6×(6+n).
pub fn body_jacobian(ws: &KinWorkspace, i: usize, out: &mut Mat<f64>) {
    let g = ws.g_b[i];
    frame_jacobian(ws, i, &g, out);
}

/// Geometric Jacobian of the end-effector in the end-effector frame (USM-18), columns base
/// twist then joint rates. `out` is 6×(6+n).
pub fn ee_jacobian(ws: &KinWorkspace, out: &mut Mat<f64>) {
    let last = ws.g_b.len() - 1;
    let g = ws.g_be;
    frame_jacobian(ws, last, &g, out);
}

/// Base-frame wrench `[f; m]` (N, N·m about the base origin) of a unit thrust of thruster
/// `j`: `B_j(q) = [R_bt e ; p_bt × (R_bt e)]` (USM-25).
pub fn thruster_column(v: &Vehicle, ws: &KinWorkspace, j: usize) -> Vec6 {
    let t = &v.thrusters[j];
    let g = &ws.g_b[t.body];
    let d = g.act_vector(&t.direction);
    let p = g.act_point(&t.position);
    stack(&d, &p.cross(&d))
}

/// The thruster configuration matrix `T(q)` (USM-26), 6×n_thrusters in the base frame:
/// `τ_b = T(q) u`. `out` must be 6×n_thrusters.
pub fn thruster_matrix(v: &Vehicle, ws: &KinWorkspace, out: &mut Matrix6xX<f64>) {
    debug_assert_eq!(out.ncols(), v.thrusters.len());
    for j in 0..v.thrusters.len() {
        out.set_column(j, &thruster_column(v, ws, j));
    }
}

/// A freshly allocated `T(q)` (convenience for analysis code, not for time steps).
pub fn thruster_matrix_owned(v: &Vehicle, ws: &KinWorkspace) -> Matrix6xX<f64> {
    let mut t = Matrix6xX::zeros(v.thrusters.len());
    thruster_matrix(v, ws, &mut t);
    t
}

/// The full generalised map of thrust (USM-25 extended to the joints): column `j` is the
/// generalised force `J_g,iᵀ F_j` of a unit thrust of thruster `j` on body `i`, i.e. the base
/// wrench `B_j` (rows 0..6) followed by the joint torques it induces (rows 6..6+n, N·m).
/// `out` must be (6+n)×n_thrusters.
pub fn generalized_thrust_map(v: &Vehicle, ws: &KinWorkspace, out: &mut Mat<f64>) {
    let n = v.joints.len();
    for (j, t) in v.thrusters.iter().enumerate() {
        let b = thruster_column(v, ws, j);
        for r in 0..6 {
            out[(r, j)] = b[r];
        }
        for k in 0..n {
            // Power pairing of the joint's unit twist with the wrench, both in F_b.
            out[(6 + k, j)] = if k < t.body {
                ws.joint_twist_b[k].dot(&b)
            } else {
                0.0
            };
        }
    }
}

/// The vehicle's centre of mass in the base frame `F_b` [m] at the configuration of `ws`
/// (after [`forward_kinematics`]): `Σ m_i g_bi(c_i) / Σ m_i`, `c_i` body `i`'s centre of gravity
/// ([`crate::model::Body::cg`]). The base origin when the total mass is not positive.
pub fn centre_of_mass(v: &Vehicle, ws: &KinWorkspace) -> Vec3 {
    let mut sum = Vec3::zeros();
    let mut mass = 0.0;
    for (b, g) in v.bodies.iter().zip(&ws.g_b) {
        sum += g.act_point(&b.cg) * b.mass;
        mass += b.mass;
    }
    if mass > 0.0 {
        sum / mass
    } else {
        Vec3::zeros()
    }
}

/// Reach [m]: `|p_be|`, the distance from the base frame's origin to the end-effector frame's
/// origin at the straight configuration `q = 0` (docs/model.md §6 "Missions"; for a chain whose
/// links are collinear at `q = 0`, the largest over joint space).
pub fn straight_reach(v: &Vehicle) -> f64 {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &vec![0.0; v.n_joints()], &mut ws);
    ws.g_be.p.norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{usm_paper, uvms_planar};
    use crate::spatial::{ang, lin, skew, Mat3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Pose of a frame in the inertial frame for a given base pose and joints.
    fn inertial_frame(v: &Vehicle, base: &Se3, q: &[f64], body: Option<usize>) -> Se3 {
        let mut ws = KinWorkspace::new(v);
        forward_kinematics(v, q, &mut ws);
        let g = match body {
            Some(i) => ws.g_b[i],
            None => ws.g_be,
        };
        base.compose(&g)
    }

    /// Move the base by a body-frame twist `dx` (exponential, to first order exact enough
    /// for central differences: we use the exact SO(3) exponential and straight translation).
    fn perturb_base(base: &Se3, dx: &Vec6) -> Se3 {
        let dr = rot_axis_angle(&ang(dx).normalize(), ang(dx).norm());
        let dr = if ang(dx).norm() == 0.0 {
            Mat3::identity()
        } else {
            dr
        };
        Se3::new(base.r * dr, base.p + base.r * lin(dx))
    }

    /// Finite-difference body twist of a frame when the generalised coordinates move along
    /// `ζ` (base twist in F_b, joint rates): V = [Rᵀ ṗ; vee(Rᵀ Ṙ)].
    fn fd_twist(v: &Vehicle, base: &Se3, q: &[f64], zeta: &[f64], body: Option<usize>) -> Vec6 {
        let h = 1e-6;
        let eval = |s: f64| {
            let dx = Vec6::from_iterator(zeta[..6].iter().map(|z| z * s));
            let b = perturb_base(base, &dx);
            let qq: Vec<f64> = q.iter().zip(&zeta[6..]).map(|(a, d)| a + d * s).collect();
            inertial_frame(v, &b, &qq, body)
        };
        let gp = eval(h);
        let gm = eval(-h);
        let g0 = eval(0.0);
        let pdot = (gp.p - gm.p) / (2.0 * h);
        let rdot = (gp.r - gm.r) / (2.0 * h);
        let w = g0.r.transpose() * rdot;
        let wv = Vec3::new(
            w[(2, 1)] - w[(1, 2)],
            w[(0, 2)] - w[(2, 0)],
            w[(1, 0)] - w[(0, 1)],
        ) / 2.0;
        stack(&(g0.r.transpose() * pdot), &wv)
    }

    fn random_state(v: &Vehicle, rng: &mut ChaCha8Rng) -> (Se3, Vec<f64>, Vec<f64>) {
        let axis = Vec3::new(rng.random(), rng.random(), rng.random()).normalize();
        let base = Se3::new(
            rot_axis_angle(&axis, rng.random_range(-3.0..3.0)),
            Vec3::new(rng.random(), rng.random(), rng.random()),
        );
        let q: Vec<f64> = v
            .joints
            .iter()
            .map(|j| rng.random_range(j.min..j.max))
            .collect();
        let zeta: Vec<f64> = (0..v.n_dof())
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        (base, q, zeta)
    }

    fn jac_times(j: &Mat<f64>, zeta: &[f64]) -> Vec6 {
        let mut out = Vec6::zeros();
        for r in 0..6 {
            out[r] = (0..j.ncols()).map(|c| j[(r, c)] * zeta[c]).sum();
        }
        out
    }

    #[test]
    fn jacobians_match_finite_differences() {
        // Central differences with h = 1e-6 on O(1) quantities: truncation ~h² and rounding
        // ~1e-16/h ≈ 1e-10, so 1e-7 leaves a wide margin while catching any wrong column.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for v in [usm_paper(), uvms_planar()] {
            let n = v.n_dof();
            let mut ws = KinWorkspace::new(&v);
            let mut j = Mat::<f64>::zeros(6, n);
            for _ in 0..10 {
                let (base, q, zeta) = random_state(&v, &mut rng);
                forward_kinematics(&v, &q, &mut ws);
                ee_jacobian(&ws, &mut j);
                let fd = fd_twist(&v, &base, &q, &zeta, None);
                assert!((jac_times(&j, &zeta) - fd).norm() < 1e-7, "ee: {}", v.name);
                for i in 0..v.bodies.len() {
                    body_jacobian(&ws, i, &mut j);
                    let fd = fd_twist(&v, &base, &q, &zeta, Some(i));
                    assert!((jac_times(&j, &zeta) - fd).norm() < 1e-7, "body {i}");
                }
            }
        }
    }

    #[test]
    fn straight_usm_paper_geometry() {
        let v = usm_paper();
        let ws = KinWorkspace::new(&v);
        // End-effector at the total length 3.300 m (USM Table II).
        assert!((ws.g_be.p - Vec3::new(3.3, 0.0, 0.0)).norm() < 1e-12);
        let t = thruster_matrix_owned(&v, &ws);
        // No thruster makes a roll moment when straight (docs/model.md §2).
        assert!(t.row(3).amax() < 1e-15);
        assert_eq!(t.rank(1e-9), 5);
        // Bending a joint *between* thruster-carrying links gives full rank (docs/model.md §2). Joints
        // 0 and 1 lie behind every thruster: bending them turns all thrusters rigidly and
        // the rank stays 5.
        let mut ws2 = ws.clone();
        for (k, expect) in [(0, 5), (1, 5), (2, 6), (3, 6), (4, 6), (5, 6)] {
            let mut q = vec![0.0; 8];
            q[k] = 0.4;
            forward_kinematics(&v, &q, &mut ws2);
            assert_eq!(
                thruster_matrix_owned(&v, &ws2).rank(1e-9),
                expect,
                "joint {k}"
            );
        }
    }

    #[test]
    fn tcm_column_equals_transported_thrust() {
        // Transport each unit thrust through the chain one joint at a time, as a wrench, and
        // compare with the closed-form column B_j (USM-25).
        let v = usm_paper();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut ws = KinWorkspace::new(&v);
        for _ in 0..20 {
            let (_, q, _) = random_state(&v, &mut rng);
            forward_kinematics(&v, &q, &mut ws);
            let t = thruster_matrix_owned(&v, &ws);
            for (j, th) in v.thrusters.iter().enumerate() {
                let mut w = stack(&th.direction, &th.position.cross(&th.direction));
                for k in (0..th.body).rev() {
                    let jt = &v.joints[k];
                    let g = jt.placement.compose(&Se3::from_axis_angle(&jt.axis, q[k]));
                    w = g.wrench_to_parent(&w);
                }
                w = v.base.inverse().wrench_to_parent(&w);
                assert!((t.column(j) - w).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn generalized_map_is_jacobian_transpose() {
        // Q_j = J_g,iᵀ F_j: compare against the explicit body Jacobian.
        let v = usm_paper();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut ws = KinWorkspace::new(&v);
        let (_, q, _) = random_state(&v, &mut rng);
        forward_kinematics(&v, &q, &mut ws);
        let mut map = Mat::<f64>::zeros(v.n_dof(), v.n_thrusters());
        generalized_thrust_map(&v, &ws, &mut map);
        let mut jb = Mat::<f64>::zeros(6, v.n_dof());
        for (j, th) in v.thrusters.iter().enumerate() {
            body_jacobian(&ws, th.body, &mut jb);
            let f = stack(&th.direction, &(skew(&th.position) * th.direction));
            for c in 0..v.n_dof() {
                let expect: f64 = (0..6).map(|r| jb[(r, c)] * f[r]).sum();
                assert!((map[(c, j)] - expect).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn centre_of_mass_of_the_straight_and_folded_usm() {
        // Straight: every body's CG on the x axis at its middle, so the CoM is Σ m_i x_i / Σ m_i
        // of the body centres; rotating a joint moves only the bodies after it.
        let v = usm_paper();
        let mut ws = KinWorkspace::new(&v);
        let (mut x, mut m) = (0.0, 0.0);
        for (i, b) in v.bodies.iter().enumerate() {
            x += b.mass * ws.g_b[i].act_point(&b.cg).x;
            m += b.mass;
        }
        let c = centre_of_mass(&v, &ws);
        assert!((c - Vec3::new(x / m, 0.0, 0.0)).norm() < 1e-12, "{c:?}");
        let mut q = vec![0.0; v.n_joints()];
        q[2] = 0.5;
        forward_kinematics(&v, &q, &mut ws);
        let bent = centre_of_mass(&v, &ws);
        assert!((bent - c).norm() > 1e-3 && bent.x < c.x, "{bent:?}");
    }

    #[test]
    fn uvms_planar_reference_pose() {
        // docs/model.md §8 (Antonelli & Chiaverini): q = (1.47, −1.00, 0.30) at vehicle pose 0 puts the
        // end-effector at (5.92, 4.29) with heading 0.77 rad (values printed to 2 decimals).
        let v = uvms_planar();
        let mut ws = KinWorkspace::new(&v);
        forward_kinematics(&v, &[1.47, -1.0, 0.3], &mut ws);
        assert!((ws.g_be.p.x - 5.92).abs() < 0.005);
        assert!((ws.g_be.p.y - 4.29).abs() < 0.005);
        let yaw = ws.g_be.r[(1, 0)].atan2(ws.g_be.r[(0, 0)]);
        assert!((yaw - 0.77).abs() < 1e-12);
    }
}
