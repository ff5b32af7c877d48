//! Python keyword arguments as a typed request (issue 76): each keyword's value is converted to
//! the harness's [`Value`] by its Python type (never written as flag text), and the request is
//! built and checked by `footprint_harness::args::keywords`, as the command line's flags are.

use crate::py_err;
use footprint_harness::args::keywords::{from_keywords, Keywords};
use footprint_harness::args::Value;
use footprint_harness::io::grid::Coordinates;
use footprint_harness::io::volume::Volume;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyString};

/// A Python keyword's value, typed (`None`: the keyword is left at its default): `bool`, `int`
/// (numpy's too), `float`, `str` or a path, or a sequence of them (tuple, list, 1-D array).
fn value(key: &str, o: &Bound<'_, PyAny>) -> PyResult<Option<Value>> {
    if o.is_none() {
        return Ok(None);
    }
    Ok(Some(typed(key, o)?))
}

fn typed(key: &str, o: &Bound<'_, PyAny>) -> PyResult<Value> {
    if let Ok(b) = o.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if let Ok(i) = o.extract::<i64>() {
        return Ok(Value::Int(i));
    }
    if let Ok(x) = o.extract::<f64>() {
        return Ok(Value::Float(x));
    }
    if let Ok(t) = o.cast::<PyString>() {
        return Ok(Value::Text(t.extract::<String>()?));
    }
    if o.hasattr("__fspath__")? {
        let path = o.py().import("os")?.call_method1("fspath", (o,))?;
        return Ok(Value::Text(path.extract::<String>()?));
    }
    if let Ok(items) = o.try_iter() {
        let v = items
            .map(|item| typed(key, &item?))
            .collect::<PyResult<Vec<Value>>>()?;
        return Ok(Value::List(v));
    }
    Err(PyValueError::new_err(format!(
        "{key}: a value of type {} is not understood (numbers, strings, paths and tuples are)",
        o.get_type()
    )))
}

/// A request (`render`'s, `verify`'s or `bench`'s) built from Python keywords as typed values:
/// the command line's defaults, each keyword set and checked as its flag would be.
pub fn request<T: Keywords>(keywords: &Bound<'_, PyDict>) -> PyResult<T> {
    let mut pairs = Vec::new();
    for (k, v) in keywords.iter() {
        let key: String = k.extract()?;
        if let Some(v) = value(&key, &v)? {
            pairs.push((key, v));
        }
    }
    from_keywords(pairs.iter().map(|(k, v)| (k.as_str(), v))).map_err(py_err)
}

/// Takes the `coordinates` keyword out of `keywords` (it is no flag: a `.vtr` carries them in
/// the file): a rectilinear grid's (x, y, z) coordinates, three sequences of numbers in world
/// units, one per sample along each axis; `None` where it is absent or None.
pub fn take_coordinates(keywords: &Bound<'_, PyDict>) -> PyResult<Option<[Vec<f64>; 3]>> {
    let Some(c) = keywords.get_item("coordinates")? else {
        return Ok(None);
    };
    keywords.del_item("coordinates")?;
    if c.is_none() {
        return Ok(None);
    }
    let bad = || PyValueError::new_err("coordinates: give three sequences of numbers (x, y, z)");
    let mut axes = Vec::new();
    for axis in c.try_iter().map_err(|_| bad())? {
        let numbers = axis?
            .try_iter()
            .map_err(|_| bad())?
            .map(|x| x?.extract::<f64>().map_err(|_| bad()))
            .collect::<PyResult<Vec<f64>>>()?;
        axes.push(numbers);
    }
    let [x, y, z]: [Vec<f64>; 3] = axes.try_into().map_err(|_| bad())?;
    Ok(Some([x, y, z]))
}

/// `volume` on the rectilinear grid of `coordinates` (checked against its dims: finite,
/// strictly increasing; its spacing becomes their mean), or as it is for `None`.
pub fn on_grid(mut volume: Volume, coordinates: Option<[Vec<f64>; 3]>) -> PyResult<Volume> {
    if let Some(axes) = coordinates {
        let grid = Coordinates::new(axes, volume.dims)
            .map_err(|e| PyValueError::new_err(format!("coordinates: {e}")))?;
        volume.spacing = grid.mean_spacing();
        volume.grid = Some(std::sync::Arc::new(grid));
    }
    Ok(volume)
}
