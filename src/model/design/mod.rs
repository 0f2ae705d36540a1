//! Design files (TOML): a [`Vehicle`] described by a preset name, by explicit body / joint /
//! thruster lists, or by a `[generator]` table (docs/model.md §2).
//!
//! # Forms
//! A design file uses exactly one of four forms:
//!
//! 1. **Preset**: `preset = "usm-paper"` (a name in [`PRESETS`]), optionally with `name`.
//! 2. **Explicit lists**: `[[body]]`, `[[joint]]`, `[[thruster]]`, optional `[fluid]`,
//!    `[base]` and `[end_effector]`. Joint `k` joins body `k` to body `k+1`.
//! 3. **Generator**: a `[generator]` table mapping onto [`GeneratorSpec`](crate::model::generator::GeneratorSpec); every field is
//!    optional and defaults to [`GeneratorSpec::default`](crate::model::generator::GeneratorSpec::default). An explicit `[[thruster]]` list
//!    given next to `[generator]` *replaces* the thrusters of the placement rule (set
//!    `thruster_rule = "none"` to make that obvious). `[fluid]`, `[base]` and
//!    `[end_effector]` may be given too; the generated bodies stay neutrally buoyant in the
//!    given fluid (their volume is recomputed as `m/ρ`).
//! 4. **URDF pointer**: `urdf = "robot.urdf"` (relative to the design file), optionally with
//!    `name`, `thrust_limit` [N] and `fixed_joints` (the import options of `design import`);
//!    the URDF is imported (docs/urdf.md) and its errors keep the URDF's file and line.
//!
//! # Units and frames
//! SI units everywhere (m, kg, s, N, kg·m²); angles are in degrees only in keys ending in
//! `_deg`. Every body frame has its origin at the body's rear (tail) face with x along the
//! body towards the head. Positions are in the frame of the body they belong to; joint
//! positions are on the parent body; `rpy_deg` is a roll-pitch-yaw placement rotation
//! `R = Rz(yaw) Ry(pitch) Rx(roll)`.
//!
//! # Schema (explicit form)
//! - top: `name` (string, optional; defaults to the file stem).
//! - `[fluid]`: `rho` [kg/m³], `g` [m/s²], `current` [3] [m/s] in the inertial frame;
//!   all optional, defaults from [`Fluid::default`](crate::model::Fluid::default).
//! - `[[body]]`: `name`, `mass` [kg], `length` [m], `radius` [m] required; optional `cg` [3]
//!   and `cb` [3] [m] (default: the centre `(l/2, 0, 0)`), `volume` [m³] (default `πr²l`) or
//!   `neutral = true` (volume `m/ρ`), `inertia` [3][3] [kg·m²] about the CG (default solid
//!   cylinder), and `[body.hydro]` with `kind = "cylinder"` (`cd_x`, `cd_y`, `cd_z`,
//!   `linear_damping` [6], `strips`, `axial_added_mass_ratio`, `added_mass_scale`; defaults of
//!   `Hydro::cylinder(0.1, 1.0)`) or `kind = "coefficients"` (`added_mass` [6][6] required,
//!   `linear` and `quadratic` [6][6] default zero). Without `[body.hydro]`: the cylinder model
//!   with its defaults.
//! - `[[joint]]`: `name` (default `q1`, `q2`, …), `axis` [3] (any nonzero vector, normalised),
//!   `position` [3] on the parent body (default its front face `(l_parent, 0, 0)`), `rpy_deg`
//!   [3] (default 0), `limits_deg` [2] (default `[-90, 90]`).
//! - `[[thruster]]`: `name` (default `T1`, `T2`, …), `body` (a body name or a 0-based
//!   index), `position` [3] [m], `direction` [3] (nonzero, normalised), `u_min`, `u_max` [N]
//!   (default ∓40), optional `time_constant` [s] and `rate_limit` [N/s].
//! - `[base]`: `position` [3], `rpy_deg` [3]: the base frame on body 0 (default identity, the
//!   tail face). `[end_effector]`: the same on the last body (default its front face).
//!
//! # Errors
//! Every problem is a [`DesignError`] naming the file, the 1-based line and column when
//! known, the key path (`thruster[2].direction`) and what is wrong. Positions come from the
//! input layer's located tree ([`Document`]): it maps serde error spans to key paths and
//! key paths of later physics checks ([`Vehicle::validate`]) back to lines. NaN and
//! infinite literals are rejected everywhere.
//!
//! # Files
//! `error`: [`DesignError`]; `schema`: the serde structs of the file; `build`: schema →
//! [`Vehicle`] with the defaults and checks; `write`: the explicit form
//! ([`design_to_toml`]); `tests`: their tests.

mod build;
mod error;
mod schema;
#[cfg(test)]
mod tests;
mod write;

pub use error::{DesignError, DesignErrorKind, DesignFault};
pub use write::{design_to_toml, thrusters_to_toml};

use super::presets::{self, PRESETS};
use super::Vehicle;
use crate::input::document::Document;
use build::{build, Ctx};
use error::{syntax, unplaced};
use schema::DesignFile;
use serde::Deserialize;
use std::path::Path;

