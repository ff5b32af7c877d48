//! Depth from Python (issue 77): `footprint.depth_map` and `footprint.probe` over a numpy volume,
//! read in place as `render` reads it (`footprint_harness::commands::probe`: where each ray's
//! accumulated opacity first reaches 0.5 in the frame's continuous model).

use crate::keywords::request;
use crate::{interruptible, spacing3, with_volume};
use footprint_harness::args::RenderArgs;
use footprint_harness::commands::probe::probe_frame;
use footprint_harness::io::stream::InMemory;
use footprint_harness::pipeline::depth::Probe;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// The probes of `volume`'s frame (`keywords` as `render`'s) at `pixels` (every pixel: None).
fn probes_of(
    py: Python<'_>,
    volume: &Bound<'_, PyAny>,
    spacing: (f64, f64, f64),
    keywords: &Bound<'_, PyDict>,
    pixels: Option<&[[usize; 2]]>,
) -> PyResult<(Vec<Probe>, (usize, usize))> {
    let mut args: RenderArgs = request(keywords)?;
    let size = args.size;
    let found = with_volume(volume, spacing3(spacing), |v, _| {
        args.memory = Some(InMemory {
            volume: Arc::new(v),
            name: "array".into(),
        });
        let out = interruptible(py, None, || probe_frame(&args, pixels));
        args.memory = None;
        out
    })?;
    Ok((found.0, size))
}

/// Every pixel's depth, (height, width) float32, NaN where the opacity never reaches 0.5.
#[pyfunction]
pub fn depth_array<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    spacing: (f64, f64, f64),
    keywords: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let (found, (w, h)) = probes_of(py, volume, spacing, keywords, None)?;
    let depth: Vec<f32> = found.iter().map(|p| p.depth as f32).collect();
    PyArray1::from_vec(py, depth).reshape([h, w])
}

/// One pixel's (depth, world point, value); NaNs where the opacity never reaches 0.5.
#[pyfunction]
pub fn probe_pixel(
    py: Python<'_>,
    volume: &Bound<'_, PyAny>,
    spacing: (f64, f64, f64),
    at: (usize, usize),
    keywords: &Bound<'_, PyDict>,
) -> PyResult<(f64, (f64, f64, f64), f64)> {
    let (found, _) = probes_of(py, volume, spacing, keywords, Some(&[[at.0, at.1]]))?;
    let p = found[0];
    Ok((p.depth, (p.world[0], p.world[1], p.world[2]), p.value))
}
