//! Design files (TOML): a [`Vehicle`] described by a preset name, by explicit body / joint /
//! thruster lists, or by a `[generator]` table (SPEC §2).
//!
//! # Forms
//! A design file uses exactly one of three forms:
//!
//! 1. **Preset**: `preset = "usm-paper"` (a name in [`PRESETS`]), optionally with `name`.
//! 2. **Explicit lists**: `[[body]]`, `[[joint]]`, `[[thruster]]`, optional `[fluid]`,
//!    `[base]` and `[end_effector]`. Joint `k` joins body `k` to body `k+1`.
//! 3. **Generator**: a `[generator]` table mapping onto [`GeneratorSpec`]; every field is
//!    optional and defaults to [`GeneratorSpec::default`]. An explicit `[[thruster]]` list
//!    given next to `[generator]` *replaces* the thrusters of the placement rule (set
//!    `thruster_rule = "none"` to make that obvious). `[fluid]`, `[base]` and
//!    `[end_effector]` may be given too; the generated bodies stay neutrally buoyant in the
//!    given fluid (their volume is recomputed as `m/ρ`).
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
//!   all optional, defaults from [`Fluid::default`].
//! - `[[body]]`: `name`, `mass` [kg], `length` [m], `radius` [m] required; optional `cg` [3]
//!   and `cb` [3] [m] (default: the centre `(l/2, 0, 0)`), `volume` [m³] (default `πr²l`) or
//!   `neutral = true` (volume `m/ρ`), `inertia` [3][3] [kg·m²] about the CG (default solid
//!   cylinder), and `[body.hydro]` with `kind = "cylinder"` (`cd_x`, `cd_y`, `cd_z`,
//!   `linear_damping` [6], `strips`, `axial_added_mass_ratio`; defaults of
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
//! known, the key path (`thruster[2].direction`) and what is wrong. Positions come from a
//! span index built by deserialising the document into a tree of `toml::Spanned` nodes; it
//! maps serde error spans to key paths and key paths of later physics checks
//! ([`Vehicle::validate`]) back to lines. NaN and infinite literals are rejected everywhere.

use super::generator::{GeneratorSpec, ThrusterRule};
use super::presets::{self, PRESETS};
use super::{Body, Fluid, Hydro, Joint, ModelError, Thruster, Vehicle};
use crate::diag::{line_col, one_line, write_located};
use crate::spatial::{rot_axis_angle, Mat3, Mat6, Se3, Vec3};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt::{self, Write as _};
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

/// What kind of problem a [`DesignError`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignErrorKind {
    /// The file could not be read.
    Io,
    /// The argument is neither an existing file nor a preset name.
    NotFound,
    /// The text is not valid TOML.
    Syntax,
    /// Valid TOML that does not fit the schema: unknown key, wrong type, missing key,
    /// non-finite number, conflicting forms.
    Schema,
    /// Fits the schema but describes an invalid vehicle (e.g. negative mass, zero thrust
    /// direction, a thruster on a body that does not exist).
    Invalid,
}

/// An error in a design file: where it is and what is wrong.
///
/// Displays as `origin:line:column: key: message`, omitting the position when unknown
/// (e.g. for designs built from an in-memory table) and the key when there is none.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct DesignError {
    /// What kind of problem this is.
    pub kind: DesignErrorKind,
    /// The file (or other origin) the design came from.
    pub origin: String,
    /// Key path of the offending entry in file terms, e.g. `thruster[2].direction` or
    /// `joint[1].limits_deg`; empty when the problem is not tied to a key.
    pub key: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column (in characters), when known.
    pub column: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for DesignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_located(
            f,
            &self.origin,
            self.line,
            self.column,
            &self.key,
            &self.message,
        )
    }
}

// ---------------------------------------------------------------------------------------
// Span index: a key path <-> byte span map of the document
// ---------------------------------------------------------------------------------------

/// A generic TOML node that keeps the span of every key and value.
enum Node {
    Table(Vec<(Spanned<String>, Spanned<Node>)>),
    Array(Vec<Spanned<Node>>),
    Float(f64),
    Other,
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct NodeVisitor;
        impl<'de> Visitor<'de> for NodeVisitor {
            type Value = Node;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("any TOML value")
            }
            fn visit_bool<E>(self, _: bool) -> Result<Node, E> {
                Ok(Node::Other)
            }
            fn visit_i64<E>(self, _: i64) -> Result<Node, E> {
                Ok(Node::Other)
            }
            fn visit_u64<E>(self, _: u64) -> Result<Node, E> {
                Ok(Node::Other)
            }
            fn visit_f64<E>(self, v: f64) -> Result<Node, E> {
                Ok(Node::Float(v))
            }
            fn visit_str<E>(self, _: &str) -> Result<Node, E> {
                Ok(Node::Other)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<Node, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element()? {
                    v.push(x);
                }
                Ok(Node::Array(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Node, A::Error> {
                let mut v = Vec::new();
                while let Some(kv) = a.next_entry()? {
                    v.push(kv);
                }
                Ok(Node::Table(v))
            }
        }
        d.deserialize_any(NodeVisitor)
    }
}

/// One node of the document: its key path, value span and key span.
struct Entry {
    path: String,
    value: Range<usize>,
    key: Option<Range<usize>>,
}

/// Error-reporting context: the origin, the text (for line numbers) and the span index.
struct Ctx<'a> {
    origin: &'a str,
    text: &'a str,
    /// Whether byte offsets refer to a file the user wrote (line numbers meaningful).
    positions: bool,
    entries: Vec<Entry>,
    /// Non-finite floats found while indexing: (path, value).
    non_finite: Vec<(String, f64)>,
}

fn join_key(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

impl<'a> Ctx<'a> {
    /// Parse `text` into the span index; a TOML syntax error becomes a [`DesignError`].
    fn parse(text: &'a str, origin: &'a str, positions: bool) -> Result<Self, DesignError> {
        let mut ctx = Ctx {
            origin,
            text,
            positions,
            entries: Vec::new(),
            non_finite: Vec::new(),
        };
        match toml::from_str::<Spanned<Node>>(text) {
            Ok(root) => {
                ctx.index(String::new(), &root, None);
                Ok(ctx)
            }
            Err(e) => {
                let (line, column) = match e.span() {
                    Some(s) if positions => {
                        let (l, c) = line_col(text, s.start);
                        (Some(l), Some(c))
                    }
                    _ => (None, None),
                };
                Err(DesignError {
                    kind: DesignErrorKind::Syntax,
                    origin: origin.to_string(),
                    key: String::new(),
                    line,
                    column,
                    message: format!("TOML syntax error: {}", one_line(e.message())),
                })
            }
        }
    }

    /// A context without positions or keys (fallback for tables that cannot be printed).
    fn empty(origin: &'a str) -> Self {
        Ctx {
            origin,
            text: "",
            positions: false,
            entries: Vec::new(),
            non_finite: Vec::new(),
        }
    }

    fn index(&mut self, path: String, node: &Spanned<Node>, key: Option<Range<usize>>) {
        if !path.is_empty() {
            self.entries.push(Entry {
                path: path.clone(),
                value: node.span(),
                key,
            });
        }
        match node.get_ref() {
            Node::Table(kvs) => {
                for (k, v) in kvs {
                    self.index(join_key(&path, k.get_ref()), v, Some(k.span()));
                }
            }
            Node::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    self.index(format!("{path}[{i}]"), v, None);
                }
            }
            Node::Float(x) if !x.is_finite() => self.non_finite.push((path, *x)),
            _ => {}
        }
    }

    /// Byte offset of the key `path`, or of its nearest ancestor present in the document.
    fn locate(&self, path: &str) -> Option<usize> {
        let mut p = path;
        loop {
            if let Some(e) = self.entries.iter().find(|e| e.path == p) {
                return Some(e.key.as_ref().map_or(e.value.start, |k| k.start));
            }
            p = parent_path(p)?;
        }
    }

    /// Key path of the smallest node whose key or value span contains `offset`.
    fn path_at(&self, offset: usize) -> Option<&str> {
        self.entries
            .iter()
            .flat_map(|e| {
                std::iter::once(&e.value)
                    .chain(e.key.as_ref())
                    .map(move |s| (e, s))
            })
            .filter(|(_, s)| s.start <= offset && offset < s.end.max(s.start + 1))
            .min_by_key(|(_, s)| s.end - s.start)
            .map(|(e, _)| e.path.as_str())
    }

    fn at_offset(&self, offset: Option<usize>) -> (Option<usize>, Option<usize>) {
        match offset {
            Some(o) if self.positions => {
                let (l, c) = line_col(self.text, o);
                (Some(l), Some(c))
            }
            _ => (None, None),
        }
    }

    /// An error at key `key` (positioned at the key or its nearest ancestor).
    fn err(&self, kind: DesignErrorKind, key: &str, message: impl Into<String>) -> DesignError {
        let (line, column) = self.at_offset(self.locate(key));
        DesignError {
            kind,
            origin: self.origin.to_string(),
            key: key.to_string(),
            line,
            column,
            message: message.into(),
        }
    }

    /// A schema error with the given message.
    fn schema(&self, key: &str, message: impl Into<String>) -> DesignError {
        self.err(DesignErrorKind::Schema, key, message)
    }

    /// A physics/consistency error with the given message.
    fn invalid(&self, key: &str, message: impl Into<String>) -> DesignError {
        self.err(DesignErrorKind::Invalid, key, message)
    }

    /// A serde error from deserialising the typed schema.
    fn serde_error(&self, e: toml::de::Error) -> DesignError {
        let offset = e.span().map(|s| s.start);
        let key = offset
            .and_then(|o| self.path_at(o))
            .unwrap_or_default()
            .to_string();
        let (line, column) = self.at_offset(offset);
        DesignError {
            kind: DesignErrorKind::Schema,
            origin: self.origin.to_string(),
            key,
            line,
            column,
            message: one_line(e.message()),
        }
    }

    /// Map a [`ModelError`] from [`Vehicle::validate`] or [`GeneratorSpec::build`] to a
    /// positioned error, translating model keys to file keys.
    fn model_error(&self, e: ModelError, fallback: Option<&str>) -> DesignError {
        let key = file_key(&e.key);
        let mut err = self.invalid(&key, e.message);
        if err.line.is_none() && self.locate(&key).is_none() {
            if let Some(fb) = fallback {
                let (line, column) = self.at_offset(self.locate(fb));
                err.line = line;
                err.column = column;
            }
        }
        err
    }
}

