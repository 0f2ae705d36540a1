//! The raw URDF tree and its plugin blocks → a [`Vehicle`] (docs/urdf.md "Rules"): the root
//! link is the floating base; fixed joints (and revolute joints with `lower = upper`, UUV
//! Simulator's sensor mounts) merge the child link into its parent's body; continuous joints
//! named by a thruster plugin become thrusters; revolute joints start a new body. A body
//! with two moving child joints (a branching tree) is refused. Values no element gives are
//! filled by the project's rules and listed in the import's ledger.

use super::error::{Inferred, UrdfError};
use super::parse::{JointKind, Link, Shape, Tree, UJoint};
use super::plugins::{Plugins, ThrusterSpec};
use crate::model::{Body, Fluid, Hydro, Joint, Thruster, Vehicle, GRAVITY, RHO_SEAWATER};
use crate::spatial::{skew, Mat3, Mat6, Se3, Vec3};
use std::collections::BTreeMap;

/// Thrust limit [N] of a thruster whose file gives none (the design-file default ∓40 N).
pub const DEFAULT_THRUST_LIMIT: f64 = 40.0;

/// Options of an import.
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    /// Symmetric thrust limit [N] for thrusters whose plugin gives no finite limit
    /// (default [`DEFAULT_THRUST_LIMIT`], marked inferred).
    pub thrust_limit: Option<f64>,
    /// Revolute joints held at zero and merged like fixed joints (e.g. a gripper's fingers,
    /// which would make the tree branch); each must name a revolute joint of the file.
    pub fixed_joints: Vec<String>,
}

/// One body being gathered from its links.
#[derive(Default)]
struct Acc {
    name: String,
    line: usize,
    /// `(mass, CoM, inertia about the CoM)` of each link, body frame.
    mass: Vec<(f64, Vec3, Mat3)>,
    /// `(volume, centre)` of each link that displaces water, body frame.
    vol: Vec<(f64, Vec3)>,
    /// `(M_A, D_l, D_q)` of each link with a hydrodynamic block, about the body origin.
    hydro: Vec<(Mat6, Mat6, Mat6)>,
    /// Bounding box `(min, max)` of the primitive shapes, body frame.
    bbox: Option<(Vec3, Vec3)>,
    /// The moving child joints: `(joint index, its origin in the body frame)`.
    moving: Vec<(usize, Se3)>,
}

/// What the walk of the tree gathers.
struct Walk<'a> {
    origin: &'a str,
    tree: &'a Tree,
    plugins: &'a Plugins,
    rho: f64,
    links: BTreeMap<&'a str, usize>,
    /// Child joints of each link.
    kids: Vec<Vec<usize>>,
    seen: Vec<bool>,
    /// [`ImportOptions::fixed_joints`].
    frozen: &'a [String],
    /// `(spec index, body, position, direction, joint name)`.
    thrusters: Vec<(usize, usize, Vec3, Vec3, String)>,
    ledger: Vec<Inferred>,
}

fn at(origin: &str, line: usize, element: String, msg: impl Into<String>) -> UrdfError {
    UrdfError {
        file: origin.to_string(),
        line,
        element,
        message: msg.into(),
    }
}

fn jlabel(j: &UJoint) -> String {
    format!("<joint name=\"{}\">", j.name)
}

fn llabel(l: &Link) -> String {
    format!("<link name=\"{}\">", l.name)
}