/// Load a design: `arg` is a path to a `.toml` design file or the name of a preset
/// ([`PRESETS`]). An existing file wins over a preset of the same name.
pub fn load_design(arg: &str) -> Result<Vehicle, DesignError> {
    if is_urdf(arg) {
        return load_urdf_design(arg);
    }
    if Path::new(arg).is_file() {
        let text = read_file(arg)?;
        return parse_design(&text, arg);
    }
    if PRESETS.contains(&arg) {
        return presets::preset(arg).map_err(|e| not_found(arg, e.message));
    }
    Err(not_found(arg, not_found_message(arg)))
}

/// Load a design as a TOML table, for sweeps that override keys before building it with
/// [`parse_design_table`]: a file is parsed as it stands (syntax errors are reported with
/// line numbers); a preset name gives the preset's explicit form ([`design_to_toml`]), so
/// that keys like `thruster[2].position` exist to be overridden.
pub fn load_design_table(arg: &str) -> Result<toml::Table, DesignError> {
    let (text, origin) = if is_urdf(arg) {
        (design_to_toml(&load_urdf_design(arg)?), arg.to_string())
    } else if Path::new(arg).is_file() {
        let text = read_file(arg)?;
        if points_at_urdf(&text) {
            // The pointer form: its explicit form, so that sweep keys such as
            // `joint[0].position` exist to be overridden.
            (design_to_toml(&parse_design(&text, arg)?), arg.to_string())
        } else {
            (text, arg.to_string())
        }
    } else if PRESETS.contains(&arg) {
        let v = presets::preset(arg).map_err(|e| not_found(arg, e.message))?;
        (design_to_toml(&v), format!("preset {arg}"))
    } else {
        return Err(not_found(arg, not_found_message(arg)));
    };
    let doc = Document::parse(&text, &origin).map_err(syntax)?;
    doc.deserialize().map_err(syntax)
}

/// Parse a design from TOML text; `origin` (usually the file name) prefixes error messages.
/// The result is validated ([`Vehicle::validate`]).
pub fn parse_design(text: &str, origin: &str) -> Result<Vehicle, DesignError> {
    parse_with(text, origin, true)
}

/// Build a design from an in-memory TOML table (e.g. after a sweep applied overrides).
/// Errors name the key path but carry no line numbers.
pub fn parse_design_table(table: &toml::Table, origin: &str) -> Result<Vehicle, DesignError> {
    match toml::to_string(table) {
        Ok(text) => parse_with(&text, origin, false),
        Err(_) => {
            // Not printable as a document (should not happen for tables read from TOML):
            // deserialise directly, without key paths.
            let doc = Document::unplaced(origin);
            let ctx = Ctx::new(&doc);
            let file = DesignFile::deserialize(toml::Value::Table(table.clone()))
                .map_err(|e| ctx.serde_error(&e))?;
            build(&file, &ctx)
        }
    }
}

/// Build a design from an in-memory TOML value, which must be a table; see
/// [`parse_design_table`].
pub fn parse_design_value(value: &toml::Value, origin: &str) -> Result<Vehicle, DesignError> {
    match value {
        toml::Value::Table(t) => parse_design_table(t, origin),
        other => Err(unplaced(
            DesignErrorKind::Schema,
            origin,
            format!("a design must be a table, got a {}", other.type_str()),
        )),
    }
}

/// Whether a design file's text uses the pointer form `urdf = "…"` (top-level key).
fn points_at_urdf(text: &str) -> bool {
    text.parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("urdf"))
}

/// Whether `arg` is an existing `.urdf` file: a design given as a URDF (docs/urdf.md).
fn is_urdf(arg: &str) -> bool {
    arg.ends_with(".urdf") && Path::new(arg).is_file()
}

/// Import a URDF design with the default options; its error keeps the URDF's line and element.
fn load_urdf_design(arg: &str) -> Result<Vehicle, DesignError> {
    let opts = super::urdf::ImportOptions::default();
    super::urdf::load_urdf(Path::new(arg), &opts)
        .map(|i| i.vehicle)
        .map_err(|e| DesignError {
            at: crate::input::located::Location {
                origin: e.file.clone(),
                line: Some(e.line),
                column: None,
                key: e.element.clone(),
            },
            error: error::DesignFault {
                kind: DesignErrorKind::Invalid,
                message: e.message,
            },
        })
}

fn read_file(path: &str) -> Result<String, DesignError> {
    crate::input::document::read_text(std::path::Path::new(path)).map_err(|e| {
        unplaced(
            DesignErrorKind::Io,
            path,
            format!("cannot read the design file: {e}"),
        )
    })
}

fn not_found_message(arg: &str) -> String {
    format!(
        "no design file '{arg}' exists and it is not a preset name; presets: {}",
        PRESETS.join(", ")
    )
}

fn not_found(arg: &str, message: String) -> DesignError {
    unplaced(DesignErrorKind::NotFound, arg, message)
}

fn parse_with(text: &str, origin: &str, positions: bool) -> Result<Vehicle, DesignError> {
    let doc = if positions {
        Document::parse(text, origin)
    } else {
        Document::parse_generated(text, origin)
    }
    .map_err(syntax)?;
    let ctx = Ctx::new(&doc);
    if let Some((path, x)) = doc.first_non_finite() {
        return Err(ctx.schema(
            path,
            format!("must be a finite number, got {x} (nan and inf are not allowed)"),
        ));
    }
    let file: DesignFile = toml::from_str(text).map_err(|e| ctx.serde_error(&e))?;
    build(&file, &ctx)
}
