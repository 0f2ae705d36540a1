//! URDF in and out (docs/urdf.md): [`import_urdf`] reads a robot description with the
//! hydrodynamic plugin blocks of UUV Simulator / Plankton and gz-sim into a [`Vehicle`];
//! [`vehicle_to_urdf`] writes a design back as URDF with those blocks (the round trip is exact
//! to rounding), and [`vehicle_to_mjcf`] as a MuJoCo model.
//!
//! Frames and units (docs/urdf.md "Conventions"): SI; a body frame is its root link's frame
//! (not moved to a tail face); joint `placement` is the URDF joint `<origin>`, its axis in the
//! child frame; matrices are converted to the model's convention (docs/model.md §2: `M_A`
//! positive, damping wrench `−(D_l ν + D_q (|ν| ∘ ν))` about the body frame origin, x forward,
//! z up).
//!
//! Files: `parse` (XML → links and joints, with lines), `plugins` (the plugin blocks),
//! `assemble` (tree → Vehicle, the rules), `export` (Vehicle → URDF), `mjcf` (Vehicle → MJCF).

mod assemble;
mod error;
mod export;
mod mjcf;
mod parse;
mod plugins;
#[cfg(test)]
mod tests;

pub use assemble::{ImportOptions, DEFAULT_THRUST_LIMIT};
pub use error::{Inferred, UrdfError};
pub use export::{vehicle_to_urdf, ExportError};
pub use mjcf::vehicle_to_mjcf;

use super::design::design_to_toml;
use super::Vehicle;
use std::fmt::Write as _;

/// An imported design and its ledger of inferred values.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The design (validated).
    pub vehicle: Vehicle,
    /// What the file did not give, in the order met.
    pub inferred: Vec<Inferred>,
}

/// Import a URDF text; `origin` names it in errors. The result is validated
/// ([`Vehicle::validate`]; a failure is reported at the `<robot>` element with its key path).
pub fn import_urdf(text: &str, origin: &str, opts: &ImportOptions) -> Result<Imported, UrdfError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| UrdfError {
        file: origin.to_string(),
        line: e.pos().row as usize,
        element: "XML".into(),
        message: e.to_string(),
    })?;
    let tree = parse::parse_tree(origin, &doc)?;
    let plugins = plugins::read_plugins(origin, doc.root_element())?;
    let (vehicle, inferred) = assemble::assemble(origin, &tree, &plugins, opts)?;
    vehicle.validate().map_err(|e| UrdfError {
        file: origin.to_string(),
        line: parse::line_of(doc.root_element()),
        element: "<robot>".into(),
        message: format!("the imported design is invalid: {e}"),
    })?;
    Ok(Imported { vehicle, inferred })
}

/// Read and import a URDF file.
pub fn load_urdf(path: &std::path::Path, opts: &ImportOptions) -> Result<Imported, UrdfError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| UrdfError {
        file: origin.clone(),
        line: 0,
        element: "file".into(),
        message: format!("cannot read: {e}"),
    })?;
    import_urdf(&text, &origin, opts)
}

/// The design file of an import: a header naming the source and listing every inferred
/// value (the ledger of this design), then the explicit form ([`design_to_toml`]).
pub fn imported_to_toml(imp: &Imported, source: &str) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# Imported by `usm-study design import` from {source} (docs/urdf.md)."
    );
    if imp.inferred.is_empty() {
        let _ = writeln!(
            o,
            "# Ledger of this design: every value was given by the file."
        );
    } else {
        let _ = writeln!(
            o,
            "# Ledger of this design: {} value(s) the file did not give, filled by the project's rules:",
            imp.inferred.len()
        );
        for i in &imp.inferred {
            let _ = writeln!(o, "#   inferred: {}: {}", i.key, i.note);
        }
    }
    o.push_str(&design_to_toml(&imp.vehicle));
    o
}
