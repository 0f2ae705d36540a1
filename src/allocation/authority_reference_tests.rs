//! The dedicated authority solver against Clarabel (the reference): random joint configurations
//! of every preset and of generated designs (3–9 links, rules paper / distributed / ends), all
//! six and transport's five commanded rows, with every thruster and with one removed, the
//! straight (rank-deficient) configuration among them. Every programme must be certified (no
//! Clarabel fallback: the duality-gap certificate held) and agree with Clarabel to 1e-7
//! relative to `max(|a|, the largest thrust limit)` (Clarabel's tolerances are relative to the
//! data: at a zero authority it answers up to ≈ 2e-7 N where the simplex gives 0 with a
//! certificate); the worst agreement is printed
//! (`cargo test --release --lib authority_reference -- --nocapture`).

use super::*;
use crate::kinematics::{centre_of_mass, forward_kinematics, thruster_matrix, KinWorkspace};
use crate::model::generator::{GeneratorSpec, ThrusterRule};
use crate::model::presets::{preset, PRESETS};
use crate::model::Vehicle;
use rand::{Rng, SeedableRng};

const ALL6: [bool; 6] = [true; 6];
const TRANSPORT: [bool; 6] = [true, true, true, false, true, true];
/// Configurations per design and mask (the straight one first).
const CONFIGS: usize = 200;

/// The worst agreement seen, and what was covered.
#[derive(Debug, Default)]
struct Tally {
    worst_rel: f64,
    worst_abs: f64,
    worst_at: String,
    programmes: usize,
    /// Programmes whose reference answer is below the under-actuation tolerance.
    zero: usize,
}

impl Tally {
    fn compare_at(
        &mut self,
        (a, b): (&AttainableAuthority, &AttainableAuthority),
        m: [bool; 6],
        scale: f64,
        at: &str,
    ) {
        for (k, &on) in m.iter().enumerate() {
            for (x, y) in [
                (a.positive[k], b.positive[k]),
                (a.negative[k], b.negative[k]),
            ] {
                if !on {
                    assert!(x.is_nan() && y.is_nan());
                    continue;
                }
                assert!(x.is_finite() && y.is_finite(), "axis {k}: {x} vs {y} {at}");
                self.programmes += 1;
                self.zero += usize::from(y.abs() <= 1e-6);
                let abs = (x - y).abs();
                let rel = abs / y.abs().max(scale);
                if rel > self.worst_rel {
                    self.worst_rel = rel;
                    self.worst_at = format!("axis {k}: {x} vs Clarabel {y} {at}");
                }
                self.worst_abs = self.worst_abs.max(abs);
            }
        }
    }
}

impl Tally {
    fn merge(&mut self, o: Tally) {
        if o.worst_rel > self.worst_rel {
            (self.worst_rel, self.worst_at) = (o.worst_rel, o.worst_at);
        }
        self.worst_abs = self.worst_abs.max(o.worst_abs);
        self.programmes += o.programmes;
        self.zero += o.zero;
    }
}

