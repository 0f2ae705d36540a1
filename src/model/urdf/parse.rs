//! URDF XML → the raw kinematic tree: links with their inertials and primitive geometry, joints
//! with type, origin, axis and limits, each with the 1-based line it starts on
//! (docs/urdf.md "Elements read"). No model rules here: [`super::assemble`] applies them.

use super::error::UrdfError;
use crate::spatial::{rot_axis_angle, Mat3, Se3, Vec3};
use roxmltree::Node;

/// One `<link>`.
#[derive(Clone, Debug)]
pub(super) struct Link {
    pub name: String,
    pub line: usize,
    /// `<inertial>`: mass [kg], its frame in the link frame, the inertia about the CoM in the
    /// axes of that frame [kg·m²]. `None`: the link has no `<inertial>`.
    pub inertial: Option<(f64, Se3, Mat3)>,
    /// Primitive `<collision>` shapes in the link frame (meshes are ignored: docs/urdf.md).
    pub collision: Vec<(Se3, Shape)>,
    /// Primitive `<visual>` shapes, for the size of a link without collision primitives.
    pub visual: Vec<(Se3, Shape)>,
}

/// A primitive geometry (sizes in metres).
#[derive(Clone, Copy, Debug)]
pub(super) enum Shape {
    /// `<box size="x y z">`.
    Box(Vec3),
    /// `<cylinder radius length>`, axis along the shape frame's z.
    Cylinder { radius: f64, length: f64 },
    /// `<sphere radius>`.
    Sphere(f64),
}

impl Shape {
    /// Enclosed volume [m³].
    pub fn volume(&self) -> f64 {
        match *self {
            Shape::Box(s) => s.x * s.y * s.z,
            Shape::Cylinder { radius, length } => std::f64::consts::PI * radius * radius * length,
            Shape::Sphere(r) => 4.0 / 3.0 * std::f64::consts::PI * r * r * r,
        }
    }

    /// Half extents of the shape's own bounding box [m].
    pub fn half_extents(&self) -> Vec3 {
        match *self {
            Shape::Box(s) => s / 2.0,
            Shape::Cylinder { radius, length } => Vec3::new(radius, radius, length / 2.0),
            Shape::Sphere(r) => Vec3::new(r, r, r),
        }
    }
}

/// A joint type the importer knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum JointKind {
    Revolute,
    Continuous,
    Fixed,
}

/// One `<joint>`.
#[derive(Clone, Debug)]
pub(super) struct UJoint {
    pub name: String,
    pub line: usize,
    pub kind: JointKind,
    pub parent: String,
    pub child: String,
    /// `<origin>`: the child link frame in the parent link frame at zero angle.
    pub origin: Se3,
    /// `<axis xyz>` normalised (URDF default `1 0 0`), in the child frame.
    pub axis: Vec3,
    /// `<limit lower upper>` [rad] when given.
    pub limits: Option<(f64, f64)>,
}

/// The parsed tree with the robot's name.
pub(super) struct Tree {
    pub name: String,
    pub links: Vec<Link>,
    pub joints: Vec<UJoint>,
}

/// Line of a node (1-based).
pub(super) fn line_of(node: Node) -> usize {
    node.document().text_pos_at(node.range().start).row as usize
}

/// An error at `node`.
pub(super) fn err_at(origin: &str, node: Node, msg: impl Into<String>) -> UrdfError {
    UrdfError {
        file: origin.to_string(),
        line: line_of(node),
        element: element_label(node),
        message: msg.into(),
    }
}

/// `<tag name="…">` of an element node.
pub(super) fn element_label(node: Node) -> String {
    match node.attribute("name") {
        Some(n) => format!("<{} name=\"{n}\">", node.tag_name().name()),
        None => format!("<{}>", node.tag_name().name()),
    }
}

/// The element children of `node` named `tag`.
pub(super) fn children<'a, 'i>(
    node: Node<'a, 'i>,
    tag: &'static str,
) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == tag)
}

