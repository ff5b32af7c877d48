//! The window `render` uses when none is given (`--window` absent), for a volume file: the data's
//! foreground, found without the user opening another tool.
//!
//! The rule, on at most 2²⁰ evenly strided finite samples ([`Volume::strided_sample`](crate::io::volume::Volume::strided_sample)):
//! take the values between the 0.5th and 99.5th percentiles (robust to a few outliers: metal in
//! a CT, a hot pixel), split them in two by Otsu's threshold (the split of a 256-bin histogram
//! that maximises the variance between the classes: background, air or empty space, below it),
//! and map the threshold to the table's first entry and the 99.5th percentile to its last. The
//! default transfer function for a file (`ct-bone-skin`) is transparent over its first 18 %, so
//! the background vanishes and what lies above it gets colour and opacity by value.
//!
//! The built-in scene keeps its own range, and a stream from a pipe, which cannot be read twice,
//! its type's range; `footprint info` prints the window this picks.

use crate::io::volume::SampleType;
use crate::io::volume::ValueMap;
use crate::scene::ShadingSpec;
use crate::CliError;
use footprint::shade::Shading;

/// The window for a render without `--window`: [`auto_window`] of a user's volume's `sample`;
/// else (the built-in scene, or no sample spans a range) the data's `range`; for a pipe, which
/// cannot be read twice (`piped`: its sample type), an 8-bit type's range, or an error asking
/// for `--window`.
pub(crate) fn default_window(
    name: &str,
    range: Option<(f32, f32)>,
    piped: Option<SampleType>,
    sample: Option<&[f32]>,
) -> Result<[f32; 2], CliError> {
    if let Some(w) = sample.and_then(auto_window) {
        return Ok(w);
    }
    let (lo, hi) = match (range, piped) {
        (Some(r), _) => r,
        (None, Some(SampleType::U8)) => (0.0, 255.0),
        (None, Some(SampleType::I8)) => (-128.0, 127.0),
        (None, _) => {
            return Err(CliError::input(
                "standard input cannot be read twice: give --window LO,HI",
            ))
        }
    };
    range_window(name, lo, hi)
}

/// The window of data whose finite samples span `lo`..=`hi` when no sample gives one
/// ([`auto_window`]): that range, refused where it is empty (no finite sample: `lo > hi`) or
/// a single value. What `render` does, and what `info` reports it would do.
pub(crate) fn range_window(name: &str, lo: f32, hi: f32) -> Result<[f32; 2], CliError> {
    if lo > hi {
        // `range` of data without one finite sample.
        return Err(CliError::input(format!(
            "{name}: no sample is finite (all NaN or infinite): nothing to render"
        )));
    }
    if !(hi > lo) {
        return Err(CliError::input(format!(
            "{name}: the data are constant ({lo}); give --window"
        )));
    }
    Ok([lo, hi])
}

/// `--window LO,HI` (data units, f64) as `render` checks it, in the renderer's values
/// (through `values`): HI must exceed LO (both finite: the parser refuses anything else), and
/// stay above it as f32 values.
pub(crate) fn check_given(window: [f64; 2], values: ValueMap) -> Result<[f32; 2], CliError> {
    if !(window[1] > window[0]) {
        return Err(CliError::input(format!(
            "--window {},{}: HI must exceed LO",
            window[0], window[1]
        )));
    }
    let w = values.window_from_data(window);
    if !(w[1] > w[0]) || !w[0].is_finite() || !w[1].is_finite() {
        return Err(CliError::input(format!(
            "--window {},{}: f32 values cannot tell LO from HI at this magnitude (the samples \
             are not wide enough to be rebased): widen the window",
            window[0], window[1]
        )));
    }
    Ok(w)
}

/// The percentiles of the robust range, in percent.
pub const ROBUST: [f64; 2] = [0.5, 99.5];

/// What [`auto_window`] says it did, for `info` and `--json`.
pub const RULE: &str = "Otsu's threshold of the values between the 0.5th and 99.5th percentiles, \
                        to the 99.5th percentile";