impl Walk<'_> {
    /// The thruster plugin naming joint `j`, if any.
    fn spec_of(&self, j: &UJoint) -> Option<usize> {
        self.plugins.thrusters.iter().position(|s: &ThrusterSpec| {
            s.joint.as_deref() == Some(j.name.as_str())
                || s.link.as_deref() == Some(j.child.as_str())
        })
    }

    /// Gather body `b` from its root link `root` (frame = the body frame).
    fn body(&mut self, root: usize, b: usize) -> Result<Acc, UrdfError> {
        let mut acc = Acc {
            name: self.tree.links[root].name.clone(),
            line: self.tree.links[root].line,
            ..Acc::default()
        };
        let tree = self.tree;
        let mut stack = vec![(root, Se3::identity())];
        while let Some((li, t)) = stack.pop() {
            self.seen[li] = true;
            self.add_link(&mut acc, li, &t, li == root)?;
            for ji in self.kids[li].clone() {
                let j = &tree.joints[ji];
                let ci = self.links[j.child.as_str()];
                let tc = t.compose(&j.origin);
                let fixed = match (j.kind, j.limits) {
                    (JointKind::Fixed, _) => true,
                    (JointKind::Revolute, Some((lo, hi))) => {
                        lo == hi || self.frozen.contains(&j.name)
                    }
                    _ => false,
                };
                if fixed {
                    stack.push((ci, tc));
                } else if j.kind == JointKind::Continuous {
                    let Some(spec) = self.spec_of(j) else {
                        return Err(at(
                            self.origin,
                            j.line,
                            jlabel(j),
                            "continuous joint not named by any thruster plugin: only \
                             propeller joints may be continuous (the model's joints are \
                             revolute with limits)",
                        ));
                    };
                    let dir = tc.r * j.axis;
                    self.thrusters.push((spec, b, tc.p, dir, j.name.clone()));
                    stack.push((ci, tc));
                } else {
                    acc.moving.push((ji, tc));
                }
            }
        }
        Ok(acc)
    }

    /// Add link `li` (at `t` in the body frame) to `acc`.
    fn add_link(
        &mut self,
        acc: &mut Acc,
        li: usize,
        t: &Se3,
        is_root: bool,
    ) -> Result<(), UrdfError> {
        let (tree, plugins) = (self.tree, self.plugins);
        let l = &tree.links[li];
        let m = match l.inertial {
            Some((m, f, i)) => {
                let g = t.compose(&f);
                acc.mass.push((m, g.p, g.r * i * g.r.transpose()));
                m
            }
            None if is_root => {
                return Err(at(
                    self.origin,
                    l.line,
                    llabel(l),
                    "missing <inertial>: a link that starts a body (the root, or the child of \
                     a revolute joint) needs its mass and inertia",
                ))
            }
            None => 0.0,
        };
        let h = plugins.hydro.get(&l.name);
        let com = l.inertial.map_or(Vec3::zeros(), |(_, f, _)| f.p);
        let given = h.and_then(|h| {
            if h.neutral {
                Some(m / self.rho)
            } else {
                h.volume
            }
        });
        match (h, given) {
            (Some(h), Some(v)) => {
                let c = h.cob.unwrap_or(if h.neutral { com } else { Vec3::zeros() });
                acc.vol.push((v, t.act_point(&c)));
            }
            // gz-sim's Buoyancy system: the volume of the collision shapes.
            _ if !plugins.any_uuv => {
                for (f, s) in &l.collision {
                    acc.vol.push((s.volume(), t.compose(f).p));
                }
            }
            _ => {}
        }
        if let Some(h) = h {
            if h.added_mass.is_some() || h.linear.is_some() || h.quadratic.is_some() {
                let z = Mat6::zeros();
                let mv = |x: Option<Mat6>| {
                    let x = x.unwrap_or(z);
                    if is_root {
                        x
                    } else {
                        t.inertia_to_parent(&x)
                    }
                };
                acc.hydro
                    .push((mv(h.added_mass), mv(h.linear), mv(h.quadratic)));
                if !is_root && h.quadratic.is_some() {
                    self.ledger.push(Inferred::new(
                        format!("body {}", acc.name),
                        format!("quadratic damping of merged link {} moved by congruence (exact only for a pure translation-free rotation)", l.name),
                    ));
                }
            }
            for n in &h.notes {
                self.ledger
                    .push(Inferred::new(format!("body {}", acc.name), n.clone()));
            }
        }
        let shapes = if l.collision.is_empty() {
            &l.visual
        } else {
            &l.collision
        };
        for (f, s) in shapes {
            grow_bbox(&mut acc.bbox, &t.compose(f), s);
        }
        Ok(())
    }
}

fn grow_bbox(bbox: &mut Option<(Vec3, Vec3)>, f: &Se3, s: &Shape) {
    let h = s.half_extents();
    // Half extents of the rotated box: |R| h.
    let e = f.r.abs() * h;
    let (lo, hi) = (f.p - e, f.p + e);
    *bbox = Some(match bbox {
        Some((a, b)) => (a.inf(&lo), b.sup(&hi)),
        None => (lo, hi),
    });
}