/// Translate a model key (`joint[1].limits`) into the design-file key (`joint[1].limits_deg`).
fn file_key(key: &str) -> String {
    let (parent, last) = match key.rfind('.') {
        Some(i) => (&key[..i + 1], &key[i + 1..]),
        None => ("", key),
    };
    let last = match last {
        "limits" => "limits_deg",
        "rotation" => "rpy_deg",
        "joint_limit" => "joint_limit_deg",
        other => other,
    };
    format!("{parent}{last}")
}

/// The parent of a key path: `a.b[2].c` → `a.b[2]` → `a.b` → `a` → none.
fn parent_path(p: &str) -> Option<&str> {
    if p.ends_with(']') {
        return p.rfind('[').map(|i| &p[..i]);
    }
    p.rfind('.').map(|i| &p[..i])
}

// ---------------------------------------------------------------------------------------
// Schema
// ---------------------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DesignFile {
    name: Option<String>,
    preset: Option<String>,
    fluid: Option<FluidSpec>,
    body: Option<Vec<BodySpec>>,
    joint: Option<Vec<JointSpec>>,
    thruster: Option<Vec<ThrusterSpec>>,
    base: Option<FrameSpec>,
    end_effector: Option<FrameSpec>,
    generator: Option<GeneratorFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FluidSpec {
    rho: Option<f64>,
    g: Option<f64>,
    current: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodySpec {
    name: String,
    mass: f64,
    length: f64,
    radius: f64,
    cg: Option<[f64; 3]>,
    cb: Option<[f64; 3]>,
    volume: Option<f64>,
    neutral: Option<bool>,
    inertia: Option<[[f64; 3]; 3]>,
    hydro: Option<HydroSpec>,
}

/// Both hydro kinds in one struct so that each misplaced key gets its own error.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HydroSpec {
    kind: Option<String>,
    cd_x: Option<f64>,
    cd_y: Option<f64>,
    cd_z: Option<f64>,
    linear_damping: Option<[f64; 6]>,
    strips: Option<usize>,
    axial_added_mass_ratio: Option<f64>,
    added_mass: Option<[[f64; 6]; 6]>,
    linear: Option<[[f64; 6]; 6]>,
    quadratic: Option<[[f64; 6]; 6]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointSpec {
    name: Option<String>,
    axis: [f64; 3],
    position: Option<[f64; 3]>,
    rpy_deg: Option<[f64; 3]>,
    limits_deg: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ThrusterSpec {
    name: Option<String>,
    body: BodyRef,
    position: [f64; 3],
    direction: [f64; 3],
    u_min: Option<f64>,
    u_max: Option<f64>,
    time_constant: Option<f64>,
    rate_limit: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    position: Option<[f64; 3]>,
    rpy_deg: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GeneratorFile {
    links: Option<usize>,
    link_length: Option<OneOrMany>,
    link_mass: Option<OneOrMany>,
    radius: Option<f64>,
    module_length: Option<f64>,
    module_mass: Option<f64>,
    joint_limit_deg: Option<f64>,
    thruster_rule: Option<String>,
    thrust_limit: Option<f64>,
    longitudinal_offset: Option<f64>,
    cd_axial_ends: Option<f64>,
    cd_axial: Option<f64>,
    cd_cross: Option<f64>,
}

/// A thruster's body: by name or by 0-based index.
enum BodyRef {
    Index(i64),
    Name(String),
}

impl<'de> Deserialize<'de> for BodyRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = BodyRef;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a body name (string) or a 0-based body index (integer)")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<BodyRef, E> {
                Ok(BodyRef::Index(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<BodyRef, E> {
                Ok(BodyRef::Index(i64::try_from(v).unwrap_or(i64::MAX)))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<BodyRef, E> {
                Ok(BodyRef::Name(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// One number for every link, or one per link.
struct OneOrMany(Vec<f64>);

impl<'de> Deserialize<'de> for OneOrMany {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = OneOrMany;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v as f64]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v as f64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<OneOrMany, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(OneOrMany(v))
            }
        }
        d.deserialize_any(V)
    }
}

// ---------------------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------------------

/// Load a design: `arg` is a path to a `.toml` design file or the name of a preset
/// ([`PRESETS`]). An existing file wins over a preset of the same name.
pub fn load_design(arg: &str) -> Result<Vehicle, DesignError> {
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
    let (text, origin) = if Path::new(arg).is_file() {
        (read_file(arg)?, arg.to_string())
    } else if PRESETS.contains(&arg) {
        let v = presets::preset(arg).map_err(|e| not_found(arg, e.message))?;
        (design_to_toml(&v), format!("preset {arg}"))
    } else {
        return Err(not_found(arg, not_found_message(arg)));
    };
    Ctx::parse(&text, &origin, true)?;
    toml::from_str(&text).map_err(|e| DesignError {
        kind: DesignErrorKind::Syntax,
        origin: origin.clone(),
        key: String::new(),
        line: None,
        column: None,
        message: one_line(e.message()),
    })
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
            let ctx = Ctx::empty(origin);
            let file = DesignFile::deserialize(toml::Value::Table(table.clone()))
                .map_err(|e| ctx.serde_error(e))?;
            build(&file, &ctx)
        }
    }
}

/// Build a design from an in-memory TOML value, which must be a table; see
/// [`parse_design_table`].
pub fn parse_design_value(value: &toml::Value, origin: &str) -> Result<Vehicle, DesignError> {
    match value {
        toml::Value::Table(t) => parse_design_table(t, origin),
        other => Err(DesignError {
            kind: DesignErrorKind::Schema,
            origin: origin.to_string(),
            key: String::new(),
            line: None,
            column: None,
            message: format!("a design must be a table, got a {}", other.type_str()),
        }),
    }
}

fn read_file(path: &str) -> Result<String, DesignError> {
    std::fs::read_to_string(path).map_err(|e| DesignError {
        kind: DesignErrorKind::Io,
        origin: path.to_string(),
        key: String::new(),
        line: None,
        column: None,
        message: format!("cannot read the design file: {e}"),
    })
}

fn not_found_message(arg: &str) -> String {
    format!(
        "no design file '{arg}' exists and it is not a preset name; presets: {}",
        PRESETS.join(", ")
    )
}

fn not_found(arg: &str, message: String) -> DesignError {
    DesignError {
        kind: DesignErrorKind::NotFound,
        origin: arg.to_string(),
        key: String::new(),
        line: None,
        column: None,
        message,
    }
}

fn parse_with(text: &str, origin: &str, positions: bool) -> Result<Vehicle, DesignError> {
    let ctx = Ctx::parse(text, origin, positions)?;
    if let Some((path, x)) = ctx.non_finite.first() {
        return Err(ctx.schema(
            path,
            format!("must be a finite number, got {x} (nan and inf are not allowed)"),
        ));
    }
    let file: DesignFile = toml::from_str(text).map_err(|e| ctx.serde_error(e))?;
    build(&file, &ctx)
}

// ---------------------------------------------------------------------------------------
// Building the vehicle
// ---------------------------------------------------------------------------------------

fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Rotation `Rz(yaw) Ry(pitch) Rx(roll)` from `[roll, pitch, yaw]` [rad].
fn rot_rpy(rpy: &Vec3) -> Mat3 {
    rot_axis_angle(&Vec3::z(), rpy[2])
        * rot_axis_angle(&Vec3::y(), rpy[1])
        * rot_axis_angle(&Vec3::x(), rpy[0])
}

/// `[roll, pitch, yaw]` [rad] of a rotation matrix, inverse of [`rot_rpy`]; at the
/// gimbal lock (pitch = ±90°) roll is set to zero.
fn rpy_of(r: &Mat3) -> Vec3 {
    let s = (-r[(2, 0)]).clamp(-1.0, 1.0);
    let pitch = s.asin();
    if s.abs() < 1.0 - 1e-12 {
        Vec3::new(
            r[(2, 1)].atan2(r[(2, 2)]),
            pitch,
            r[(1, 0)].atan2(r[(0, 0)]),
        )
    } else {
        Vec3::new(0.0, pitch, (-r[(0, 1)]).atan2(r[(1, 1)]))
    }
}

/// A frame from optional `position` and `rpy_deg`.
fn frame(spec: Option<&FrameSpec>, default_position: Vec3) -> Se3 {
    let p = spec.and_then(|s| s.position).map_or(default_position, vec3);
    match spec.and_then(|s| s.rpy_deg) {
        Some(rpy) => Se3::new(rot_rpy(&vec3(rpy).map(f64::to_radians)), p),
        None => Se3::from_translation(p),
    }
}

/// Normalise a nonzero vector; vectors already unit to rounding are kept bit-exact.
fn unit(ctx: &Ctx, key: &str, v: [f64; 3]) -> Result<Vec3, DesignError> {
    let v = vec3(v);
    let n = v.norm();
    if n.is_nan() || n <= 0.0 || n.is_infinite() {
        return Err(ctx.invalid(key, "must be a nonzero vector"));
    }
    if (n - 1.0).abs() <= 4.0 * f64::EPSILON {
        Ok(v)
    } else {
        Ok(v / n)
    }
}

fn mat6(a: &[[f64; 6]; 6]) -> Mat6 {
    Mat6::from_fn(|r, c| a[r][c])
}

fn build(file: &DesignFile, ctx: &Ctx) -> Result<Vehicle, DesignError> {
    let explicit = file.body.is_some() || file.joint.is_some();
    let explicit_key = if file.body.is_some() { "body" } else { "joint" };
    let forms: Vec<&str> = [
        ("preset", file.preset.is_some()),
        (explicit_key, explicit),
        ("generator", file.generator.is_some()),
    ]
    .iter()
    .filter(|(_, present)| *present)
    .map(|(k, _)| *k)
    .collect();
    let usage = "a design uses exactly one of `preset = \"NAME\"`, explicit [[body]]/[[joint]] \
                 lists or a [generator] table";
    if forms.len() > 1 {
        return Err(ctx.schema(
            forms[1],
            format!("cannot be combined with `{}`: {usage}", forms[0]),
        ));
    }
    let default_name = || {
        Path::new(ctx.origin)
            .file_stem()
            .and_then(|s| s.to_str())
            .filter(|s| !s.is_empty())
            .unwrap_or("design")
            .to_string()
    };
    let name = file.name.clone().unwrap_or_else(default_name);
    let v = match forms.first() {
        None => return Err(ctx.schema("", format!("no design found: {usage}"))),
        Some(&"preset") => build_preset(file, ctx)?,
        Some(&"generator") => build_generator(file, ctx, &name)?,
        Some(_) => build_explicit(file, ctx, &name)?,
    };
    let fallback = if file.generator.is_some() {
        Some("generator")
    } else {
        None
    };
    v.validate().map_err(|e| ctx.model_error(e, fallback))?;
    Ok(v)
}

fn build_preset(file: &DesignFile, ctx: &Ctx) -> Result<Vehicle, DesignError> {
    for (key, present) in [
        ("fluid", file.fluid.is_some()),
        ("thruster", file.thruster.is_some()),
        ("base", file.base.is_some()),
        ("end_effector", file.end_effector.is_some()),
    ] {
        if present {
            return Err(ctx.schema(
                key,
                "not allowed with `preset`: a preset design takes only `name`; write the \
                 preset out with `usm-study design show` to change it",
            ));
        }
    }
    let p = file.preset.as_deref().unwrap_or_default();
    let mut v = presets::preset(p).map_err(|e| ctx.invalid("preset", e.message))?;
    if let Some(n) = &file.name {
        v.name = n.clone();
    }
    Ok(v)
}

fn fluid(file: &DesignFile) -> Fluid {
    let d = Fluid::default();
    match &file.fluid {
        None => d,
        Some(f) => Fluid {
            rho: f.rho.unwrap_or(d.rho),
            g: f.g.unwrap_or(d.g),
            current: f.current.map_or(d.current, vec3),
        },
    }
}

fn build_generator(file: &DesignFile, ctx: &Ctx, name: &str) -> Result<Vehicle, DesignError> {
    let Some(g) = &file.generator else {
        return Err(ctx.schema("generator", "missing"));
    };
    let d = GeneratorSpec::default();
    let rule = match &g.thruster_rule {
        None => d.thruster_rule,
        Some(s) => s
            .parse::<ThrusterRule>()
            .map_err(|m| ctx.schema("generator.thruster_rule", m))?,
    };
    let spec = GeneratorSpec {
        links: g.links.unwrap_or(d.links),
        link_length: g
            .link_length
            .as_ref()
            .map_or(d.link_length, |v| v.0.clone()),
        link_mass: g.link_mass.as_ref().map_or(d.link_mass, |v| v.0.clone()),
        radius: g.radius.unwrap_or(d.radius),
        module_length: g.module_length.unwrap_or(d.module_length),
        module_mass: g.module_mass.unwrap_or(d.module_mass),
        joint_limit: g.joint_limit_deg.map_or(d.joint_limit, f64::to_radians),
        thruster_rule: rule,
        thrust_limit: g.thrust_limit.unwrap_or(d.thrust_limit),
        longitudinal_offset: g.longitudinal_offset.unwrap_or(d.longitudinal_offset),
        cd_axial_ends: g.cd_axial_ends.unwrap_or(d.cd_axial_ends),
        cd_axial: g.cd_axial.unwrap_or(d.cd_axial),
        cd_cross: g.cd_cross.unwrap_or(d.cd_cross),
    };
    for (key, values) in [
        ("link_length", &spec.link_length),
        ("link_mass", &spec.link_mass),
    ] {
        if let Some(x) = values.iter().find(|x| x.is_nan() || **x <= 0.0) {
            return Err(ctx.invalid(
                &format!("generator.{key}"),
                format!("values must be > 0, got {x}"),
            ));
        }
    }
    if key_present(ctx, "generator.link_length") && spec.link_length.is_empty() {
        return Err(ctx.invalid("generator.link_length", "needs at least one value"));
    }
    for (key, v) in [
        ("cd_axial_ends", spec.cd_axial_ends),
        ("cd_axial", spec.cd_axial),
        ("cd_cross", spec.cd_cross),
    ] {
        if v.is_nan() || v < 0.0 {
            return Err(ctx.invalid(
                &format!("generator.{key}"),
                format!("must be >= 0, got {v}"),
            ));
        }
    }
    let mut v = spec
        .build(name)
        .map_err(|e| ctx.model_error(e, Some("generator")))?;
    if file.fluid.is_some() {
        v.fluid = fluid(file);
        if v.fluid.rho > 0.0 {
            for b in &mut v.bodies {
                b.volume = b.mass / v.fluid.rho;
            }
        }
    }
    if let Some(list) = &file.thruster {
        v.thrusters = thrusters(list, &v.bodies, ctx)?;
    }
    if let Some(b) = &file.base {
        v.base = frame(Some(b), Vec3::zeros());
    }
    if let Some(e) = &file.end_effector {
        let last = v.bodies.last().map_or(0.0, |b| b.length);
        v.end_effector = frame(Some(e), Vec3::new(last, 0.0, 0.0));
    }
    Ok(v)
}

fn key_present(ctx: &Ctx, path: &str) -> bool {
    ctx.entries.iter().any(|e| e.path == path)
}

fn build_explicit(file: &DesignFile, ctx: &Ctx, name: &str) -> Result<Vehicle, DesignError> {
    let Some(body_specs) = &file.body else {
        return Err(ctx.schema("body", "explicit [[joint]] lists need [[body]] lists"));
    };
    let fluid = fluid(file);
    let mut bodies = Vec::with_capacity(body_specs.len());
    for (i, b) in body_specs.iter().enumerate() {
        if let Some(j) = body_specs[..i].iter().position(|o| o.name == b.name) {
            return Err(ctx.invalid(
                &format!("body[{i}].name"),
                format!("duplicate body name '{}' (also body[{j}])", b.name),
            ));
        }
        bodies.push(body(b, i, &fluid, ctx)?);
    }
    let joint_specs: &[JointSpec] = file.joint.as_deref().unwrap_or_default();
    let mut joints = Vec::with_capacity(joint_specs.len());
    for (k, j) in joint_specs.iter().enumerate() {
        let key = |f: &str| format!("joint[{k}].{f}");
        let axis = unit(ctx, &key("axis"), j.axis)?;
        let parent_len = bodies.get(k).map_or(0.0, |b: &Body| b.length);
        let pos = j.position.map_or(Vec3::new(parent_len, 0.0, 0.0), vec3);
        let placement = match j.rpy_deg {
            Some(rpy) => Se3::new(rot_rpy(&vec3(rpy).map(f64::to_radians)), pos),
            None => Se3::from_translation(pos),
        };
        let [lo, hi] = j.limits_deg.unwrap_or([-90.0, 90.0]);
        if lo > hi {
            return Err(ctx.invalid(
                &key("limits_deg"),
                format!("need min <= max, got [{lo}, {hi}]"),
            ));
        }
        joints.push(Joint {
            name: j.name.clone().unwrap_or_else(|| format!("q{}", k + 1)),
            placement,
            axis,
            min: lo.to_radians(),
            max: hi.to_radians(),
        });
    }
    let thrusters = match &file.thruster {
        Some(list) => thrusters(list, &bodies, ctx)?,
        None => Vec::new(),
    };
    let base = frame(file.base.as_ref(), Vec3::zeros());
    let last = bodies.last().map_or(0.0, |b| b.length);
    let end_effector = frame(file.end_effector.as_ref(), Vec3::new(last, 0.0, 0.0));
    Ok(Vehicle {
        name: name.to_string(),
        bodies,
        joints,
        thrusters,
        base,
        end_effector,
        fluid,
    })
}

fn body(b: &BodySpec, i: usize, fluid: &Fluid, ctx: &Ctx) -> Result<Body, DesignError> {
    let key = |f: &str| format!("body[{i}].{f}");
    // Check the scalars the defaults are computed from before using them.
    for (f, v) in [("mass", b.mass), ("length", b.length), ("radius", b.radius)] {
        if v.is_nan() || v <= 0.0 {
            return Err(ctx.invalid(&key(f), format!("must be > 0, got {v}")));
        }
    }
    let hydro = hydro(b.hydro.as_ref(), i, ctx)?;
    let mut body = Body::cylinder(&b.name, b.mass, b.length, b.radius, hydro);
    if let Some(cg) = b.cg {
        body.cg = vec3(cg);
    }
    if let Some(cb) = b.cb {
        body.cb = vec3(cb);
    }
    match (b.volume, b.neutral) {
        (Some(_), Some(true)) => {
            return Err(ctx.schema(
                &key("neutral"),
                "give either `volume` or `neutral = true`, not both",
            ))
        }
        (Some(v), _) => body.volume = v,
        (None, Some(true)) => body.volume = b.mass / fluid.rho,
        _ => {}
    }
    if let Some(m) = b.inertia {
        body.inertia = Mat3::from_fn(|r, c| m[r][c]);
    }
    Ok(body)
}

fn hydro(h: Option<&HydroSpec>, i: usize, ctx: &Ctx) -> Result<Hydro, DesignError> {
    let Some(h) = h else {
        return Ok(Hydro::cylinder(0.1, 1.0));
    };
    let key = |f: &str| format!("body[{i}].hydro.{f}");
    let cylinder_keys = [
        ("cd_x", h.cd_x.is_some()),
        ("cd_y", h.cd_y.is_some()),
        ("cd_z", h.cd_z.is_some()),
        ("linear_damping", h.linear_damping.is_some()),
        ("strips", h.strips.is_some()),
        ("axial_added_mass_ratio", h.axial_added_mass_ratio.is_some()),
    ];
    let coefficient_keys = [
        ("added_mass", h.added_mass.is_some()),
        ("linear", h.linear.is_some()),
        ("quadratic", h.quadratic.is_some()),
    ];
    let misplaced = |keys: &[(&str, bool)], kind: &str| -> Result<(), DesignError> {
        match keys.iter().find(|(_, present)| *present) {
            Some((f, _)) => Err(ctx.schema(&key(f), format!("not a key of hydro kind \"{kind}\""))),
            None => Ok(()),
        }
    };
    match h.kind.as_deref().unwrap_or("cylinder") {
        "cylinder" => {
            misplaced(&coefficient_keys, "cylinder")?;
            let Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                axial_added_mass_ratio,
            } = Hydro::cylinder(0.1, 1.0)
            else {
                return Err(ctx.schema(&key("kind"), "internal: cylinder defaults"));
            };
            let strips = h.strips.unwrap_or(strips);
            if !(1..=MAX_STRIPS).contains(&strips) {
                return Err(ctx.invalid(
                    &key("strips"),
                    format!("must be between 1 and {MAX_STRIPS}, got {strips}"),
                ));
            }
            Ok(Hydro::Cylinder {
                cd_x: h.cd_x.unwrap_or(cd_x),
                cd_y: h.cd_y.unwrap_or(cd_y),
                cd_z: h.cd_z.unwrap_or(cd_z),
                linear_damping: h.linear_damping.unwrap_or(linear_damping),
                strips,
                axial_added_mass_ratio: h.axial_added_mass_ratio.unwrap_or(axial_added_mass_ratio),
            })
        }
        "coefficients" => {
            misplaced(&cylinder_keys, "coefficients")?;
            let Some(added_mass) = &h.added_mass else {
                return Err(ctx.schema(
                    &key("added_mass"),
                    "required with kind = \"coefficients\" (a 6×6 matrix)",
                ));
            };
            Ok(Hydro::Coefficients {
                added_mass: mat6(added_mass),
                linear: h.linear.as_ref().map_or(Mat6::zeros(), mat6),
                quadratic: h.quadratic.as_ref().map_or(Mat6::zeros(), mat6),
            })
        }
        other => Err(ctx.schema(
            &key("kind"),
            format!("unknown hydro kind '{other}'; valid: cylinder, coefficients"),
        )),
    }
}

/// Upper bound on strip-theory integration points per body (guards against absurd input).
const MAX_STRIPS: usize = 1000;

fn thrusters(
    list: &[ThrusterSpec],
    bodies: &[Body],
    ctx: &Ctx,
) -> Result<Vec<Thruster>, DesignError> {
    let mut out = Vec::with_capacity(list.len());
    for (i, t) in list.iter().enumerate() {
        let key = |f: &str| format!("thruster[{i}].{f}");
        let body = match &t.body {
            BodyRef::Index(k) => usize::try_from(*k)
                .ok()
                .filter(|k| *k < bodies.len())
                .ok_or_else(|| {
                    ctx.invalid(
                        &key("body"),
                        format!(
                            "body index {k} does not exist (the design has {} bodies, 0..{})",
                            bodies.len(),
                            bodies.len()
                        ),
                    )
                })?,
            BodyRef::Name(n) => bodies.iter().position(|b| &b.name == n).ok_or_else(|| {
                let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
                ctx.invalid(
                    &key("body"),
                    format!("no body named '{n}'; bodies: {}", names.join(", ")),
                )
            })?,
        };
        let direction = unit(ctx, &key("direction"), t.direction)?;
        let u_min = t.u_min.unwrap_or(-40.0);
        let u_max = t.u_max.unwrap_or(40.0);
        if u_min > u_max {
            let k = if t.u_min.is_some() { "u_min" } else { "u_max" };
            return Err(ctx.invalid(
                &key(k),
                format!("need u_min <= u_max, got [{u_min}, {u_max}]"),
            ));
        }
        out.push(Thruster {
            name: t.name.clone().unwrap_or_else(|| format!("T{}", i + 1)),
            body,
            position: vec3(t.position),
            direction,
            u_min,
            u_max,
            time_constant: t.time_constant,
            rate_limit: t.rate_limit,
        });
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------

/// A float written so that it parses back to the same bits (shortest round-trip form,
/// always with a `.` or an exponent so that TOML reads it as a float).
fn fnum(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:?}")
    }
}

fn farr(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| fnum(*x)).collect();
    format!("[{}]", items.join(", "))
}

fn fmat<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>, indent: &str) -> String {
    let rows: Vec<String> = (0..R)
        .map(|r| {
            let row: Vec<f64> = (0..C).map(|c| m[(r, c)]).collect();
            format!("{indent}  {},", farr(&row))
        })
        .collect();
    format!("[\n{}\n{indent}]", rows.join("\n"))
}

