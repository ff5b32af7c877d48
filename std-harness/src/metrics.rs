//! How far apart two images are.
//!
//! Colour images ([`compare`]): linear premultiplied RGBA in [0, 1], exactly what `render` writes
//! to its PNG before 8-bit quantisation. Per channel c over the N pixels:
//! MSE_c = Σ (core − ref)² / N, RMSE_c = √MSE_c, PSNR_c = 10·log₁₀(1 / MSE_c) dB (peak 1), max abs
//! = max |core − ref|. *Overall* is the same over the R, G and B channels together (MSE averaged
//! over 3N values): the colour a person sees. PSNR is infinite (JSON null) when the images are
//! identical.
//!
//! Single-channel images ([`max_rel_diff`]): max |a − b| relative to b's peak, the footprint
//! measure used by `compare`, the tests and the stability charts.

use crate::io::{image::GreyImage, json::Json};
use crate::CliError;

/// Error statistics of one channel or of RGB together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    pub mse: f64,
    pub rmse: f64,
    pub psnr_db: f64,
    pub max_abs: f64,
}

impl ErrorStats {
    fn from_sums(sum_sq: f64, count: usize, max_abs: f64) -> Self {
        let mse = sum_sq / count as f64;
        let psnr_db = if mse > 0.0 {
            10.0 * (1.0 / mse).log10()
        } else {
            f64::INFINITY
        };
        ErrorStats {
            mse,
            rmse: mse.sqrt(),
            psnr_db,
            max_abs,
        }
    }
    /// `psnr_db`, `rmse`, `max_abs`, `mse`.
    pub fn json(&self) -> Json {
        Json::object()
            .num("psnr_db", self.psnr_db)
            .num("rmse", self.rmse)
            .num("max_abs", self.max_abs)
            .num("mse", self.mse)
    }
}

/// Per-channel (R, G, B, A) and overall (RGB) errors of `core` against `reference`.
pub fn compare(core: &[[f32; 4]], reference: &[[f64; 4]]) -> ([ErrorStats; 4], ErrorStats) {
    let mut sq = [0.0f64; 4];
    let mut mx = [0.0f64; 4];
    for (c, r) in core.iter().zip(reference) {
        for ch in 0..4 {
            let d = (f64::from(c[ch]) - r[ch]).abs();
            sq[ch] += d * d;
            // NaN propagates (f64::max would drop it): a non-finite pixel is never "close".
            if d.is_nan() || d > mx[ch] {
                mx[ch] = d;
            }
        }
    }
    let n = core.len().max(1);
    let per = [0, 1, 2, 3].map(|ch| ErrorStats::from_sums(sq[ch], n, mx[ch]));
    let overall = ErrorStats::from_sums(sq[0] + sq[1] + sq[2], 3 * n, mx[0].max(mx[1]).max(mx[2]));
    (per, overall)
}

/// PSNR (dB, peak 1) of `a` against `b` over every value they hold (the grey values, or R, G and
/// B together for colour PFMs): [`compare`]'s overall figure for images read from files.
pub fn psnr(a: &GreyImage, b: &GreyImage) -> f64 {
    let sum_sq = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum::<f64>();
    ErrorStats::from_sums(sum_sq, b.data.len().max(1), 0.0).psnr_db
}

/// max |a − b| / max(b), the "normalised footprint" difference used throughout the tests. NaN if
/// either image holds a non-finite value (so no threshold passes it).
pub fn max_rel_diff(a: &GreyImage, b: &GreyImage) -> Result<f64, CliError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CliError::input(format!(
            "images differ in size: {}x{} vs {}x{}",
            a.width, a.height, b.width, b.height
        )));
    }
    if a.data.iter().chain(&b.data).any(|v| !v.is_finite()) {
        return Ok(f64::NAN);
    }
    let peak = f64::from(b.peak());
    if peak <= 0.0 {
        return Err(CliError::input("reference image has no positive value"));
    }
    let worst = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| f64::from(x - y).abs())
        .fold(0.0, f64::max);
    Ok(worst / peak)
}
