//! An independent reading of a URDF for `tests/urdf_fixtures.rs`: its own XML walk (roxmltree)
//! and its own linear algebra (nalgebra), no usm-study code. It gives what `inspect` must
//! agree with: total mass, displaced volume, fluid density, the centre of mass and the thruster
//! matrix `T` at q = 0 in the root link's frame, and the attainable wrench under a thrust box,
//! solved here by enumerating the vertices of the feasible polytope (not the project's simplex
//! or Clarabel).

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::collections::BTreeMap;

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

fn floats(s: &str) -> Vec<f64> {
    s.split_whitespace().map(|t| t.parse().unwrap()).collect()
}

fn rpy(v: &[f64]) -> Matrix3<f64> {
    let (r, p, y) = (v[0], v[1], v[2]);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, r.cos(), -r.sin(), 0.0, r.sin(), r.cos());
    let ry = Matrix3::new(p.cos(), 0.0, p.sin(), 0.0, 1.0, 0.0, -p.sin(), 0.0, p.cos());
    let rz = Matrix3::new(y.cos(), -y.sin(), 0.0, y.sin(), y.cos(), 0.0, 0.0, 0.0, 1.0);
    rz * ry * rx
}

fn el<'a, 'i>(n: &Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(tag))
}

fn txt(n: Node) -> String {
    n.text().unwrap().trim().to_string()
}

/// `(R, p)` of an `<origin>` child (identity when absent).
fn origin_of(n: &Node) -> (Matrix3<f64>, Vector3<f64>) {
    match el(n, "origin") {
        None => (Matrix3::identity(), Vector3::zeros()),
        Some(o) => (
            rpy(&floats(o.attribute("rpy").unwrap_or("0 0 0"))),
            Vector3::from_vec(floats(o.attribute("xyz").unwrap_or("0 0 0"))),
        ),
    }
}

/// What the file says, read directly.
pub struct Reading {
    /// Total mass of every `<inertial>` [kg].
    pub mass: f64,
    /// Displaced volume [m³].
    pub volume: f64,
    /// Fluid density [kg/m³].
    pub rho: f64,
    /// Centre of mass at q = 0 in the root link frame [m].
    pub com: Vector3<f64>,
    /// Thruster matrix at q = 0 (columns `[d; p × d]`, root link frame), in plugin order.
    pub t: DMatrix<f64>,
}

