//! The NPS AUV II (Healey & Lienard 1993) as a one-body floating base for Antonelli &
//! Chiaverini's case 3 (docs/model.md §8): mass, inertia, hydrostatics and manoeuvring derivatives
//! from `../shared/data/nps_auv2.toml` (Fossen's MSS `npsauv.m`, commit `6bca7942…`; the
//! legacy file `VESSELS/npsauv.m` at `b661a212…` for ρ, g and m), driven by six ideal
//! generalised-force actuators (the paper's `τ_r = B u_r`, AC-2, with `B` invertible).
//!
//! Choices (see `nps_auv2_notes.md` and `results/antonelli/FINDINGS.md`):
//! - the legacy (pre-2024) constants ρ = 1000 kg/m³, g = 9.8 m/s², m = 5454.54 kg, which
//!   Antonelli's work used (the 2024 file's ρ = 1025 scales every hydrodynamic force by
//!   +2.5 %); neutrally buoyant, `z_G` = 0.061 m below `CO`, `CB` at `CO`;
//! - rigid-body Coriolis forces come from the crate's Newton–Euler pass (absolute twist), so
//!   the rigid-body parts MSS folds into the surge derivatives (`m′` terms) and its two
//!   sign slips (notes §5.1–2) are not in the table;
//! - the propeller and fins are not modelled (the paper reports generalised forces); the
//!   propeller-race terms (`Zqn`, `Zwn`, `Kpn`, `Mqn`, `Mwn`) enter with MSS's ε = −1 of a
//!   stopped propeller;
//! - surge resistance `−Cd0 ½ρL² |u| u` (MSS writes `u²`, which pushes backwards whatever
//!   the sign of `u`); case 3 as written turns it off
//!   ([`crate::paper::antonelli::dynamic::DynamicCase::surge_resistance`]);
//! - cross-flow integrand for pitch `(w − x q)` like heave (MSS has `w + x q`, notes §5.3;
//!   no difference in the planar motions of case 3).
//!
//! Frames: the body frame has its origin at the tail (x forward, y port, z up, the crate's
//! convention); `CO` is the hull's centre, 2.65 m ahead of the tail, and the base frame `F_b`
//! sits there. The derivatives are in SNAME axes (y starboard, z down).

use crate::model::manoeuvring::{CrossFlow, Manoeuvring};
use crate::model::{Body, Fluid, Hydro, Thruster, Vehicle};
use crate::spatial::{Mat3, Mat6, Se3, Vec3, Vec6};

/// Hull length `L` [m] (also the prime-system reference length).
pub const LENGTH: f64 = 5.3;
/// Mass [kg] (legacy MSS file; the 2024 file has W/g = 5443.4).
pub const MASS: f64 = 5454.54;
/// Water density [kg/m³] (legacy MSS file).
pub const RHO: f64 = 1000.0;
/// Gravity [m/s²] (legacy MSS file).
pub const G: f64 = 9.8;
/// Centre of gravity below `CO` [m].
pub const Z_G: f64 = 0.061;
/// Limit of each generalised-force actuator [N] (ideal: never reached in case 3).
pub const ACTUATOR_LIMIT: f64 = 1.0e6;

/// Rotational inertia about `CO` in SNAME axes [kg·m²]: `Ix, Iy, Iz` and the products
/// `Ixy = Iyz = Ixz = −13.58`, as the dyadic `[[Ix, −Ixy, −Ixz], …]`.
fn inertia_co_sname() -> Mat3 {
    let (ix, iy, iz, pxy, pyz, pxz) = (2038.0, 13587.0, 13587.0, -13.58, -13.58, -13.58);
    Mat3::new(ix, -pxy, -pxz, -pxy, iy, -pyz, -pxz, -pyz, iz)
}

