//! `Polylidar(preset=..., **params)`: a preset's [`Config`] with keyword overrides, in the
//! original package's names.

use polylidar::{Config, Preset};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

/// Keywords of the original `polylidar.Polylidar3D` that have another name here.
const ALIASES: [(&str, &str); 1] = [("task_threads", "threads")];

/// The configuration of `preset` (default: [`Config::default`]) with `params` applied
/// field by field; nested sections (`laplacian`, `bilateral`, `fastga`, `postprocess`) are
/// dicts merged into the preset's, `None` turns an optional section off.
pub fn build(
    py: Python<'_>,
    preset: Option<&str>,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Config> {
    let base = match preset {
        None => Config::default(),
        Some(name) => name
            .parse::<Preset>()
            .map_err(|e| PyValueError::new_err(e.to_string()))?
            .config(),
    };
    let Some(params) = params.filter(|p| !p.is_empty()) else {
        return Ok(base);
    };
    let mut value =
        serde_json::to_value(&base).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let overrides = to_json(py, params)?;
    let (Value::Object(target), Value::Object(mut overrides)) = (&mut value, overrides) else {
        return Err(PyTypeError::new_err("parameters must be keyword arguments"));
    };
    for (from, to) in ALIASES {
        if let Some(v) = overrides.remove(from) {
            overrides.insert(to.to_owned(), v);
        }
    }
    // The original has two normal thresholds; this implementation one (`norm_thresh`, the
    // segment's normal test and the 2.5D filter).
    if let Some(min) = overrides.remove("norm_thresh_min") {
        match overrides.get("norm_thresh") {
            Some(n) if *n != min => {
                return Err(PyValueError::new_err(format!(
                    "norm_thresh_min = {min} differs from norm_thresh = {n}: this implementation \
                     has one normal threshold (norm_thresh); pass one of them"
                )));
            }
            _ => {
                overrides.insert("norm_thresh".to_owned(), min);
            }
        }
    }
    for (key, v) in overrides {
        let Some(slot) = target.get_mut(&key) else {
            let mut known: Vec<&str> = target.keys().map(String::as_str).collect();
            known.extend(["norm_thresh_min", "task_threads"]);
            return Err(PyTypeError::new_err(format!(
                "Polylidar() got an unexpected keyword argument '{key}'; known: {}",
                known.join(", ")
            )));
        };
        match (slot, v) {
            (Value::Object(section), Value::Object(fields)) => section.extend(fields),
            (slot, Value::Object(fields)) if slot.is_null() => {
                *slot = Value::Object(fields);
            }
            (slot, v) => *slot = v,
        }
    }
    let config: Config = serde_json::from_value(value)
        .map_err(|e| PyValueError::new_err(format!("invalid parameter: {e}")))?;
    config
        .validate()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(config)
}

/// `obj` as JSON through Python's `json` module (NumPy scalars through `.item()`).
pub fn to_json(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Value> {
    let json = py.import("json")?;
    let item = py
        .import("operator")?
        .getattr("methodcaller")?
        .call1(("item",))?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("default", item)?;
    kwargs.set_item("allow_nan", false)?;
    let text: String = json
        .call_method("dumps", (obj,), Some(&kwargs))
        .map_err(|e| {
            PyTypeError::new_err(format!(
                "parameters must be numbers, strings, booleans, lists or dicts: {e}"
            ))
        })?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A JSON value as the Python object `json.loads` makes of it.
pub fn from_json<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?
        .call_method1("loads", (value.to_string(),))
}
