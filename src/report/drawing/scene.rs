//! What a drawing shows: the geometry of a [`Scene`] in the inertial frame (z up, metres).

use crate::spatial::{Se3, Vec3};

/// A solid cylinder: a body outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    /// Name (written as `data-body`).
    pub name: String,
    /// Pose in the inertial frame; the cylinder's axis is this frame's x axis [m].
    pub pose: Se3,
    /// Length along x from the pose's origin [m].
    pub length: f64,
    /// Radius [m].
    pub radius: f64,
    /// Drawn shaded (a joint module) rather than white (a link).
    pub module: bool,
}

/// A revolute joint's axis: a centre line through `position`, or a dot where it points out of
/// the page.
#[derive(Clone, Debug, PartialEq)]
pub struct JointAxis {
    /// Name (written as `data-joint`).
    pub name: String,
    /// A point of the axis, inertial frame [m].
    pub position: Vec3,
    /// Unit direction, inertial frame.
    pub axis: Vec3,
    /// Half the length of the drawn centre line [m].
    pub half_length: f64,
}

/// A thrust arrow from `start` along `direction`.
#[derive(Clone, Debug, PartialEq)]
pub struct Arrow {
    /// Name, drawn next to the tip.
    pub name: String,
    /// Start point, inertial frame [m].
    pub start: Vec3,
    /// Unit direction, inertial frame.
    pub direction: Vec3,
    /// Drawn length [m].
    pub length: f64,
}

/// A small axis triad of a frame: x solid, y dashed, z dotted.
#[derive(Clone, Debug, PartialEq)]
pub struct Triad {
    /// Label at the origin.
    pub name: String,
    /// The frame in the inertial frame.
    pub pose: Se3,
    /// Length of each axis [m].
    pub size: f64,
}

/// A labelled point: the whole vehicle's centre of gravity (`filled`) or of buoyancy.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Label next to the point (written as `data-marker`).
    pub name: String,
    /// The point, inertial frame [m].
    pub position: Vec3,
    /// Drawn as a filled dot (else as a ring).
    pub filled: bool,
}

/// Everything a drawing shows, in the inertial frame (z up).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Caption lines; the first is the title (bold).
    pub caption: Vec<String>,
    /// Body outlines.
    pub cylinders: Vec<Cylinder>,
    /// Joint axes.
    pub joints: Vec<JointAxis>,
    /// Thrust arrows.
    pub arrows: Vec<Arrow>,
    /// Frame triads.
    pub triads: Vec<Triad>,
    /// Legend text explaining the arrow lengths (e.g. `length ∝ limit: 0.01 m per N`).
    pub arrow_legend: String,
    /// Labelled points (the centres of gravity and buoyancy of `design draw`).
    pub markers: Vec<Marker>,
}