/// Prime added-mass derivatives `A` (MSS: `M_A = −½ρL³ T A T`, `T = diag(1,1,1,L,L,L)`).
fn added_mass_sname(rho: f64) -> Mat6 {
    let mut a = Mat6::zeros();
    for (i, j, c) in [
        (0, 0, -7.6e-3),
        (1, 1, -5.5e-2),
        (1, 3, 1.2e-4),
        (1, 5, 1.2e-3),
        (2, 2, -2.4e-1),
        (2, 4, -6.8e-3),
        (3, 1, 1.2e-4),
        (3, 3, -1.0e-3),
        (3, 5, -3.4e-5),
        (4, 2, -6.8e-3),
        (4, 4, -1.7e-2),
        (5, 1, 1.2e-3),
        (5, 3, -3.4e-5),
        (5, 5, -3.4e-3),
    ] {
        a[(i, j)] = c;
    }
    let t = Mat6::from_diagonal(&Vec6::new(1.0, 1.0, 1.0, LENGTH, LENGTH, LENGTH));
    -(0.5 * rho * LENGTH.powi(3)) * t * a * t
}

/// Velocity-product derivatives of `npsauv.m` (force row `i`, velocity components `j, k` of
/// `[u v w p q r]`, prime value, power of `L` in `½ρLᵏ`), the `n`-suffixed ones times ε = −1.
const PRODUCTS: &[(usize, usize, usize, f64, i32)] = &[
    // X
    (0, 1, 1, 5.3e-2, 2),
    (0, 2, 2, 1.7e-1, 2),
    (0, 1, 5, 2.0e-2, 3),
    (0, 2, 4, -2.0e-1, 3),
    (0, 1, 3, -3.0e-3, 3),
    (0, 4, 4, -1.5e-2, 4),
    (0, 5, 5, 4.0e-3, 4),
    (0, 3, 5, 7.5e-4, 4),
    (0, 3, 3, 7.0e-3, 4),
    // Y
    (1, 0, 1, -1.0e-1, 2),
    (1, 1, 2, 6.8e-2, 2),
    (1, 0, 3, 3.0e-3, 3),
    (1, 0, 5, 3.0e-2, 3),
    (1, 1, 4, 2.4e-2, 3),
    (1, 2, 3, 2.3e-1, 3),
    (1, 2, 5, -1.9e-2, 3),
    (1, 3, 4, 4.0e-3, 4),
    (1, 4, 5, -6.5e-3, 4),
    // Z (Zwn, Zqn times ε = −1)
    (2, 0, 2, -3.0e-1, 2),
    (2, 1, 1, -6.8e-2, 2),
    (2, 0, 2, 5.1e-3, 2),
    (2, 0, 4, -1.4e-1, 3),
    (2, 1, 3, -4.8e-2, 3),
    (2, 1, 5, 4.5e-2, 3),
    (2, 0, 4, 2.9e-3, 3),
    (2, 3, 3, 1.3e-4, 4),
    (2, 3, 5, 6.7e-3, 4),
    (2, 5, 5, -7.4e-3, 4),
    // K (Kpn times ε = −1)
    (3, 0, 1, 3.1e-3, 3),
    (3, 1, 2, -1.9e-1, 3),
    (3, 0, 3, -1.1e-2, 4),
    (3, 0, 5, -8.4e-4, 4),
    (3, 1, 4, -5.1e-3, 4),
    (3, 2, 3, -1.3e-4, 4),
    (3, 2, 5, 1.4e-2, 4),
    (3, 0, 3, 5.7e-4, 4),
    (3, 3, 4, -6.9e-5, 5),
    (3, 4, 5, 1.7e-2, 5),
    // M (Mwn, Mqn times ε = −1)
    (4, 0, 2, 1.0e-1, 3),
    (4, 1, 1, -2.6e-2, 3),
    (4, 0, 2, 2.9e-3, 3),
    (4, 0, 4, -6.8e-2, 4),
    (4, 1, 3, 1.2e-3, 4),
    (4, 1, 5, 1.7e-2, 4),
    (4, 0, 4, 1.6e-3, 4),
    (4, 3, 3, 5.3e-5, 5),
    (4, 3, 5, 5.0e-3, 5),
    (4, 5, 5, 2.9e-3, 5),
    // N
    (5, 0, 1, -7.4e-3, 3),
    (5, 1, 2, -2.7e-2, 3),
    (5, 0, 3, -8.4e-4, 4),
    (5, 0, 5, -1.6e-2, 4),
    (5, 1, 4, -1.0e-2, 4),
    (5, 2, 3, -1.7e-2, 4),
    (5, 2, 5, 7.4e-3, 4),
    (5, 3, 4, -2.1e-2, 5),
    (5, 4, 5, 2.7e-3, 5),
];