/// Read `text`; `neutral_links` are links the project treats as neutrally buoyant (m/ρ): the
/// links of a body with no volume in the file (docs/urdf.md "Rules").
pub fn read(text: &str, neutral_links: &[&str]) -> Reading {
    let doc = roxmltree::Document::parse(text).unwrap();
    let robot = doc.root_element();
    let links: Vec<_> = robot
        .children()
        .filter(|c| c.has_tag_name("link"))
        .collect();
    let joints: Vec<_> = robot
        .children()
        .filter(|c| c.has_tag_name("joint"))
        .collect();
    // Every link's frame in the root link's frame at q = 0: walk the joints from the root.
    let child_of: BTreeMap<&str, &Node> = joints
        .iter()
        .map(|j| (el(j, "child").unwrap().attribute("link").unwrap(), j))
        .collect();
    let root = links
        .iter()
        .map(|l| l.attribute("name").unwrap())
        .find(|n| !child_of.contains_key(n))
        .unwrap();
    let mut frames: BTreeMap<String, (Matrix3<f64>, Vector3<f64>)> = BTreeMap::new();
    frames.insert(root.into(), (Matrix3::identity(), Vector3::zeros()));
    while frames.len() < links.len() {
        for j in &joints {
            let parent = el(j, "parent").unwrap().attribute("link").unwrap();
            let child = el(j, "child").unwrap().attribute("link").unwrap();
            if frames.contains_key(child) {
                continue;
            }
            if let Some(&(rp, pp)) = frames.get(parent) {
                let (r, p) = origin_of(j);
                frames.insert(child.into(), (rp * r, pp + rp * p));
            }
        }
    }
    let mut mass = 0.0;
    let mut moment = Vector3::zeros();
    for l in &links {
        let Some(i) = el(l, "inertial") else { continue };
        let m: f64 = el(&i, "mass")
            .unwrap()
            .attribute("value")
            .unwrap()
            .parse()
            .unwrap();
        let (r, p) = frames[l.attribute("name").unwrap()];
        let (_, c) = origin_of(&i);
        mass += m;
        moment += m * (p + r * c);
    }
    let plugins: Vec<_> = robot
        .descendants()
        .filter(|c| c.has_tag_name("plugin"))
        .collect();
    let uuv = plugins.iter().find(|p| {
        p.attribute("filename")
            .unwrap_or("")
            .contains("underwater_object")
    });
    let (rho, volume) = match uuv {
        // UUV Simulator: the plugin's fluid density and the volume of its link blocks.
        Some(p) => {
            let rho: f64 = txt(el(p, "fluid_density").unwrap()).parse().unwrap();
            let v: f64 = p
                .children()
                .filter(|c| c.has_tag_name("link"))
                .map(|l| txt(el(&l, "volume").unwrap()).parse::<f64>().unwrap())
                .sum();
            (rho, v + neutral_volume(&links, neutral_links, rho))
        }
        // gz-sim: the Buoyancy system's collision volumes (boxes, cylinders); the named
        // neutral links add m/ρ; ρ from the thrusters' fluid_density.
        None => {
            let rho: f64 = plugins
                .iter()
                .find_map(|p| el(p, "fluid_density"))
                .map(|n| txt(n).parse().unwrap())
                .unwrap();
            let mut v = 0.0;
            for l in &links {
                for c in l.children().filter(|c| c.has_tag_name("collision")) {
                    let g = el(&c, "geometry").unwrap();
                    if let Some(b) = el(&g, "box") {
                        v += floats(b.attribute("size").unwrap()).iter().product::<f64>();
                    } else if let Some(y) = el(&g, "cylinder") {
                        let r: f64 = y.attribute("radius").unwrap().parse().unwrap();
                        let h: f64 = y.attribute("length").unwrap().parse().unwrap();
                        v += std::f64::consts::PI * r * r * h;
                    }
                }
            }
            (rho, v + neutral_volume(&links, neutral_links, rho))
        }
    };
    // Thruster joints in the order of their plugins.
    let names: Vec<String> = plugins
        .iter()
        .filter(|p| p.attribute("filename").unwrap_or("").contains("thruster"))
        .filter_map(|p| el(p, "jointName").or_else(|| el(p, "joint_name")).map(txt))
        .collect();
    let mut cols = Vec::new();
    for jn in &names {
        let j = joints
            .iter()
            .find(|j| j.attribute("name") == Some(jn.as_str()))
            .unwrap();
        let parent = el(j, "parent").unwrap().attribute("link").unwrap();
        let (rp, pp) = frames[parent];
        let (r, p) = origin_of(j);
        let a = Vector3::from_vec(floats(el(j, "axis").unwrap().attribute("xyz").unwrap()));
        let (d, p) = (rp * r * a.normalize(), pp + rp * p);
        let m = p.cross(&d);
        cols.extend([d.x, d.y, d.z, m.x, m.y, m.z]);
    }
    Reading {
        mass,
        volume,
        rho,
        com: moment / mass,
        t: DMatrix::from_column_slice(6, names.len(), &cols),
    }
}

/// `Σ m/ρ` over the links named in `neutral`.
fn neutral_volume(links: &[Node], neutral: &[&str], rho: f64) -> f64 {
    links
        .iter()
        .filter(|l| neutral.contains(&l.attribute("name").unwrap()))
        .map(|l| {
            let i = el(l, "inertial").unwrap();
            let m: f64 = el(&i, "mass")
                .unwrap()
                .attribute("value")
                .unwrap()
                .parse::<f64>()
                .unwrap();
            m / rho
        })
        .sum()
}

/// `T` with its moment rows taken about `r` (root frame): `m_r = m − r × f`.
pub fn about(t: &DMatrix<f64>, r: &Vector3<f64>) -> DMatrix<f64> {
    let mut out = t.clone();
    for k in 0..t.ncols() {
        let f = Vector3::new(t[(0, k)], t[(1, k)], t[(2, k)]);
        let m = Vector3::new(t[(3, k)], t[(4, k)], t[(5, k)]) - r.cross(&f);
        for i in 0..3 {
            out[(3 + i, k)] = m[i];
        }
    }
    out
}

