//! Python values → TOML values and key overrides; library errors → [`UsmStudyError`].

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use usm_study::input::keypath::{set, KeyPath};

use crate::UsmStudyError;

/// An error met without the GIL (inside a run or a batch): its message, raised as a
/// [`UsmStudyError`] once the GIL is held again.
#[derive(Clone, Debug, thiserror::Error)]
#[error("{0}")]
pub struct Failure(pub String);

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        UsmStudyError::new_err(f.0)
    }
}

/// A library error as a [`Failure`]: the error and its causes on one line, `a: b: c`, as the
/// command line prints them (a cause its parent's message already ends with is not
/// repeated).
pub fn err(e: &(dyn std::error::Error + 'static)) -> Failure {
    let mut line = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !line.ends_with(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
        cause = c.source();
    }
    Failure(line)
}

/// A message as a [`Failure`].
pub fn msg(text: impl Into<String>) -> Failure {
    Failure(text.into())
}

/// A Python value as a TOML value: bool, int, float, str, list/tuple (array), dict (table).
pub fn to_toml(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return match v.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            Err(_) => Err(msg(format!("{key}: integer {v} does not fit in 64 bits")).into()),
        };
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v.extract()?;
        let mut out = Vec::with_capacity(items.len());
        for (i, x) in items.iter().enumerate() {
            out.push(to_toml(&format!("{key}[{i}]"), x)?);
        }
        return Ok(toml::Value::Array(out));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k.extract()?;
            let value = to_toml(&format!("{key}.{k}"), &x)?;
            t.insert(k, value);
        }
        return Ok(toml::Value::Table(t));
    }
    // numpy scalars and other numbers: anything float() accepts.
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(msg(format!(
        "{key}: a value of type {} is not a TOML value (use bool, int, float, str, list or dict)",
        v.get_type().name()?
    ))
    .into())
}

/// One `--set`-style override: a key path and its value.
#[derive(Clone, Debug)]
pub struct Set {
    /// The key as written (`control.k_psi`).
    pub key: String,
    /// The parsed key path.
    pub path: KeyPath,
    /// The value.
    pub value: toml::Value,
}

/// A Python dict of overrides (`{"control.k_psi": 0.3}`) as [`Set`]s, in order.
pub fn overrides(d: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<Set>> {
    let mut out = Vec::new();
    if let Some(d) = d {
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            let path =
                KeyPath::parse(key.trim()).map_err(|e| PyErr::from(msg(format!("{key}: {e}"))))?;
            let value = to_toml(&key, &v)?;
            out.push(Set { key, path, value });
        }
    }
    Ok(out)
}

/// Apply overrides to a scenario table, as `--set` does.
pub fn apply(table: &mut toml::Table, sets: &[Set]) -> Result<(), Failure> {
    for s in sets {
        set(table, &s.path.0, s.value.clone(), &s.key)
            .map_err(|e| msg(format!("{}: {e}", s.key)))?;
    }
    Ok(())
}