/// The NPS AUV II manoeuvring model about `CO` (SNAME axes) for water of density `rho`,
/// with `CO` at `(L/2, 0, 0)` of a tail-origin body frame with y to port and z up.
pub fn nps_auv2_hydro(rho: f64) -> Manoeuvring {
    let mut products = [Mat6::zeros(); 6];
    for &(i, j, k, c, power) in PRODUCTS {
        products[i][(j, k)] += c * 0.5 * rho * LENGTH.powi(power);
    }
    let r2 = 0.5 * rho * LENGTH * LENGTH;
    let stations = (0..=10).map(|k| -LENGTH / 2.0 + k as f64 * LENGTH / 10.0);
    Manoeuvring {
        origin: Vec3::new(LENGTH / 2.0, 0.0, 0.0),
        axes: Mat3::from_diagonal(&Vec3::new(1.0, -1.0, -1.0)),
        added_mass: added_mass_sname(rho),
        products,
        quadratic: Vec6::new(0.00385 * r2, 0.0, 0.0, 0.0, 0.0, 0.0),
        crossflow: CrossFlow {
            stations: stations.collect(),
            width: LENGTH / 10.0,
            k_y: 0.5 * rho * 0.5 * 0.53,
            k_z: 0.5 * rho * 0.6 * 0.53,
        },
        kirchhoff: false,
    }
}

/// Offsets of the six ideal actuators from `CO` (body axes) and their directions: three
/// forces at `CO`, then a z force 1 m to port, an x force 1 m up and a y force 1 m ahead,
/// so that `τ_b = (u₁+u₅, u₂+u₆, u₃+u₄, u₄, u₅, u₆)` ([`actuator_thrusts`] inverts it).
const ACTUATORS: [([f64; 3], [f64; 3]); 6] = [
    ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
    ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
    ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
];

/// The actuator commands that produce the base wrench `tau = [f; m]` (in `F_b`, moment about
/// `CO`) on [`nps_auv2`] exactly.
pub fn actuator_thrusts(tau: &Vec6) -> [f64; 6] {
    [
        tau[0] - tau[4],
        tau[1] - tau[5],
        tau[2] - tau[3],
        tau[3],
        tau[4],
        tau[5],
    ]
}

