//! Engineering drawings of a vehicle: three orthographic views (top `x–y`, side `x–z`, front
//! `y–z`, see [`views`]) to one scale with a scale bar, a caption and a legend, as one
//! self-contained SVG (native `<text>`, inline style sheet, no fonts, scripts or links).
//!
//! The drawing knows geometry, not physics: the caller describes a [`Scene`] in the inertial
//! frame (metres) — cylinders, joint axes, thrust arrows, frame triads — and the caption lines;
//! [`render_svg`] lays the views out and writes the document. The bytes depend only on the scene.
//!
//! [`run`] draws a whole run the same way: the body at several times in one picture, and an
//! SMIL animation.
//!
//! Machine-readable structure (for tests and the HTML report): each view is a
//! `<g class="view" id="view-top|side|front">` whose `data-scale` (px per m), `data-x0` and
//! `data-y0` give its transform `x = x0 + scale·u`, `y = y0 − scale·v` ([`ViewTransform`]),
//! `data-u`/`data-v` naming the inertial axes of `u` and `v`. Each thrust arrow is a
//! `<g class="thruster" id="VIEW-NAME" data-thruster="NAME">` whose `data-x1 data-y1` is the
//! projected start and `data-x2 data-y2` the projected tip, in SVG px; when the arrow is not
//! along the view's normal it holds a `<line>` with the same coordinates.

mod camera;
mod labels;
mod page;
mod render;
pub mod run_drawing;
mod scene;
pub mod svg;
pub mod views;

pub use page::{layout, nice_length, render_svg, Layout, ACCENT};
pub use scene::{Arrow, Cylinder, JointAxis, Marker, Scene, Triad};
pub use views::{Bounds, View, ViewTransform};