/// Mass, CoM and inertia about the CoM of the parts (parallel-axis theorem); one part as is.
fn combine(parts: &[(f64, Vec3, Mat3)]) -> (f64, Vec3, Mat3) {
    if let [one] = parts {
        return *one;
    }
    let m: f64 = parts.iter().map(|p| p.0).sum();
    let c = parts.iter().map(|p| p.1 * p.0).sum::<Vec3>() / m;
    let i = parts
        .iter()
        .map(|(pm, pc, pi)| {
            let d = skew(&(pc - c));
            pi - d * d * *pm
        })
        .sum();
    (m, c, i)
}

/// Links by name, the child joints of each link and the root link; errors for a joint naming
/// a missing link, a link with two parent joints, a loop or a disconnected tree.
#[allow(clippy::type_complexity)]
fn tree_shape<'t>(
    origin: &str,
    tree: &'t Tree,
) -> Result<(BTreeMap<&'t str, usize>, Vec<Vec<usize>>, usize), UrdfError> {
    let links: BTreeMap<&str, usize> = tree
        .links
        .iter()
        .enumerate()
        .map(|(i, l)| (l.name.as_str(), i))
        .collect();
    let mut kids = vec![Vec::new(); tree.links.len()];
    let mut parent_of: Vec<Option<usize>> = vec![None; tree.links.len()];
    for (ji, j) in tree.joints.iter().enumerate() {
        let find = |n: &str| {
            links.get(n).copied().ok_or_else(|| {
                at(
                    origin,
                    j.line,
                    jlabel(j),
                    format!("names link `{n}`, which does not exist"),
                )
            })
        };
        let (p, c) = (find(&j.parent)?, find(&j.child)?);
        if let Some(o) = parent_of[c] {
            return Err(at(
                origin,
                j.line,
                jlabel(j),
                format!(
                    "link `{}` is already the child of joint `{}` (line {}): a loop, not a tree",
                    j.child, tree.joints[o].name, tree.joints[o].line
                ),
            ));
        }
        parent_of[c] = Some(ji);
        kids[p].push(ji);
    }
    let roots: Vec<usize> = (0..tree.links.len())
        .filter(|&i| parent_of[i].is_none())
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => {
            // Follow parents from the first link until one repeats: the joint met last in
            // the file on that cycle closes the loop.
            let mut path = Vec::new();
            let mut li = 0;
            while let Some(ji) = parent_of[li] {
                if let Some(start) = path.iter().position(|&x| x == ji) {
                    path.drain(..start);
                    break;
                }
                path.push(ji);
                li = links[tree.joints[ji].parent.as_str()];
            }
            let j = path
                .iter()
                .map(|&ji| &tree.joints[ji])
                .max_by_key(|j| j.line);
            let (line, el) = j.map_or((1, "<robot>".into()), |j| (j.line, jlabel(j)));
            return Err(at(origin, line, el, "no root link: the joints form a loop"));
        }
        many => {
            let l = &tree.links[many[1]];
            let names: Vec<&str> = many.iter().map(|&i| tree.links[i].name.as_str()).collect();
            return Err(at(
                origin,
                l.line,
                llabel(l),
                format!(
                    "{} links have no parent joint ({}): the tree is not connected",
                    many.len(),
                    names.join(", ")
                ),
            ));
        }
    };
    Ok((links, kids, root))
}