/// The NPS AUV II as a one-body vehicle (see the module doc), in water of density
/// [`RHO`] under gravity [`G`], still (no current: scenarios set `fluid.current`).
pub fn nps_auv2() -> Vehicle {
    let hydro = nps_auv2_hydro(RHO);
    let co = hydro.origin;
    let axes = hydro.axes;
    // CG 0.061 m below CO (z up in the body frame); inertia about CO → about the CG.
    let cg = co + axes * Vec3::new(0.0, 0.0, Z_G);
    let r = cg - co;
    let i_co = axes * inertia_co_sname() * axes.transpose();
    let i_cg = i_co - MASS * (Mat3::identity() * r.norm_squared() - r * r.transpose());
    let body = Body {
        name: "nps-auv2".into(),
        mass: MASS,
        length: LENGTH,
        radius: 0.265,
        cg,
        cb: co,
        volume: MASS / RHO,
        inertia: i_cg,
        hydro: Hydro::Manoeuvring(Box::new(hydro)),
    };
    let thrusters = ACTUATORS
        .iter()
        .enumerate()
        .map(|(k, (p, d))| Thruster {
            name: format!("tau{}", k + 1),
            body: 0,
            position: co + Vec3::from_row_slice(p),
            direction: Vec3::from_row_slice(d),
            u_min: -ACTUATOR_LIMIT,
            u_max: ACTUATOR_LIMIT,
            time_constant: None,
            rate_limit: None,
        })
        .collect();
    Vehicle {
        name: "nps-auv2".into(),
        bodies: vec![body],
        joints: Vec::new(),
        thrusters,
        base: Se3::from_translation(co),
        end_effector: Se3::from_translation(Vec3::new(LENGTH, 0.0, 0.0)),
        fluid: Fluid {
            rho: RHO,
            g: G,
            current: Vec3::zeros(),
        },
    }
}

#[cfg(test)]
mod kernel_tests {
    //! The manoeuvring kernel on the NPS AUV II data (moved here from `dynamics::manoeuvring`:
    //! the kernel is core, the vehicle is the paper's).
    use super::{nps_auv2_hydro, LENGTH, RHO};
    use crate::dynamics::manoeuvring::ManoeuvringKernel;
    use crate::spatial::{Se3, Vec6};
    use proptest::prelude::*;

    fn kernel() -> ManoeuvringKernel {
        ManoeuvringKernel::new(&nps_auv2_hydro(RHO))
    }

    /// `v_r` at the body origin for a twist `nu` at CO in SNAME axes.
    fn at_origin(k: &ManoeuvringKernel, nu: &Vec6) -> Vec6 {
        Se3::new(k.model.axes, k.model.origin).twist_to_parent(nu)
    }

    #[test]
    fn pure_sway_matches_the_mss_expressions() {
        // u = 0, v = 0.2 m/s (SNAME): X = r2 Xvv v², Z = r2 Zvv v², M = r3 Mvv v², and the
        // cross-flow −½ρ (L/10)·11·Cdy·Hx·v|v| on Y with no yaw moment (symmetric stations).
        let k = kernel();
        let v = 0.2;
        let nu = Vec6::new(0.0, v, 0.0, 0.0, 0.0, 0.0);
        let p = k.parts(&at_origin(&k, &nu));
        let g = Se3::new(k.model.axes, k.model.origin);
        let back = |w: &Vec6| g.wrench_to_child(w);
        let (r2, r3) = (0.5 * RHO * LENGTH.powi(2), 0.5 * RHO * LENGTH.powi(3));
        let prod = back(&p.products);
        assert!((prod[0] - r2 * 5.3e-2 * v * v).abs() < 1e-9);
        assert!((prod[2] - r2 * -6.8e-2 * v * v).abs() < 1e-9);
        assert!((prod[4] - r3 * -2.6e-2 * v * v).abs() < 1e-9);
        let cf = back(&p.crossflow);
        let expect = -0.5 * RHO * 0.5 * 0.53 * 1.1 * LENGTH * v * v;
        assert!((cf[1] - expect).abs() < 1e-9 * expect.abs(), "{}", cf[1]);
        assert!(cf[5].abs() < 1e-9, "{}", cf[5]);
    }

    proptest! {
        #[test]
        fn resistance_and_crossflow_dissipate(v in proptest::array::uniform6(-2.0f64..2.0)) {
            // The drag parts never add energy: V_rᵀ F ≤ 0 (the velocity products may: they
            // are lift terms, linear in the surge speed).
            let k = kernel();
            let v = Vec6::from_row_slice(&v);
            let p = k.parts(&v);
            prop_assert!(v.dot(&p.resistance) <= 1e-12);
            prop_assert!(v.dot(&p.crossflow) <= 1e-9);
        }
    }
}
