//! Transfer functions: presets and control-point files, sampled into the lookup table the core
//! reads. Control points are `t r g b a` with t ∈ [0, 1] the position in the value window, colour
//! straight (not premultiplied), a the opacity of a slab one reference distance thick.

pub mod paraview;

use crate::CliError;
use std::path::Path;

/// Entries in the lookup tables the harness builds.
pub const LUT_SIZE: usize = 256;

/// A named preset's control points.
pub fn preset(name: &str) -> Option<Vec<[f32; 5]>> {
    Some(match name {
        // Grey linear ramp: colour and opacity rise together.
        "grey" => vec![[0.0, 0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0, 1.0]],
        // CT: air transparent, skin a faint tan veil, bone near-opaque ivory.
        "ct-bone-skin" => vec![
            [0.0, 0.0, 0.0, 0.0, 0.0],
            [0.18, 0.0, 0.0, 0.0, 0.0],
            [0.24, 0.9, 0.62, 0.5, 0.06],
            [0.34, 0.9, 0.62, 0.5, 0.03],
            [0.45, 0.9, 0.75, 0.6, 0.0],
            [0.55, 0.95, 0.92, 0.85, 0.35],
            [1.0, 1.0, 1.0, 0.95, 0.9],
        ],
        // Density, after the paper's ozone and orbital images: blue (low) → green → red (high).
        "density" => vec![
            [0.0, 0.0, 0.0, 1.0, 0.0],
            [0.08, 0.1, 0.2, 1.0, 0.01],
            [0.35, 0.1, 0.9, 0.3, 0.06],
            [0.7, 1.0, 0.3, 0.1, 0.25],
            [1.0, 1.0, 0.1, 0.05, 0.6],
        ],
        _ => return None,
    })
}

/// Names of the presets.
pub const PRESETS: [&str; 3] = ["grey", "ct-bone-skin", "density"];

/// Parses a control-point file: one `t r g b a` per line, `#` comments, t increasing in [0, 1].
pub fn parse_points(text: &str, name: &str) -> Result<Vec<[f32; 5]>, CliError> {
    let mut points = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let v: Vec<f32> = line
            .split_whitespace()
            .map(|x| x.parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                CliError::input(format!(
                    "{name}:{}: expected five numbers 't r g b a'",
                    n + 1
                ))
            })?;
        if v.len() != 5 || v.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Err(CliError::input(format!(
                "{name}:{}: expected five numbers in [0, 1]: 't r g b a'",
                n + 1
            )));
        }
        if points.last().is_some_and(|p: &[f32; 5]| p[0] >= v[0]) {
            return Err(CliError::input(format!(
                "{name}:{}: positions must increase",
                n + 1
            )));
        }
        points.push([v[0], v[1], v[2], v[3], v[4]]);
    }
    if points.len() < 2 {
        return Err(CliError::input(format!(
            "{name}: needs at least two control points"
        )));
    }
    Ok(points)
}

/// Resolves `--tf`: a preset name (ours, or ParaView's built-in ones, see [`crate::tf::paraview`]), a
/// ParaView preset file (`.json`; `FILE.json#NAME` picks a preset by name from a file of several),
/// or a control-point file.
pub fn load(spec: &str) -> Result<Vec<[f32; 5]>, CliError> {
    if let Some(p) = preset(spec) {
        return Ok(p);
    }
    if let Some(p) = paraview::builtin_points(spec) {
        return Ok(p);
    }
    let (file, want) = match spec.rsplit_once('#') {
        Some((f, n)) if f.to_ascii_lowercase().ends_with(".json") => (f, Some(n)),
        _ => (spec, None),
    };
    let path = Path::new(file);
    if !path.exists() {
        return Err(CliError::input(format!(
            "--tf '{spec}': not a preset ({}; ParaView's {}) nor a file",
            PRESETS.join(", "),
            paraview::BUILTINS.join(", ")
        )));
    }
    let bytes = crate::io::read_file(path)?;
    let text =
        String::from_utf8(bytes).map_err(|_| CliError::input(format!("{file}: not text")))?;
    if file.to_ascii_lowercase().ends_with(".json") {
        return paraview::parse_json(&text, file, want);
    }
    parse_points(&text, spec)
}

/// Samples control points into a LUT of `LUT_SIZE` straight RGBA entries (linear between points,
/// constant beyond the ends).
pub fn lut(points: &[[f32; 5]]) -> Vec<[f32; 4]> {
    (0..LUT_SIZE)
        .map(|i| {
            let t = i as f32 / (LUT_SIZE - 1) as f32;
            let j = points
                .iter()
                .position(|p| p[0] >= t)
                .unwrap_or(points.len() - 1);
            let (p, q) = if j == 0 {
                (points[0], points[0])
            } else {
                (points[j - 1], points[j])
            };
            let f = if q[0] > p[0] {
                ((t - p[0]) / (q[0] - p[0])).clamp(0.0, 1.0)
            } else {
                0.0
            };
            [1, 2, 3, 4].map(|c| p[c] + f * (q[c] - p[c]))
        })
        .collect()
}