/// The first element child of `node` named `tag`.
pub(super) fn child<'a, 'i>(node: Node<'a, 'i>, tag: &'static str) -> Option<Node<'a, 'i>> {
    children(node, tag).next()
}

/// Whitespace-separated finite floats.
pub(super) fn floats(
    origin: &str,
    node: Node,
    text: &str,
    what: &str,
) -> Result<Vec<f64>, UrdfError> {
    text.split_whitespace()
        .map(|t| match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(err_at(
                origin,
                node,
                format!("{what}: `{t}` is not a finite number"),
            )),
        })
        .collect()
}

/// Exactly `n` floats from an attribute (or `default` when absent).
fn attr_floats(
    origin: &str,
    node: Node,
    attr: &str,
    n: usize,
    default: Option<&[f64]>,
) -> Result<Vec<f64>, UrdfError> {
    match node.attribute(attr) {
        Some(t) => {
            let v = floats(origin, node, t, attr)?;
            if v.len() != n {
                return Err(err_at(
                    origin,
                    node,
                    format!("attribute {attr} needs {n} numbers, got {}", v.len()),
                ));
            }
            Ok(v)
        }
        None => default
            .map(<[f64]>::to_vec)
            .ok_or_else(|| err_at(origin, node, format!("missing attribute {attr}"))),
    }
}

/// One float attribute.
fn attr_f64(origin: &str, node: Node, attr: &str) -> Result<f64, UrdfError> {
    Ok(attr_floats(origin, node, attr, 1, None)?[0])
}

/// `R = Rz(yaw) Ry(pitch) Rx(roll)` (URDF's fixed-axis roll-pitch-yaw).
pub(super) fn rot_rpy(rpy: &Vec3) -> Mat3 {
    rot_axis_angle(&Vec3::z(), rpy[2])
        * rot_axis_angle(&Vec3::y(), rpy[1])
        * rot_axis_angle(&Vec3::x(), rpy[0])
}

/// The `<origin xyz rpy>` child of `node` (identity when absent).
fn origin_of(origin: &str, node: Node) -> Result<Se3, UrdfError> {
    match child(node, "origin") {
        None => Ok(Se3::identity()),
        Some(o) => {
            let p = attr_floats(origin, o, "xyz", 3, Some(&[0.0; 3]))?;
            let r = attr_floats(origin, o, "rpy", 3, Some(&[0.0; 3]))?;
            Ok(Se3::new(
                rot_rpy(&Vec3::new(r[0], r[1], r[2])),
                Vec3::new(p[0], p[1], p[2]),
            ))
        }
    }
}

fn inertial_of(origin: &str, link: Node) -> Result<Option<(f64, Se3, Mat3)>, UrdfError> {
    let Some(n) = child(link, "inertial") else {
        return Ok(None);
    };
    let mass_node =
        child(n, "mass").ok_or_else(|| err_at(origin, n, "<inertial> without <mass>"))?;
    let mass = attr_f64(origin, mass_node, "value")?;
    if mass < 0.0 {
        return Err(err_at(
            origin,
            mass_node,
            format!("mass must be >= 0, got {mass}"),
        ));
    }
    let frame = origin_of(origin, n)?;
    let i = child(n, "inertia").ok_or_else(|| err_at(origin, n, "<inertial> without <inertia>"))?;
    let g = |a: &str| attr_f64(origin, i, a);
    let (xx, xy, xz, yy, yz, zz) = (
        g("ixx")?,
        g("ixy")?,
        g("ixz")?,
        g("iyy")?,
        g("iyz")?,
        g("izz")?,
    );
    let inertia = Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    Ok(Some((mass, frame, inertia)))
}