fn tstr(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// Degrees of `x` [rad] chosen so that converting back with `to_radians` gives `x` exactly
/// when a neighbouring float allows it.
fn deg(x: f64) -> f64 {
    let d = x.to_degrees();
    if !d.is_finite() || d.to_radians() == x {
        return d;
    }
    for k in 1..=4u64 {
        for cand in [
            f64::from_bits(d.to_bits().wrapping_add(k)),
            f64::from_bits(d.to_bits().wrapping_sub(k)),
        ] {
            if cand.is_finite() && cand.to_radians() == x {
                return cand;
            }
        }
    }
    d
}

fn write_rpy(out: &mut String, r: &Mat3) {
    if *r != Mat3::identity() {
        let rpy = rpy_of(r).map(deg);
        let _ = writeln!(out, "rpy_deg = {}", farr(rpy.as_slice()));
    }
}

/// The explicit form of a design (what `usm-study design show` prints): every body, joint
/// and thruster with all values written out, plus `[fluid]`, `[base]` and
/// `[end_effector]`. Floats are written in their shortest round-trip form, so
/// `parse_design(&design_to_toml(&v), ..)` gives back `v` (angles in `_deg` keys within
/// about 1e-15 relative, exact for the presets' joint limits).
pub fn design_to_toml(v: &Vehicle) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# usm-study design file, explicit form, of the design {}.\n\
         # Written by `usm-study design show`; save it, edit it and pass the file wherever a\n\
         # design or preset name is accepted (e.g. `--design my_design.toml`).\n\
         # Units: SI (m, kg, s, N); angles in degrees only in keys ending in `_deg`.\n\
         # Frames: each body frame has its origin at the body's tail face, x towards the head;\n\
         # joint k joins body k (parent) to body k+1; positions are in the owning body's frame.",
        tstr(&v.name)
    );
    let _ = writeln!(o, "name = {}\n", tstr(&v.name));
    let _ = writeln!(o, "[fluid]");
    let _ = writeln!(o, "rho = {}  # density [kg/m³]", fnum(v.fluid.rho));
    let _ = writeln!(o, "g = {}  # gravity [m/s²]", fnum(v.fluid.g));
    let _ = writeln!(
        o,
        "current = {}  # inertial frame [m/s]\n",
        farr(v.fluid.current.as_slice())
    );
    let _ = writeln!(o, "# Base frame on body 0 (tail face by default).\n[base]");
    let _ = writeln!(o, "position = {}", farr(v.base.p.as_slice()));
    write_rpy(&mut o, &v.base.r);
    let _ = writeln!(
        o,
        "\n# End-effector frame on the last body (front face by default).\n[end_effector]"
    );
    let _ = writeln!(o, "position = {}", farr(v.end_effector.p.as_slice()));
    write_rpy(&mut o, &v.end_effector.r);
    for (i, b) in v.bodies.iter().enumerate() {
        let _ = writeln!(o, "\n# body {i}\n[[body]]");
        let _ = writeln!(o, "name = {}", tstr(&b.name));
        let _ = writeln!(o, "mass = {}  # [kg]", fnum(b.mass));
        let _ = writeln!(o, "length = {}  # [m]", fnum(b.length));
        let _ = writeln!(o, "radius = {}  # [m]", fnum(b.radius));
        let _ = writeln!(o, "cg = {}", farr(b.cg.as_slice()));
        let _ = writeln!(o, "cb = {}", farr(b.cb.as_slice()));
        let _ = writeln!(o, "volume = {}  # displaced [m³]", fnum(b.volume));
        let _ = writeln!(
            o,
            "inertia = {}  # about the CG [kg·m²]",
            fmat(&b.inertia, "")
        );
        let _ = writeln!(o, "[body.hydro]");
        match &b.hydro {
            Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                axial_added_mass_ratio,
            } => {
                let _ = writeln!(o, "kind = \"cylinder\"");
                let _ = writeln!(o, "cd_x = {}", fnum(*cd_x));
                let _ = writeln!(o, "cd_y = {}", fnum(*cd_y));
                let _ = writeln!(o, "cd_z = {}", fnum(*cd_z));
                let _ = writeln!(o, "linear_damping = {}", farr(linear_damping));
                let _ = writeln!(o, "strips = {strips}");
                let _ = writeln!(
                    o,
                    "axial_added_mass_ratio = {}",
                    fnum(*axial_added_mass_ratio)
                );
            }
            Hydro::Coefficients {
                added_mass,
                linear,
                quadratic,
            } => {
                let _ = writeln!(o, "kind = \"coefficients\"");
                let _ = writeln!(o, "added_mass = {}", fmat(added_mass, ""));
                let _ = writeln!(o, "linear = {}", fmat(linear, ""));
                let _ = writeln!(o, "quadratic = {}", fmat(quadratic, ""));
            }
        }
    }
    for (k, j) in v.joints.iter().enumerate() {
        let _ = writeln!(o, "\n# joint {k}: body {k} -> body {}\n[[joint]]", k + 1);
        let _ = writeln!(o, "name = {}", tstr(&j.name));
        let _ = writeln!(o, "axis = {}", farr(j.axis.as_slice()));
        let _ = writeln!(o, "position = {}", farr(j.placement.p.as_slice()));
        write_rpy(&mut o, &j.placement.r);
        let _ = writeln!(o, "limits_deg = {}", farr(&[deg(j.min), deg(j.max)]));
    }
    let unique_names = v
        .bodies
        .iter()
        .enumerate()
        .all(|(i, b)| v.bodies[..i].iter().all(|o| o.name != b.name));
    for t in &v.thrusters {
        let _ = writeln!(o, "\n[[thruster]]");
        let _ = writeln!(o, "name = {}", tstr(&t.name));
        match v.bodies.get(t.body) {
            Some(b) if unique_names => {
                let _ = writeln!(o, "body = {}", tstr(&b.name));
            }
            _ => {
                let _ = writeln!(o, "body = {}", t.body);
            }
        }
        let _ = writeln!(o, "position = {}", farr(t.position.as_slice()));
        let _ = writeln!(o, "direction = {}", farr(t.direction.as_slice()));
        let _ = writeln!(o, "u_min = {}", fnum(t.u_min));
        let _ = writeln!(o, "u_max = {}", fnum(t.u_max));
        if let Some(tc) = t.time_constant {
            let _ = writeln!(o, "time_constant = {}", fnum(tc));
        }
        if let Some(r) = t.rate_limit {
            let _ = writeln!(o, "rate_limit = {}", fnum(r));
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::generator::ThrusterRule;
    use crate::model::presets::usm_paper;
    use proptest::prelude::*;

    /// Compare two vehicles field by field with an absolute tolerance (relative for big
    /// values); `Err` names the first difference.
    fn close(a: &Vehicle, b: &Vehicle, tol: f64) -> Result<(), String> {
        fn num(key: &str, x: f64, y: f64, tol: f64) -> Result<(), String> {
            if (x - y).abs() <= tol * (1.0 + x.abs().max(y.abs())) {
                Ok(())
            } else {
                Err(format!("{key}: {x} vs {y}"))
            }
        }
        fn nums(key: &str, x: &[f64], y: &[f64], tol: f64) -> Result<(), String> {
            if x.len() != y.len() {
                return Err(format!("{key}: lengths {} vs {}", x.len(), y.len()));
            }
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                num(&format!("{key}[{i}]"), *p, *q, tol)?;
            }
            Ok(())
        }
        fn se3(key: &str, x: &Se3, y: &Se3, tol: f64) -> Result<(), String> {
            nums(&format!("{key}.p"), x.p.as_slice(), y.p.as_slice(), tol)?;
            nums(&format!("{key}.r"), x.r.as_slice(), y.r.as_slice(), tol)
        }
        if a.name != b.name {
            return Err(format!("name: {} vs {}", a.name, b.name));
        }
        if (a.bodies.len(), a.joints.len(), a.thrusters.len())
            != (b.bodies.len(), b.joints.len(), b.thrusters.len())
        {
            return Err("counts differ".into());
        }
        num("fluid.rho", a.fluid.rho, b.fluid.rho, tol)?;
        num("fluid.g", a.fluid.g, b.fluid.g, tol)?;
        nums(
            "fluid.current",
            a.fluid.current.as_slice(),
            b.fluid.current.as_slice(),
            tol,
        )?;
        se3("base", &a.base, &b.base, tol)?;
        se3("end_effector", &a.end_effector, &b.end_effector, tol)?;
        for (i, (x, y)) in a.bodies.iter().zip(&b.bodies).enumerate() {
            let k = |f: &str| format!("body[{i}].{f}");
            if x.name != y.name {
                return Err(k("name"));
            }
            num(&k("mass"), x.mass, y.mass, tol)?;
            num(&k("length"), x.length, y.length, tol)?;
            num(&k("radius"), x.radius, y.radius, tol)?;
            num(&k("volume"), x.volume, y.volume, tol)?;
            nums(&k("cg"), x.cg.as_slice(), y.cg.as_slice(), tol)?;
            nums(&k("cb"), x.cb.as_slice(), y.cb.as_slice(), tol)?;
            nums(
                &k("inertia"),
                x.inertia.as_slice(),
                y.inertia.as_slice(),
                tol,
            )?;
            match (&x.hydro, &y.hydro) {
                (
                    Hydro::Cylinder {
                        cd_x,
                        cd_y,
                        cd_z,
                        linear_damping,
                        strips,
                        axial_added_mass_ratio,
                    },
                    Hydro::Cylinder {
                        cd_x: cx,
                        cd_y: cy,
                        cd_z: cz,
                        linear_damping: ld,
                        strips: s,
                        axial_added_mass_ratio: ar,
                    },
                ) => {
                    nums(
                        &k("hydro.cd"),
                        &[*cd_x, *cd_y, *cd_z],
                        &[*cx, *cy, *cz],
                        tol,
                    )?;
                    nums(&k("hydro.linear_damping"), linear_damping, ld, tol)?;
                    num(&k("hydro.axial"), *axial_added_mass_ratio, *ar, tol)?;
                    if strips != s {
                        return Err(k("hydro.strips"));
                    }
                }
                (
                    Hydro::Coefficients {
                        added_mass,
                        linear,
                        quadratic,
                    },
                    Hydro::Coefficients {
                        added_mass: am,
                        linear: l,
                        quadratic: q,
                    },
                ) => {
                    nums(
                        &k("hydro.added_mass"),
                        added_mass.as_slice(),
                        am.as_slice(),
                        tol,
                    )?;
                    nums(&k("hydro.linear"), linear.as_slice(), l.as_slice(), tol)?;
                    nums(
                        &k("hydro.quadratic"),
                        quadratic.as_slice(),
                        q.as_slice(),
                        tol,
                    )?;
                }
                _ => return Err(k("hydro kind")),
            }
        }
        for (i, (x, y)) in a.joints.iter().zip(&b.joints).enumerate() {
            let k = |f: &str| format!("joint[{i}].{f}");
            if x.name != y.name {
                return Err(k("name"));
            }
            se3(&k("placement"), &x.placement, &y.placement, tol)?;
            nums(&k("axis"), x.axis.as_slice(), y.axis.as_slice(), tol)?;
            nums(&k("limits"), &[x.min, x.max], &[y.min, y.max], tol)?;
        }
        for (i, (x, y)) in a.thrusters.iter().zip(&b.thrusters).enumerate() {
            let k = |f: &str| format!("thruster[{i}].{f}");
            if x.name != y.name || x.body != y.body {
                return Err(k("name/body"));
            }
            nums(
                &k("position"),
                x.position.as_slice(),
                y.position.as_slice(),
                tol,
            )?;
            nums(
                &k("direction"),
                x.direction.as_slice(),
                y.direction.as_slice(),
                tol,
            )?;
            nums(&k("limits"), &[x.u_min, x.u_max], &[y.u_min, y.u_max], tol)?;
            if x.time_constant.is_some() != y.time_constant.is_some()
                || x.rate_limit.is_some() != y.rate_limit.is_some()
            {
                return Err(k("options"));
            }
            num(
                &k("tc"),
                x.time_constant.unwrap_or(0.0),
                y.time_constant.unwrap_or(0.0),
                tol,
            )?;
            num(
                &k("rate"),
                x.rate_limit.unwrap_or(0.0),
                y.rate_limit.unwrap_or(0.0),
                tol,
            )?;
        }
        Ok(())
    }

    fn round_trip(v: &Vehicle) -> Result<Vehicle, String> {
        let text = design_to_toml(v);
        parse_design(&text, "rt.toml").map_err(|e| format!("{e}\n{text}"))
    }

    #[test]
    fn presets_round_trip() {
        for p in PRESETS {
            let v = presets::preset(p).unwrap();
            let back = round_trip(&v).unwrap();
            close(&v, &back, 1e-12).unwrap();
            // Floats other than angles come back bit-exact.
            assert_eq!(v.bodies, back.bodies, "{p}");
            assert_eq!(v.thrusters, back.thrusters, "{p}");
            assert_eq!(v.fluid, back.fluid, "{p}");
            assert_eq!(v.joints, back.joints, "{p}");
        }
    }

    #[test]
    fn preset_form_and_load_design() {
        let v = parse_design("preset = \"usm-paper\"\nname = \"mine\"\n", "p.toml").unwrap();
        assert_eq!(v.name, "mine");
        assert_eq!(v.bodies, usm_paper().bodies);
        let v = load_design("uvms-planar").unwrap();
        assert_eq!(v.n_joints(), 3);
        let e = load_design("no/such/file.toml").unwrap_err();
        assert_eq!(e.kind, DesignErrorKind::NotFound);
        assert!(e.to_string().contains("usm-paper"), "{e}");
        assert!(e.to_string().contains("no design file"), "{e}");
        let e = parse_design("preset = \"nope\"\n", "p.toml").unwrap_err();
        assert_eq!((e.key.as_str(), e.line), ("preset", Some(1)));
        // A file on disk.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.toml");
        std::fs::write(&path, design_to_toml(&usm_paper())).unwrap();
        let v = load_design(path.to_str().unwrap()).unwrap();
        close(&v, &usm_paper(), 1e-12).unwrap();
    }

    const SMALL: &str = r#"
name = "small"

[fluid]
rho = 1000
current = [0.1, 0, 0]

[[body]]
name = "tail"
mass = 10
length = 0.5
radius = 0.1
neutral = true

[[body]]
name = "mid"
mass = 5.0
length = 0.2
radius = 0.1
cg = [0.1, 0.0, -0.01]
[body.hydro]
kind = "coefficients"
added_mass = [
  [1, 0, 0, 0, 0, 0],
  [0, 2, 0, 0, 0, 0],
  [0, 0, 2, 0, 0, 0],
  [0, 0, 0, 0, 0, 0],
  [0, 0, 0, 0, 0.1, 0],
  [0, 0, 0, 0, 0, 0.1],
]

[[body]]
name = "head"
mass = 3
length = 0.3
radius = 0.05
volume = 0.002
inertia = [[0.01, 0, 0], [0, 0.03, 0], [0, 0, 0.03]]
[body.hydro]
cd_x = 0.5
strips = 3

[[joint]]
name = "yaw"
axis = [0, 0, 2]

[[joint]]
axis = [0, 1, 0]
position = [0.25, 0, 0]
rpy_deg = [0, 0, 90]
limits_deg = [-45, 30]

[[thruster]]
body = "mid"
position = [0.1, 0, 0.05]
direction = [0, 3, 4]

[[thruster]]
name = "aft"
body = 2
position = [0.1, 0, 0]
direction = [1, 0, 0]
u_min = -10
u_max = 20
time_constant = 0.1
rate_limit = 100

[end_effector]
position = [0.3, 0, 0]
rpy_deg = [0, -90, 0]
"#;

    #[test]
    fn explicit_small_file() {
        let v = parse_design(SMALL, "small.toml").unwrap();
        assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (3, 2, 2));
        assert_eq!(v.fluid.rho, 1000.0);
        assert_eq!(v.fluid.g, GRAVITY_DEFAULT);
        assert_eq!(v.bodies[0].volume, 10.0 / 1000.0);
        assert_eq!(v.bodies[1].cg, Vec3::new(0.1, 0.0, -0.01));
        assert_eq!(v.bodies[1].cb, Vec3::new(0.1, 0.0, 0.0));
        assert!(matches!(v.bodies[1].hydro, Hydro::Coefficients { .. }));
        assert_eq!(v.bodies[2].volume, 0.002);
        assert_eq!(v.bodies[2].inertia[(1, 1)], 0.03);
        match &v.bodies[2].hydro {
            Hydro::Cylinder {
                cd_x, cd_y, strips, ..
            } => {
                assert_eq!((*cd_x, *cd_y, *strips), (0.5, 1.0, 3));
            }
            _ => panic!("cylinder expected"),
        }
        assert_eq!(v.joints[0].axis, Vec3::z());
        assert_eq!(v.joints[0].name, "yaw");
        assert_eq!(v.joints[0].placement.p, Vec3::new(0.5, 0.0, 0.0));
        assert!((v.joints[0].max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(v.joints[1].name, "q2");
        assert!((v.joints[1].placement.r * Vec3::x() - Vec3::y()).norm() < 1e-15);
        assert!((v.joints[1].min + 45f64.to_radians()).abs() < 1e-15);
        assert_eq!(v.thrusters[0].name, "T1");
        assert_eq!(v.thrusters[0].body, 1);
        assert!((v.thrusters[0].direction - Vec3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
        assert_eq!((v.thrusters[0].u_min, v.thrusters[0].u_max), (-40.0, 40.0));
        assert_eq!(v.thrusters[1].body, 2);
        assert_eq!(v.thrusters[1].time_constant, Some(0.1));
        assert!((v.end_effector.r * Vec3::x() - Vec3::z()).norm() < 1e-15);
        // And it round-trips (gimbal-lock rpy included).
        close(&v, &round_trip(&v).unwrap(), 1e-12).unwrap();
    }

    const GRAVITY_DEFAULT: f64 = crate::model::GRAVITY;

    #[test]
    fn generator_files() {
        let text = "name = \"g4\"\n[generator]\nlinks = 4\nlink_length = [0.5, 0.6, 0.7, 0.4]\n\
                    thruster_rule = \"distributed\"\njoint_limit_deg = 60\n";
        let v = parse_design(text, "g.toml").unwrap();
        let spec = GeneratorSpec {
            links: 4,
            link_length: vec![0.5, 0.6, 0.7, 0.4],
            thruster_rule: ThrusterRule::Distributed,
            joint_limit: 60f64.to_radians(),
            ..Default::default()
        };
        assert_eq!(v, spec.build("g4").unwrap());
        assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (7, 6, 6));
        // Defaults only; name from the file stem.
        let v = parse_design("[generator]\n", "designs/usm5.toml").unwrap();
        assert_eq!(v, GeneratorSpec::default().build("usm5").unwrap());
        // Generator + explicit thrusters: the list replaces the rule's thrusters.
        let text = "[generator]\nlinks = 3\nlink_length = 0.5\nthruster_rule = \"paper\"\n\
                    [fluid]\ncurrent = [0.2, 0, 0]\n\
                    [[thruster]]\nbody = \"L1\"\nposition = [0.25, 0, 0]\ndirection = [0, 1, 0]\n\
                    [[thruster]]\nbody = 0\nposition = [0.25, 0, 0]\ndirection = [0, 0, -1]\n";
        let v = parse_design(text, "gt.toml").unwrap();
        assert_eq!(v.n_thrusters(), 2);
        assert_eq!(v.thrusters[0].body, 2);
        assert_eq!(v.thrusters[1].direction, -Vec3::z());
        assert_eq!(v.bodies.len(), 5);
        assert_eq!(v.fluid.current, Vec3::new(0.2, 0.0, 0.0));
    }

    /// Parse `text` expecting an error at `key` on `line`; returns the error.
    #[track_caller]
    fn expect_err(text: &str, key: &str, line: Option<usize>, msg: &str) -> DesignError {
        let e = match parse_design(text, "designs/bad.toml") {
            Ok(_) => panic!("expected an error for:\n{text}"),
            Err(e) => e,
        };
        let shown = e.to_string();
        assert_eq!(e.key, key, "{shown}");
        assert_eq!(e.line, line, "{shown}");
        assert!(shown.contains(msg), "'{msg}' not in: {shown}");
        match line {
            Some(l) => assert!(
                shown.starts_with(&format!("designs/bad.toml:{l}:")),
                "{shown}"
            ),
            None => assert!(shown.starts_with("designs/bad.toml: "), "{shown}"),
        }
        if !key.is_empty() {
            assert!(shown.contains(&format!(": {key}: ")), "{shown}");
        }
        e
    }

    /// A small valid explicit design; tests replace one line to break it.
    const BASE: &str = "name = \"t\"\n\
[[body]]\n\
name = \"a\"\n\
mass = 2.0\n\
length = 0.5\n\
radius = 0.1\n\
[[body]]\n\
name = \"b\"\n\
mass = 2.0\n\
length = 0.5\n\
radius = 0.1\n\
[[joint]]\n\
axis = [0, 0, 1]\n\
limits_deg = [-90, 90]\n\
[[thruster]]\n\
body = \"b\"\n\
position = [0.2, 0, 0]\n\
direction = [1, 0, 0]\n\
u_min = -40\n\
[fluid]\n\
rho = 1026\n";

    /// `BASE` with line `n` (1-based) replaced by `with`.
    fn base_with(n: usize, with: &str) -> String {
        let mut lines: Vec<&str> = BASE.lines().collect();
        lines[n - 1] = with;
        lines.join("\n") + "\n"
    }

    #[test]
    fn base_is_valid() {
        let v = parse_design(BASE, "b.toml").unwrap();
        assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (2, 1, 1));
    }

    #[test]
    fn schema_errors() {
        use DesignErrorKind::*;
        let e = expect_err(
            &base_with(10, "colour = \"red\""),
            "body[1].colour",
            Some(10),
            "unknown field `colour`",
        );
        assert_eq!(e.column, Some(1));
        assert_eq!(e.kind, Schema);
        expect_err(
            &base_with(1, "nmae = \"t\""),
            "nmae",
            Some(1),
            "unknown field `nmae`",
        );
        expect_err(
            &base_with(4, "mass = \"heavy\""),
            "body[0].mass",
            Some(4),
            "invalid type",
        );
        expect_err(
            &base_with(13, "axis = [0, 1]"),
            "joint[0].axis",
            Some(13),
            "invalid length 2",
        );
        // An unterminated array is reported where the parser gives up (the next line).
        let e = expect_err(
            &base_with(17, "position = [0.2, 0"),
            "",
            Some(18),
            "TOML syntax error",
        );
        assert_eq!(e.kind, Syntax);
        expect_err(
            &base_with(4, "mass = 2.0 2.0"),
            "",
            Some(4),
            "TOML syntax error",
        );
        expect_err(&base_with(5, "mass = 3.0"), "", Some(5), "duplicate key");
        // Missing required key: reported at the [[body]] header.
        expect_err(
            &base_with(6, ""),
            "body[0]",
            Some(2),
            "missing field `radius`",
        );
        // Non-finite literals.
        let e = expect_err(
            &base_with(17, "position = [0.2, nan, 0]"),
            "thruster[0].position[1]",
            Some(17),
            "must be a finite number",
        );
        assert_eq!(e.column, Some(18));
        expect_err(
            &base_with(4, "mass = inf"),
            "body[0].mass",
            Some(4),
            "finite",
        );
        expect_err(
            &base_with(21, "rho = -inf"),
            "fluid.rho",
            Some(21),
            "finite",
        );
        // Wrong body reference type.
        expect_err(
            &base_with(16, "body = 1.5"),
            "thruster[0].body",
            Some(16),
            "body name (string) or a 0-based body index",
        );
        // Forms.
        expect_err(
            &format!("preset = \"usm-paper\"\n{BASE}"),
            "body",
            Some(3),
            "cannot be combined with `preset`",
        );
        expect_err(
            &format!("{BASE}[generator]\nlinks = 3\n"),
            "generator",
            Some(22),
            "cannot be combined",
        );
        expect_err(
            "[generator]\n[[body]]\nname=\"x\"\nmass=1\nlength=1\nradius=1\n",
            "generator",
            Some(1),
            "cannot be combined",
        );
        expect_err("name = \"x\"\n", "", None, "no design found");
        expect_err(
            "[[thruster]]\nbody=0\nposition=[0,0,0]\ndirection=[1,0,0]\n",
            "",
            None,
            "no design found",
        );
        expect_err(
            "preset = \"usm-paper\"\n[[thruster]]\nbody=0\nposition=[0,0,0]\ndirection=[1,0,0]\n",
            "thruster",
            Some(2),
            "not allowed with `preset`",
        );
        // Hydro keys of the wrong kind.
        expect_err(
            &base_with(
                6,
                "radius = 0.1\n[body.hydro]\nkind = \"coefficients\"\ncd_x = 1",
            ),
            "body[0].hydro.cd_x",
            Some(9),
            "not a key of hydro kind",
        );
        expect_err(
            &base_with(6, "radius = 0.1\n[body.hydro]\nkind = \"foil\""),
            "body[0].hydro.kind",
            Some(8),
            "unknown hydro kind",
        );
        expect_err(
            &base_with(6, "radius = 0.1\n[body.hydro]\nkind = \"coefficients\""),
            "body[0].hydro.added_mass",
            Some(7),
            "required",
        );
        expect_err(
            &base_with(6, "radius = 0.1\n[body.hydro]\nstrips = 0"),
            "body[0].hydro.strips",
            Some(8),
            "between 1 and",
        );
        expect_err(
            &base_with(6, "radius = 0.1\nvolume = 0.1\nneutral = true"),
            "body[0].neutral",
            Some(8),
            "not both",
        );
        // Generator schema.
        expect_err(
            "[generator]\nlinks = 4\nthruster_rule = \"diagonal\"\n",
            "generator.thruster_rule",
            Some(3),
            "unknown thruster rule",
        );
        expect_err(
            "[generator]\nlinks = -4\n",
            "generator.links",
            Some(2),
            "invalid value",
        );
        expect_err(
            "[generator]\nlinkz = 4\n",
            "generator.linkz",
            Some(2),
            "unknown field",
        );
    }

    #[test]
    fn physics_errors() {
        use DesignErrorKind::*;
        let e = expect_err(
            &base_with(4, "mass = -2.0"),
            "body[0].mass",
            Some(4),
            "body[0].mass: must be > 0",
        );
        assert_eq!(e.kind, Invalid);
        assert_eq!(e.column, Some(1));
        expect_err(
            &base_with(9, "mass = 0"),
            "body[1].mass",
            Some(9),
            "must be > 0",
        );
        expect_err(
            &base_with(5, "length = 0.0"),
            "body[0].length",
            Some(5),
            "must be > 0",
        );
        expect_err(
            &base_with(11, "radius = -0.1"),
            "body[1].radius",
            Some(11),
            "must be > 0",
        );
        expect_err(
            &base_with(16, "body = \"c\""),
            "thruster[0].body",
            Some(16),
            "no body named 'c'",
        );
        expect_err(
            &base_with(16, "body = 2"),
            "thruster[0].body",
            Some(16),
            "body index 2 does not exist",
        );
        expect_err(
            &base_with(16, "body = -1"),
            "thruster[0].body",
            Some(16),
            "does not exist",
        );
        expect_err(
            &base_with(18, "direction = [0, 0, 0]"),
            "thruster[0].direction",
            Some(18),
            "thruster[0].direction: must be a nonzero vector",
        );
        expect_err(
            &base_with(18, "direction = [0, 1e-300, 1e-300]"),
            "thruster[0].direction",
            Some(18),
            "nonzero",
        );
        expect_err(
            &base_with(13, "axis = [0.0, 0.0, 0.0]"),
            "joint[0].axis",
            Some(13),
            "nonzero",
        );
        expect_err(
            &base_with(14, "limits_deg = [30, -30]"),
            "joint[0].limits_deg",
            Some(14),
            "min <= max",
        );
        expect_err(
            &base_with(19, "u_min = 50"),
            "thruster[0].u_min",
            Some(19),
            "u_min <= u_max",
        );
        expect_err(
            &base_with(19, "u_max = -50"),
            "thruster[0].u_max",
            Some(19),
            "u_min <= u_max",
        );
        // Errors found by Vehicle::validate are mapped back to their lines.
        expect_err(
            &base_with(21, "rho = -1"),
            "fluid.rho",
            Some(21),
            "must be > 0",
        );
        expect_err(
            &base_with(19, "time_constant = -1"),
            "thruster[0].time_constant",
            Some(19),
            "must be > 0",
        );
        expect_err(
            &base_with(6, "radius = 0.1\nvolume = -1"),
            "body[0].volume",
            Some(7),
            "must be > 0",
        );
        expect_err(
            &base_with(
                6,
                "radius = 0.1\ninertia = [[1, 0, 0], [0, -1, 0], [0, 0, 1]]",
            ),
            "body[0].inertia",
            Some(7),
            "positive definite",
        );
        expect_err(
            &base_with(6, "radius = 0.1\n[body.hydro]\ncd_y = -1"),
            "body[0].hydro.cd_y",
            Some(8),
            ">= 0",
        );
        // Wrong joint count: reported at the joint list.
        let e = expect_err(
            &format!("{BASE}[[joint]]\naxis = [0, 1, 0]\n"),
            "joint",
            Some(12),
            "needs 1 joints, got 2",
        );
        assert_eq!(e.kind, Invalid);
        expect_err(
            &base_with(12, "[[joint]]\naxis = [0, 1, 0]\n[[joint]]"),
            "joint",
            Some(12),
            "got 2",
        );
        // Generator checks with the key of the generator table.
        expect_err(
            "[generator]\nlinks = 4\nlink_length = [0.5, 0.5]\n",
            "generator.link_length",
            Some(3),
            "needs 1 or 4 values",
        );
        expect_err(
            "[generator]\nlinks = 30\n",
            "generator.links",
            Some(2),
            "between 2 and 20",
        );
        expect_err(
            "[generator]\njoint_limit_deg = -5\n",
            "generator.joint_limit_deg",
            Some(2),
            "> 0",
        );
        expect_err(
            "[generator]\nlink_mass = [1, -1, 1, 1, 1]\n",
            "generator.link_mass",
            Some(2),
            "> 0",
        );
        expect_err(
            "[generator]\nlink_length = []\n",
            "generator.link_length",
            Some(2),
            "at least one",
        );
        expect_err("[generator]\nlinks = 3\n[[thruster]]\nbody = \"L9\"\nposition = [0,0,0]\ndirection = [1,0,0]\n", "thruster[0].body", Some(4), "no body named 'L9'");
    }

    #[test]
    fn table_path_has_keys_but_no_lines() {
        let mut table: toml::Table = toml::from_str(&design_to_toml(&usm_paper())).unwrap();
        let v = parse_design_table(&table, "sweep").unwrap();
        close(&v, &usm_paper(), 1e-12).unwrap();
        let thr = table
            .get_mut("thruster")
            .and_then(|t| t.as_array_mut())
            .unwrap();
        let t2 = thr[2].as_table_mut().unwrap();
        t2.insert(
            "direction".into(),
            toml::Value::Array(vec![0.0.into(), 0.0.into(), 0.0.into()]),
        );
        let e = parse_design_table(&table, "sweep case 3").unwrap_err();
        assert_eq!(e.key, "thruster[2].direction");
        assert_eq!(e.line, None);
        assert_eq!(
            e.to_string(),
            "sweep case 3: thruster[2].direction: must be a nonzero vector"
        );
        // Generator overrides.
        let mut g: toml::Table = toml::from_str("[generator]\nlinks = 5\n").unwrap();
        let gen = g
            .get_mut("generator")
            .and_then(|t| t.as_table_mut())
            .unwrap();
        gen.insert("links".into(), 7.into());
        assert_eq!(parse_design_table(&g, "s").unwrap().bodies.len(), 13);
        let gen = g
            .get_mut("generator")
            .and_then(|t| t.as_table_mut())
            .unwrap();
        gen.insert("radius".into(), f64::NAN.into());
        let e = parse_design_value(&toml::Value::Table(g), "s").unwrap_err();
        assert_eq!(e.key, "generator.radius");
        assert!(parse_design_value(&toml::Value::Integer(3), "s").is_err());
        // load_design_table gives the explicit form of presets.
        let t = load_design_table("usm-paper").unwrap();
        assert_eq!(
            t.get("thruster")
                .and_then(|x| x.as_array())
                .map(|a| a.len()),
            Some(7)
        );
    }

    #[test]
    fn example_designs_load() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/designs");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) == Some("toml") {
                let v = load_design(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
                v.validate().unwrap();
                close(&v, &round_trip(&v).unwrap(), 1e-12).unwrap();
                n += 1;
            }
        }
        assert!(n >= 2, "expected example designs in {}", dir.display());
    }

    #[test]
    fn rpy_inverse_and_degrees() {
        for rpy in [
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(-3.0, 1.5, 2.9),
            Vec3::new(0.0, std::f64::consts::FRAC_PI_2, 0.7),
            Vec3::new(0.0, -std::f64::consts::FRAC_PI_2, -0.7),
        ] {
            let r = rot_rpy(&rpy);
            assert!((rot_rpy(&rpy_of(&r)) - r).abs().max() < 1e-14, "{rpy:?}");
        }
        for x in [
            std::f64::consts::FRAC_PI_2,
            1.0,
            -0.3,
            1e-5,
            std::f64::consts::PI,
        ] {
            assert_eq!(deg(x).to_radians(), x);
        }
        assert_eq!(fnum(1.0), "1.0");
        assert_eq!(fnum(1e300), "1e300");
        let t: toml::Table = toml::from_str("a = 1e300\nb = 1e-7").unwrap();
        assert_eq!(t["a"].as_float(), Some(1e300));
    }

    // ---------------------------------------------------------------- property tests

    fn arb_spec() -> impl Strategy<Value = GeneratorSpec> {
        (2usize..=12)
            .prop_flat_map(|n| {
                (
                    Just(n),
                    prop_oneof![
                        (0.1f64..1.5).prop_map(|l| vec![l]),
                        prop::collection::vec(0.1f64..1.5, n),
                    ],
                    prop_oneof![
                        Just(Vec::new()),
                        (1.0f64..30.0).prop_map(|m| vec![m]),
                        prop::collection::vec(1.0f64..30.0, n),
                    ],
                    (0.03f64..0.3, 0.05f64..0.3, 0.5f64..10.0, 0.1f64..3.1),
                    (0usize..4, 1.0f64..100.0, 0.0f64..0.2),
                    (0.0f64..1.5, 0.0f64..1.5, 0.0f64..2.0),
                )
            })
            .prop_map(
                |(n, ll, lm, (r, ml, mm, jl), (rule, tl, off), (ce, ca, cc))| GeneratorSpec {
                    links: n,
                    link_length: ll,
                    link_mass: lm,
                    radius: r,
                    module_length: ml,
                    module_mass: mm,
                    joint_limit: jl,
                    thruster_rule: ThrusterRule::ALL[rule],
                    thrust_limit: tl,
                    longitudinal_offset: off,
                    cd_axial_ends: ce,
                    cd_axial: ca,
                    cd_cross: cc,
                },
            )
    }

    /// The `[generator]` form of a spec.
    fn generator_toml(s: &GeneratorSpec) -> String {
        let mut o = String::from("[generator]\n");
        let _ = writeln!(o, "links = {}", s.links);
        let _ = writeln!(o, "link_length = {}", farr(&s.link_length));
        if !s.link_mass.is_empty() {
            let _ = writeln!(o, "link_mass = {}", farr(&s.link_mass));
        }
        for (k, v) in [
            ("radius", s.radius),
            ("module_length", s.module_length),
            ("module_mass", s.module_mass),
            ("joint_limit_deg", deg(s.joint_limit)),
            ("thrust_limit", s.thrust_limit),
            ("longitudinal_offset", s.longitudinal_offset),
            ("cd_axial_ends", s.cd_axial_ends),
            ("cd_axial", s.cd_axial),
            ("cd_cross", s.cd_cross),
        ] {
            let _ = writeln!(o, "{k} = {}", fnum(v));
        }
        let _ = writeln!(o, "thruster_rule = \"{}\"", s.thruster_rule);
        o
    }

    /// Byte ranges of number-like tokens (outside comments and strings, roughly).
    fn number_tokens(text: &str) -> Vec<Range<usize>> {
        let b = text.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        while i < b.len() {
            let c = b[i];
            let starts =
                c.is_ascii_digit() || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
            let prev_ok = i == 0 || matches!(b[i - 1], b' ' | b'[' | b',' | b'=');
            if starts && prev_ok {
                let s = i;
                i += 1;
                while i < b.len()
                    && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'E' | b'-' | b'+'))
                {
                    i += 1;
                }
                out.push(s..i);
            } else {
                i += 1;
            }
        }
        out
    }

    #[derive(Clone, Debug)]
    enum Mutation {
        DeleteLine(usize),
        DuplicateLine(usize),
        ReplaceNumber(usize, String),
        InsertGarbage(usize, String),
        Truncate(usize),
        SwapLines(usize, usize),
    }

    fn arb_mutation() -> impl Strategy<Value = Mutation> {
        let replacement = prop_oneof![
            Just("-1.0".to_string()),
            Just("0".to_string()),
            Just("nan".to_string()),
            Just("-inf".to_string()),
            Just("1e308".to_string()),
            Just("1e400".to_string()),
            Just("-1e-320".to_string()),
            Just("\"x\"".to_string()),
            Just("[]".to_string()),
            Just("9223372036854775807".to_string()),
            Just("99999999999999999999".to_string()),
            Just("{a = 1}".to_string()),
            "[ -~]{0,6}",
        ];
        prop_oneof![
            any::<usize>().prop_map(Mutation::DeleteLine),
            any::<usize>().prop_map(Mutation::DuplicateLine),
            (any::<usize>(), replacement).prop_map(|(i, s)| Mutation::ReplaceNumber(i, s)),
            (any::<usize>(), "[ -~\n]{0,12}").prop_map(|(i, s)| Mutation::InsertGarbage(i, s)),
            any::<usize>().prop_map(Mutation::Truncate),
            (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Mutation::SwapLines(i, j)),
        ]
    }

    fn floor_boundary(s: &str, mut i: usize) -> usize {
        i = i.min(s.len());
        while !s.is_char_boundary(i) {
            i -= 1;
        }
        i
    }

    fn apply(text: &str, m: &Mutation) -> String {
        let mut lines: Vec<&str> = text.lines().collect();
        let n = lines.len().max(1);
        match m {
            Mutation::DeleteLine(i) => {
                if !lines.is_empty() {
                    lines.remove(i % n);
                }
                lines.join("\n")
            }
            Mutation::DuplicateLine(i) => {
                if !lines.is_empty() {
                    let l = lines[i % n];
                    lines.insert(i % n, l);
                }
                lines.join("\n")
            }
            Mutation::SwapLines(i, j) => {
                if !lines.is_empty() {
                    lines.swap(i % n, j % n);
                }
                lines.join("\n")
            }
            Mutation::ReplaceNumber(i, s) => {
                let toks = number_tokens(text);
                if toks.is_empty() {
                    return text.to_string();
                }
                let r = toks[i % toks.len()].clone();
                format!("{}{}{}", &text[..r.start], s, &text[r.end..])
            }
            Mutation::InsertGarbage(i, s) => {
                let p = floor_boundary(text, i % (text.len() + 1));
                format!("{}{}{}", &text[..p], s, &text[p..])
            }
            Mutation::Truncate(i) => {
                let p = floor_boundary(text, i % (text.len() + 1));
                text[..p].to_string()
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn generated_designs_round_trip(spec in arb_spec()) {
            let v = spec.build("gen").unwrap();
            let back = round_trip(&v).map_err(TestCaseError::fail)?;
            prop_assert!(close(&v, &back, 1e-12).is_ok(), "{:?}", close(&v, &back, 1e-12));
            // The [generator] form builds the same vehicle.
            let g = parse_design(&generator_toml(&spec), "gen.toml")
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert!(close(&v, &g, 1e-12).is_ok(), "{:?}", close(&v, &g, 1e-12));
        }

        #[test]
        fn rotated_frames_round_trip(
            a in prop::array::uniform3(-3.1f64..3.1),
            b in prop::array::uniform3(-3.1f64..3.1),
            lock in any::<bool>(),
        ) {
            let mut v = usm_paper();
            let mut rb = vec3(b);
            if lock {
                rb[1] = std::f64::consts::FRAC_PI_2;
            }
            v.joints[0].placement.r = rot_rpy(&vec3(a));
            v.base.r = rot_rpy(&rb);
            v.end_effector.r = rot_rpy(&vec3(a).map(|x| -x));
            let back = round_trip(&v).map_err(TestCaseError::fail)?;
            prop_assert!(close(&v, &back, 1e-12).is_ok(), "{:?}", close(&v, &back, 1e-12));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        #[test]
        fn mutated_files_never_panic(muts in prop::collection::vec(arb_mutation(), 1..4)) {
            let mut text = design_to_toml(&usm_paper());
            for m in &muts {
                text = apply(&text, m);
            }
            match parse_design(&text, "mut.toml") {
                Ok(v) => prop_assert!(v.validate().is_ok()),
                Err(e) => {
                    // Every error names its origin and has a readable message.
                    let s = e.to_string();
                    prop_assert!(s.starts_with("mut.toml"));
                    prop_assert!(!e.message.is_empty());
                    if let Some(l) = e.line {
                        prop_assert!(l >= 1 && l <= text.lines().count().max(1) + 1, "{} {}", l, s);
                    }
                }
            }
            // The table path must not panic either.
            if let Ok(t) = toml::from_str::<toml::Table>(&text) {
                let _ = parse_design_table(&t, "mut");
            }
        }
    }
}