/// Turn the tree into a vehicle; the second value lists what was inferred.
pub(super) fn assemble(
    origin: &str,
    tree: &Tree,
    plugins: &Plugins,
    opts: &ImportOptions,
) -> Result<(Vehicle, Vec<Inferred>), UrdfError> {
    let (links, kids, root) = tree_shape(origin, tree)?;
    let mut ledger = Vec::new();
    for name in &opts.fixed_joints {
        match tree.joints.iter().find(|j| &j.name == name) {
            Some(j) if j.kind == JointKind::Revolute => ledger.push(Inferred::new(
                format!("joint {name}"),
                "held at 0 and merged into its parent's body (import option fixed_joints / --fix-joint)",
            )),
            Some(j) => {
                return Err(at(
                    origin,
                    j.line,
                    jlabel(j),
                    "named as a fixed joint by the import options, but it is not revolute",
                ))
            }
            None => {
                return Err(at(
                    origin,
                    1,
                    "<robot>".into(),
                    format!("the import options name joint `{name}` to hold fixed, but the file has no joint of that name"),
                ))
            }
        }
    }
    let rho = match (plugins.rho, plugins.thruster_rho) {
        (Some(r), _) => r,
        (None, Some(r)) => {
            ledger.push(Inferred::new("fluid.rho", format!("no fluid_density/water_density: {r} kg/m³, the thruster plugins' fluid_density")));
            r
        }
        (None, None) => {
            ledger.push(Inferred::new(
                "fluid.rho",
                format!("no fluid_density/water_density: {RHO_SEAWATER} kg/m³ (docs/model.md §2)"),
            ));
            RHO_SEAWATER
        }
    };
    let mut w = Walk {
        origin,
        tree,
        plugins,
        rho,
        links,
        kids,
        seen: vec![false; tree.links.len()],
        frozen: &opts.fixed_joints,
        thrusters: Vec::new(),
        ledger,
    };
    let mut accs = Vec::new();
    let mut joints = Vec::new();
    let mut next = Some(root);
    while let Some(li) = next {
        let acc = w.body(li, accs.len())?;
        next = match acc.moving.as_slice() {
            [] => None,
            [(ji, tc)] => {
                let j = &tree.joints[*ji];
                let (min, max) = j.limits.unwrap_or((0.0, 0.0));
                joints.push(Joint {
                    name: j.name.clone(),
                    placement: *tc,
                    axis: j.axis,
                    min,
                    max,
                });
                Some(w.links[j.child.as_str()])
            }
            [(a, _), (b, _), ..] => {
                let (ja, jb) = (&tree.joints[*a], &tree.joints[*b]);
                return Err(at(
                    origin,
                    jb.line,
                    jlabel(jb),
                    format!(
                        "branching tree: body `{}` has {} moving child joints (`{}` line {}, `{}` line {}); \
                         the model is a serial chain (docs/model.md §2)",
                        acc.name, acc.moving.len(), ja.name, ja.line, jb.name, jb.line
                    ),
                ));
            }
        };
        accs.push(acc);
    }
    if let Some(i) = w.seen.iter().position(|s| !s) {
        let l = &tree.links[i];
        return Err(at(
            origin,
            l.line,
            llabel(l),
            "link not reachable from the root link: a loop",
        ));
    }
    finish(&mut w, tree, accs, joints, opts)
}