fn shapes_of(origin: &str, link: Node, tag: &'static str) -> Result<Vec<(Se3, Shape)>, UrdfError> {
    let mut out = Vec::new();
    for c in children(link, tag) {
        let Some(geom) = child(c, "geometry") else {
            continue;
        };
        let frame = origin_of(origin, c)?;
        let Some(s) = geom.children().find(|n| n.is_element()) else {
            continue;
        };
        let shape = match s.tag_name().name() {
            "box" => {
                let v = attr_floats(origin, s, "size", 3, None)?;
                Shape::Box(Vec3::new(v[0], v[1], v[2]))
            }
            "cylinder" => Shape::Cylinder {
                radius: attr_f64(origin, s, "radius")?,
                length: attr_f64(origin, s, "length")?,
            },
            "sphere" => Shape::Sphere(attr_f64(origin, s, "radius")?),
            // Meshes (and anything else) carry no dynamics here (docs/urdf.md).
            _ => continue,
        };
        out.push((frame, shape));
    }
    Ok(out)
}

fn joint_of(origin: &str, j: Node) -> Result<UJoint, UrdfError> {
    let name = j
        .attribute("name")
        .ok_or_else(|| err_at(origin, j, "joint without a name"))?
        .to_string();
    let kind = match j.attribute("type") {
        Some("revolute") => JointKind::Revolute,
        Some("continuous") => JointKind::Continuous,
        Some("fixed") => JointKind::Fixed,
        Some(t @ ("prismatic" | "floating" | "planar")) => {
            return Err(err_at(
                origin,
                j,
                format!(
                    "joint type `{t}` is not supported: the model has revolute joints \
                     (and fixed ones, merged), docs/model.md §2"
                ),
            ))
        }
        Some(t) => return Err(err_at(origin, j, format!("unknown joint type `{t}`"))),
        None => return Err(err_at(origin, j, "joint without a type")),
    };
    let link_of = |tag: &'static str| -> Result<String, UrdfError> {
        let n = child(j, tag).ok_or_else(|| err_at(origin, j, format!("joint without <{tag}>")))?;
        n.attribute("link")
            .map(str::to_string)
            .ok_or_else(|| err_at(origin, n, format!("<{tag}> without a link attribute")))
    };
    let axis = match child(j, "axis") {
        Some(a) => {
            let v = attr_floats(origin, a, "xyz", 3, None)?;
            let v = Vec3::new(v[0], v[1], v[2]);
            let n = v.norm();
            if n <= 1e-9 || !n.is_finite() {
                return Err(err_at(origin, a, "axis must be a nonzero vector"));
            }
            if (n - 1.0).abs() > 1e-15 {
                v / n
            } else {
                v
            }
        }
        None => Vec3::x(),
    };
    let limits = match child(j, "limit") {
        Some(l) if kind == JointKind::Revolute => {
            let lo = attr_f64(origin, l, "lower")?;
            let hi = attr_f64(origin, l, "upper")?;
            if lo > hi {
                return Err(err_at(origin, l, format!("lower {lo} > upper {hi}")));
            }
            Some((lo, hi))
        }
        _ => None,
    };
    if kind == JointKind::Revolute && limits.is_none() {
        return Err(err_at(
            origin,
            j,
            "revolute joint without <limit lower upper>",
        ));
    }
    Ok(UJoint {
        name,
        line: line_of(j),
        kind,
        parent: link_of("parent")?,
        child: link_of("child")?,
        origin: origin_of(origin, j)?,
        axis,
        limits,
    })
}

/// Parse the `<robot>` document's links and joints.
pub(super) fn parse_tree(origin: &str, doc: &roxmltree::Document) -> Result<Tree, UrdfError> {
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(err_at(origin, robot, "the root element must be <robot>"));
    }
    let name = robot.attribute("name").unwrap_or("imported").to_string();
    let mut links = Vec::new();
    for l in children(robot, "link") {
        let lname = l
            .attribute("name")
            .ok_or_else(|| err_at(origin, l, "link without a name"))?;
        if links.iter().any(|o: &Link| o.name == lname) {
            return Err(err_at(origin, l, format!("link `{lname}` defined twice")));
        }
        links.push(Link {
            name: lname.to_string(),
            line: line_of(l),
            inertial: inertial_of(origin, l)?,
            collision: shapes_of(origin, l, "collision")?,
            visual: shapes_of(origin, l, "visual")?,
        });
    }
    let joints = children(robot, "joint")
        .map(|j| joint_of(origin, j))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Tree {
        name,
        links,
        joints,
    })
}