/// The value at percentile `p` (0–100) of `sorted` (ascending, non-empty): the nearest rank.
pub fn percentile(sorted: &[f32], p: f64) -> f32 {
    let i = ((p / 100.0) * (sorted.len().max(1) - 1) as f64).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// The window for finite samples `sorted` (ascending); `None` when they span no range (constant
/// data, or nothing between the robust percentiles), where the caller falls back to the data's
/// range.
pub fn auto_window(sorted: &[f32]) -> Option<[f32; 2]> {
    if sorted.is_empty() {
        return None;
    }
    let (lo, hi) = (percentile(sorted, ROBUST[0]), percentile(sorted, ROBUST[1]));
    if !(hi > lo) {
        return None;
    }
    const BINS: usize = 256;
    let width = (f64::from(hi) - f64::from(lo)) / BINS as f64;
    let mut hist = [0u64; BINS];
    for &v in sorted.iter().filter(|&&v| v >= lo && v <= hi) {
        let b = ((f64::from(v) - f64::from(lo)) / width) as usize;
        hist[b.min(BINS - 1)] += 1;
    }
    let total: u64 = hist.iter().sum();
    let sum: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    // Otsu: the split after bin t maximising w0·w1·(μ0 − μ1)².
    let (mut best, mut split) = (-1.0f64, 0usize);
    let (mut w0, mut s0) = (0u64, 0.0f64);
    for (t, &c) in hist.iter().enumerate().take(BINS - 1) {
        w0 += c;
        s0 += t as f64 * c as f64;
        let w1 = total - w0;
        if w0 == 0 || w1 == 0 {
            continue;
        }
        let (m0, m1) = (s0 / w0 as f64, (sum - s0) / w1 as f64);
        let between = w0 as f64 * w1 as f64 * (m0 - m1) * (m0 - m1);
        if between > best {
            (best, split) = (between, t);
        }
    }
    let threshold = (f64::from(lo) + (split + 1) as f64 * width) as f32;
    Some(if best > 0.0 && threshold < hi {
        [threshold, hi]
    } else {
        [lo, hi]
    })
}

/// `shading` (completed from `spec`) with an iso value in the renderer's values: the data's, as
/// `spec` holds it in f64, mapped through `values` where wide samples are rebased.
pub(crate) fn values_shading(shading: Shading, spec: ShadingSpec, values: ValueMap) -> Shading {
    match shading {
        Shading::Iso {
            value,
            opacity,
            thickness,
            phong,
        } if !values.is_identity() => {
            let exact = match spec {
                ShadingSpec::Iso { value } => value,
                _ => f64::from(value),
            };
            Shading::Iso {
                value: values.from_data(exact),
                opacity,
                thickness,
                phong,
            }
        }
        other => other,
    }
}

/// The warnings for an iso value outside the data's range `[lo, hi]` (no surface can show) and
/// for a `--window` that misses that range entirely (every voxel maps to one end of the transfer
/// function). `prepare` prints them (`footprint: warning: …`) and goes on.
pub fn outside_data_warnings(
    shading: &Shading,
    window: Option<[f32; 2]>,
    (lo, hi): (f32, f32),
) -> Vec<String> {
    let mut out = Vec::new();
    if let Shading::Iso { value, .. } = shading {
        if !(*value >= lo && *value <= hi) {
            out.push(format!(
                "iso value {value} lies outside the data's range [{lo}, {hi}]: no surface will show"
            ));
        }
    }
    if let Some([a, b]) = window {
        if b < lo || a > hi {
            out.push(format!(
                "--window {a},{b} lies outside the data's range [{lo}, {hi}]: every voxel maps to \
                 one end of the transfer function"
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn background_below_the_threshold_and_outliers_ignored() {
        // 60 % air near 0, 35 % tissue near 1000, 4.5 % bone near 2000, 0.5 % metal at 30000.
        let mut v: Vec<f32> = (0..10_000)
            .map(|i| match i % 200 {
                0..=119 => (i % 7) as f32,
                120..=189 => 1000.0 + (i % 11) as f32,
                190..=198 => 2000.0 + (i % 5) as f32,
                _ => 30_000.0,
            })
            .collect();
        v.sort_by(f32::total_cmp);
        let [a, b] = auto_window(&v).unwrap();
        assert!(
            a > 6.0 && a < 1000.0,
            "threshold {a} between air and tissue"
        );
        assert!((2000.0..=2004.0).contains(&b), "top {b} at bone, not metal");
    }

    #[test]
    fn constant_and_empty_data_fall_back() {
        assert_eq!(auto_window(&[]), None);
        assert_eq!(auto_window(&[3.0; 100]), None);
        let ramp: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        let [a, b] = auto_window(&ramp).unwrap();
        assert!(a > 0.0 && a < b && b <= 999.0, "{a} {b}");
    }
}