/// Bodies, thrusters and the fluid from the gathered values.
fn finish(
    w: &mut Walk,
    tree: &Tree,
    accs: Vec<Acc>,
    joints: Vec<Joint>,
    opts: &ImportOptions,
) -> Result<(Vehicle, Vec<Inferred>), UrdfError> {
    let rho = w.rho;
    let mut bodies = Vec::new();
    for (bi, a) in accs.iter().enumerate() {
        let (mass, cg, inertia) = combine(&a.mass);
        if mass <= 0.0 || !mass.is_finite() {
            return Err(at(
                w.origin,
                a.line,
                format!("<link name=\"{}\">", a.name),
                "body mass must be > 0",
            ));
        }
        let key = |f: &str| format!("body[{bi}].{f} ({})", a.name);
        let (volume, cb) = match a.vol.as_slice() {
            [one] => *one,
            [] => {
                w.ledger.push(Inferred::new(
                    key("volume"),
                    "no volume given: neutrally buoyant, V = m/ρ, CB = CG",
                ));
                (mass / rho, cg)
            }
            many => {
                let v: f64 = many.iter().map(|x| x.0).sum();
                (v, many.iter().map(|x| x.1 * x.0).sum::<Vec3>() / v)
            }
        };
        let usm = w.plugins.usm.get(&a.name);
        let (length, radius) = match (usm, a.bbox) {
            (Some(u), _) => (u.length, u.radius),
            (None, Some((lo, hi))) if (hi - lo).x > 0.0 => {
                let e = hi - lo;
                w.ledger.push(Inferred::new(key("length"), "length and radius from the primitive shapes' bounding box (x extent; half the larger of y, z)"));
                (e.x, 0.5 * e.y.max(e.z).max(1e-6))
            }
            _ => {
                let d = a.moving.first().map_or(0.0, |(_, t)| t.p.norm());
                let (l, r) = if d > 1e-6 {
                    (d, (volume / (std::f64::consts::PI * d)).sqrt())
                } else {
                    let r = (volume / (2.0 * std::f64::consts::PI)).cbrt();
                    (2.0 * r, r)
                };
                w.ledger.push(Inferred::new(
                    key("length"),
                    "no shapes: length from the next joint (or 2r), radius from the volume",
                ));
                (l, r)
            }
        };
        let hydro = match (usm.and_then(|u| u.cylinder.clone()), a.hydro.as_slice()) {
            (Some(h), _) => h,
            (None, []) => {
                w.ledger.push(Inferred::new(key("hydro"), "no hydrodynamic block: the cylinder hull model of a design file without [body.hydro] (Hydro::hull(length, 1))"));
                Hydro::hull(length, 1.0)
            }
            (None, [first, rest @ ..]) => {
                let (mut ma, mut dl, mut dq) = *first;
                for (a2, l2, q2) in rest {
                    ma += a2;
                    dl += l2;
                    dq += q2;
                }
                let asym = (ma - ma.transpose()).abs().max();
                if asym > 1e-9 * ma.abs().max().max(1.0) {
                    ma = (ma + ma.transpose()) / 2.0;
                    w.ledger.push(Inferred::new(key("hydro.added_mass"), format!("not symmetric in the file (largest |A - Aᵀ| entry {asym}): replaced by (A + Aᵀ)/2")));
                }
                Hydro::Coefficients {
                    added_mass: ma,
                    linear: dl,
                    quadratic: dq,
                }
            }
        };
        bodies.push(Body {
            name: a.name.clone(),
            mass,
            length,
            radius,
            cg,
            cb,
            volume,
            inertia,
            hydro,
        });
    }
    let thrusters = thrusters(w, opts)?;
    let fluid = Fluid {
        rho,
        g: w.plugins.g.unwrap_or(GRAVITY),
        current: w.plugins.current.unwrap_or_else(Vec3::zeros),
    };
    let v = Vehicle {
        name: tree.name.clone(),
        bodies,
        joints,
        thrusters,
        base: w.plugins.base.unwrap_or_else(Se3::identity),
        end_effector: w.plugins.end_effector.unwrap_or_else(Se3::identity),
        fluid,
    };
    Ok((v, std::mem::take(&mut w.ledger)))
}

fn thrusters(w: &mut Walk, opts: &ImportOptions) -> Result<Vec<Thruster>, UrdfError> {
    let mut found = std::mem::take(&mut w.thrusters);
    found.sort_by_key(|t| t.0);
    for (i, s) in w.plugins.thrusters.iter().enumerate() {
        if !found.iter().any(|t| t.0 == i) {
            let what = s
                .joint
                .as_deref()
                .or(s.link.as_deref())
                .unwrap_or("nothing");
            return Err(at(
                w.origin,
                s.line,
                "<plugin>".into(),
                format!("thruster plugin names `{what}`, which is not a continuous joint (or its child link) of the tree"),
            ));
        }
    }
    let limit = opts.thrust_limit.unwrap_or(DEFAULT_THRUST_LIMIT);
    let mut out = Vec::new();
    for (spec, body, position, direction, name) in found {
        let s = &w.plugins.thrusters[spec];
        let (u_min, u_max) = match s.limits {
            Some(l) => l,
            None => {
                w.ledger.push(Inferred::new(
                    format!("thruster {name}"),
                    format!(
                        "no finite thrust limit in its plugin: ∓{limit} N ({})",
                        if opts.thrust_limit.is_some() {
                            "--thrust-limit"
                        } else {
                            "the design-file default"
                        }
                    ),
                ));
                (-limit, limit)
            }
        };
        out.push(Thruster {
            name,
            body,
            position,
            direction,
            u_min,
            u_max,
            time_constant: s.time_constant,
            rate_limit: s.rate_limit,
        });
    }
    Ok(out)
}