/// Compare both solvers over `CONFIGS` configurations of `v` for both masks.
fn compare(v: &Vehicle, seed: u64, all: &mut Tally) {
    let mut tally = Tally::default();
    let (lo, hi): (Vec<f64>, Vec<f64>) = v.thrusters.iter().map(|t| (t.u_min, t.u_max)).unzip();
    let n = v.n_thrusters();
    let scale = lo.iter().chain(&hi).fold(0.0_f64, |s, x| s.max(x.abs()));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut ws = KinWorkspace::new(v);
    let mut t = Matrix6xX::zeros(n);
    let mut q = vec![0.0; v.n_joints()];
    forward_kinematics(v, &q, &mut ws);
    thruster_matrix(v, &ws, &mut t);
    let r0 = centre_of_mass(v, &ws);
    for mask in [ALL6, TRANSPORT] {
        let mut fast = AuthoritySolver::new(&t, &lo, &hi, mask, &r0).unwrap();
        let mut slow = AuthoritySolver::new(&t, &lo, &hi, mask, &r0)
            .unwrap()
            .clarabel_only();
        for i in 0..CONFIGS {
            for (qk, j) in q.iter_mut().zip(&v.joints) {
                *qk = if i == 0 {
                    0.0
                } else {
                    rng.random_range(j.min..=j.max)
                };
            }
            forward_kinematics(v, &q, &mut ws);
            thruster_matrix(v, &ws, &mut t);
            let r = centre_of_mass(v, &ws);
            let at = format!("{} q{i} mask {mask:?}", v.name);
            let (a, b) = (fast.solve(&t, &r).unwrap(), slow.solve(&t, &r).unwrap());
            tally.compare_at((&a, &b), mask, scale, &at);
            let removed = i % n;
            let (a, b) = (fast.solve_without(removed), slow.solve_without(removed));
            tally.compare_at((&a, &b), mask, scale, &format!("{at} without {removed}"));
        }
        assert_eq!(fast.clarabel_programmes(), 0, "{}: uncertified", v.name);
        assert_eq!(
            slow.clarabel_programmes(),
            4 * CONFIGS * mask.iter().filter(|&&x| x).count()
        );
    }
    eprintln!(
        "{}: {} programmes, worst |Δ| {:.2e}, worst relative {:.2e}, {} at zero",
        v.name, tally.programmes, tally.worst_abs, tally.worst_rel, tally.zero
    );
    all.merge(tally);
}

fn generated(rule: ThrusterRule, links: usize) -> Vehicle {
    GeneratorSpec {
        links,
        thruster_rule: rule,
        ..Default::default()
    }
    .build(&format!("{rule:?}-{links}"))
    .unwrap()
}

fn check(tally: Tally, min_zero: usize) {
    eprintln!("{tally:?}");
    assert!(tally.worst_rel <= 1e-7, "{tally:?}");
    assert!(tally.zero >= min_zero, "{tally:?}");
}

#[test]
fn equals_clarabel_on_the_presets() {
    let mut tally = Tally::default();
    for (s, name) in PRESETS.iter().enumerate() {
        compare(&preset(name).unwrap(), s as u64, &mut tally);
    }
    // The straight usm-paper has no roll authority (all six rows commanded).
    check(tally, 1);
}

fn rule(rule: ThrusterRule, min_zero: usize) {
    let mut tally = Tally::default();
    for links in 3..=9 {
        compare(&generated(rule, links), 100 + links as u64, &mut tally);
    }
    check(tally, min_zero);
}

#[test]
fn equals_clarabel_on_generated_paper_layouts() {
    rule(ThrusterRule::Paper, 1);
}

#[test]
fn equals_clarabel_on_generated_distributed_layouts() {
    // distributed/3: 4 thrusters for 5 or 6 commanded rows, under-actuated everywhere.
    rule(ThrusterRule::Distributed, 100);
}

#[test]
fn equals_clarabel_on_generated_ends_layouts() {
    rule(ThrusterRule::Ends, 1);
}

#[test]
fn a_box_without_zero_goes_to_clarabel() {
    // Thrust limits [5, 30] N exclude zero: every programme is Clarabel's (and infeasible ones
    // NaN), as before the dedicated solver.
    let v = preset("usm-paper").unwrap();
    let mut ws = KinWorkspace::new(&v);
    let mut t = Matrix6xX::zeros(v.n_thrusters());
    forward_kinematics(&v, &vec![0.3; v.n_joints()], &mut ws);
    thruster_matrix(&v, &ws, &mut t);
    let n = v.n_thrusters();
    let r = Vector3::zeros();
    let mut s = AuthoritySolver::new(&t, &vec![5.0; n], &vec![30.0; n], TRANSPORT, &r).unwrap();
    let mut reference = AuthoritySolver::new(&t, &vec![5.0; n], &vec![30.0; n], TRANSPORT, &r)
        .unwrap()
        .clarabel_only();
    let a = s.solve(&t, &r).unwrap();
    assert_eq!(s.clarabel_programmes(), 10);
    let b = reference.solve(&t, &r).unwrap();
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    let (a, b) = (s.solve_without(0), reference.solve_without(0));
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    assert_eq!(s.clarabel_programmes(), 20);
}
