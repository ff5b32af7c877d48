//! Transfer functions: presets and control-point files, sampled into the lookup table the core
//! reads. Control points are `t r g b a` with t ∈ [0, 1] the position in the value window, colour
//! straight (not premultiplied), a the opacity of a slab one reference distance thick.

pub mod labels;
pub mod paraview;

use crate::CliError;
use std::path::Path;

/// Entries in the lookup tables the harness builds (the core's presets' size).
pub use footprint::shade::LUT_SIZE;

/// A named preset's control points (the core's [`footprint::shade::Preset`]s).
pub fn preset(name: &str) -> Option<Vec<[f32; 5]>> {
    footprint::shade::Preset::from_name(name).map(|p| p.points().to_vec())
}

/// Names of the presets.
pub const PRESETS: [&str; 3] = {
    use footprint::shade::Preset;
    [
        Preset::ALL[0].name(),
        Preset::ALL[1].name(),
        Preset::ALL[2].name(),
    ]
};

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
/// constant beyond the ends): the core's [`footprint::shade::presets::sample_points`].
pub fn lut(points: &[[f32; 5]]) -> Vec<[f32; 4]> {
    let mut out = vec![[0.0; 4]; LUT_SIZE];
    footprint::shade::presets::sample_points(points, &mut out);
    out
}