/// `max α ≥ 0` s.t. `A u = α e`, `−limit ≤ u ≤ limit` (`A`: the selected rows of a thruster
/// matrix, `e` the axis among them with its sign). The solutions of `A u = α e` are
/// `u = α u_p + N β` (`u_p` a particular solution, `N` a null-space basis from the SVD), so the
/// programme lives in `(α, β)`; its optimum is a vertex: every choice of `1 + dim β` active
/// rows among the box rows and `α = 0` is solved, and the feasible one with the largest `α`
/// kept. `e` outside the range of `A`: only `α = 0` is attainable.
pub fn max_along(a: &DMatrix<f64>, e: &DVector<f64>, limit: f64) -> f64 {
    let n = a.ncols();
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    let tol = 1e-10 * smax.max(1.0);
    let pinv = svd.pseudo_inverse(tol).unwrap();
    let up = &pinv * e;
    if (a * &up - e).norm() > 1e-9 * e.norm() {
        return 0.0;
    }
    // Null space: the right singular vectors of the (numerically) zero singular values.
    let full = DMatrix::from_fn(n, n, |i, j| if i < a.nrows() { a[(i, j)] } else { 0.0 });
    let fsvd = full.svd(false, true);
    let vt = fsvd.v_t.unwrap();
    let null: Vec<DVector<f64>> = (0..n)
        .filter(|&k| fsvd.singular_values[k] <= tol)
        .map(|k| vt.row(k).transpose())
        .collect();
    let d = null.len();
    // Rows g·x ≤ h over x = (α, β): u_i ≤ limit, −u_i ≤ limit, −α ≤ 0.
    let mut g: Vec<DVector<f64>> = Vec::new();
    let mut h: Vec<f64> = Vec::new();
    for i in 0..n {
        let row = DVector::from_fn(1 + d, |c, _| if c == 0 { up[i] } else { null[c - 1][i] });
        g.push(row.clone());
        h.push(limit);
        g.push(-row);
        h.push(limit);
    }
    g.push(DVector::from_fn(
        1 + d,
        |c, _| if c == 0 { -1.0 } else { 0.0 },
    ));
    h.push(0.0);
    let mut best = 0.0_f64;
    let m = g.len();
    let mut pick: Vec<usize> = (0..=d).collect();
    loop {
        let sys = DMatrix::from_fn(1 + d, 1 + d, |r, c| g[pick[r]][c]);
        let rhs = DVector::from_fn(1 + d, |r, _| h[pick[r]]);
        if let Some(x) = sys.lu().solve(&rhs) {
            let ok = (0..m).all(|k| g[k].dot(&x) <= h[k] + 1e-9 * limit);
            if ok && x.iter().all(|v| v.is_finite()) {
                best = best.max(x[0]);
            }
        }
        // Next combination of 1 + d rows out of m.
        let mut i = d as isize;
        while i >= 0 && pick[i as usize] == m - 1 - (d - i as usize) {
            i -= 1;
        }
        if i < 0 {
            break;
        }
        pick[i as usize] += 1;
        for k in (i as usize + 1)..=d {
            pick[k] = pick[k - 1] + 1;
        }
    }
    best
}

/// `(positive, negative)` attainable along each of `axes` (indices into the six rows) with only
/// the rows `rows` constrained (the others free).
pub fn attainable(t: &DMatrix<f64>, rows: &[usize], limit: f64) -> Vec<(usize, f64, f64)> {
    let a = DMatrix::from_fn(rows.len(), t.ncols(), |i, k| t[(rows[i], k)]);
    rows.iter()
        .enumerate()
        .map(|(i, &axis)| {
            let e = |s: f64| DVector::from_fn(rows.len(), |r, _| if r == i { s } else { 0.0 });
            (
                axis,
                max_along(&a, &e(1.0), limit),
                max_along(&a, &e(-1.0), limit),
            )
        })
        .collect()
}
