//! Westover's θ/Sx/Sy decomposition of the footprint conic, as the paper prints it (misprints
//! corrected, see the [module docs](super)), kept so its failure near 45° can be measured.

use super::mat2::{Mat2, Sym2};
use super::GeometryError;
use crate::math::{self, sq};

/// The result of [`paper_decomposition`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperDecomposition {
    /// Rotation of the ellipse's first axis, radians.
    pub theta: f32,
    /// Sx and Sy of the paper (the scales of T along its axes), px⁻¹.
    pub scales: [f32; 2],
    /// The map Tᵀ from screen offsets to unit coordinates (T Tᵀ = conic).
    pub to_unit: Mat2,
    /// Whether the 45° rotation cheat was applied.
    pub cheated: bool,
}

/// |cos 2θ| below this is "θ = 45°" for the paper's cheat: f32 evaluates cos²θ − sin²θ with an
/// absolute error of about 6e-8, so below 1e-6 the denominator is mostly rounding noise.
pub const PAPER_SINGULAR_COS2: f32 = 1e-6;

/// A conic whose anisotropy (√((X − Y)² + Z²) / (X + Y), that is (a − b)/(a + b) for squared
/// semi-axis scales a, b) is below this is decomposed as a circle when the paper's formulas fail
/// on it ([`paper_decomposition`]): its semi-axes then differ by less than 0.1 %.
pub const PAPER_ROUND_CONIC: f32 = 1e-3;

/// The largest rotation (degrees) the paper's cheat escalates to ([`paper_decomposition`]).
pub const PAPER_MAX_CHEAT_DEG: f32 = 30.0;

/// The conic rotated by `deg` about the view axis: R P Rᵀ.
fn rotate_conic(p: &Sym2, deg: f32) -> Sym2 {
    let d = deg * (core::f32::consts::PI / 180.0);
    let (s, c) = (math::sin(d), math::cos(d));
    Sym2 {
        xx: c * c * p.xx - 2.0 * c * s * p.xy + s * s * p.yy,
        xy: c * s * (p.xx - p.yy) + (c * c - s * s) * p.xy,
        yy: s * s * p.xx + 2.0 * c * s * p.xy + c * c * p.yy,
    }
}

/// Westover's decomposition of the conic P = [[X, Z/2], [Z/2, Y]] (misprints corrected, see the
/// module docs): P = T Tᵀ with T = R(θ)·diag(Sx, Sy), θ from G = (X − Y)/(Z/2) = w − 1/w,
/// w = cot θ = (G + √(G² + 4))/2, then Sx², Sy² from the 2×2 linear system
/// `[c² s²; s² c²]·[Sx²; Sy²] = [X; Y]` whose determinant cos 2θ vanishes at 45°: the paper's
/// singularity. When |cos 2θ| < [`PAPER_SINGULAR_COS2`] the view is rotated by `cheat_deg` about the
/// view axis (the conic rotated by that angle) and the decomposition retried once, as the paper
/// does; `cheat_deg` = 0 disables that.
///
/// Rotating a circle changes nothing, so for a conic that is a circle to working precision
/// (|X − Y| and |Z| below [`PAPER_ROUND_CONIC`] of X + Y: any isotropic grid seen along any
/// direction, at any roll) the retry meets the same singularity, with θ made of rounding noise.
/// Such a conic is decomposed as the circle it is: every θ serves, so θ is kept (nudged by the
/// cheat) and Sx = Sy = √((X + Y)/2), the conic's mean radius; `cheated` is set. That is the cheat
/// carried to the one case where rotating cannot help; an error is left only for a conic that is
/// not a positive ellipse.
///
/// Its f32 cancellation widens the singularity with the ellipse's anisotropy k: Sx² − Sy² is
/// found to about 2⁻²³·(X + Y)/|cos 2θ|, so a 100:1 ellipse fails (Sx² ≤ 0) within 0.01° of 45°,
/// where |cos 2θ| is not below [`PAPER_SINGULAR_COS2`]. The cheat is therefore applied wherever the
/// decomposition fails, not only where cos 2θ vanishes: the view is rotated by `cheat_deg`, then
/// (while the decomposition still fails) by twice as much, either way, up to
/// [`PAPER_MAX_CHEAT_DEG`]. What the cheat costs is charted (`footprint chart`, stability).
///
/// Computed in f32 exactly as written, including its cancellations; use the robust map for
/// rendering.
pub fn paper_decomposition(
    conic: &Sym2,
    cheat_deg: f32,
) -> Result<PaperDecomposition, GeometryError> {
    let attempt = |p: &Sym2| -> (f32, f32, f32, f32) {
        if p.xy == 0.0 {
            return (0.0, math::sqrt(p.xx), math::sqrt(p.yy), 1.0);
        }
        let g = (p.xx - p.yy) / p.xy;
        let w = 0.5 * (g + math::sqrt(g * g + 4.0));
        let theta = math::atan(1.0 / w);
        let (s, c) = (math::sin(theta), math::cos(theta));
        let denom = c * c - s * s;
        let sx2 = (p.xx * c * c - p.yy * s * s) / denom;
        let sy2 = (p.yy * c * c - p.xx * s * s) / denom;
        (theta, math::sqrt(sx2), math::sqrt(sy2), denom)
    };
    let valid = |sx: f32, sy: f32, theta: f32| {
        sx > 0.0 && sy > 0.0 && sx.is_finite() && sy.is_finite() && theta.is_finite()
    };
    let (mut theta, mut sx, mut sy, denom) = attempt(conic);
    let mut cheated = false;
    let singular = !(math::abs(denom) >= PAPER_SINGULAR_COS2) || !valid(sx, sy, theta);
    if singular && cheat_deg != 0.0 {
        cheated = true;
        let trace = conic.xx + conic.yy;
        let anisotropy = math::sqrt(sq(conic.xx - conic.yy) + sq(2.0 * conic.xy)) / trace;
        if trace > 0.0 && anisotropy < PAPER_ROUND_CONIC {
            // A circle to working precision: every θ serves (see above).
            let s = math::sqrt(0.5 * trace);
            let nudged = if theta.is_finite() {
                theta + cheat_deg * (core::f32::consts::PI / 180.0)
            } else {
                0.0
            };
            (theta, sx, sy) = (nudged, s, s);
        } else {
            let mut nudge = cheat_deg;
            'retry: while math::abs(nudge) <= PAPER_MAX_CHEAT_DEG {
                for d in [nudge, -nudge] {
                    let (t, x, y, den) = attempt(&rotate_conic(conic, d));
                    if math::abs(den) >= PAPER_SINGULAR_COS2 && valid(x, y, t) {
                        (theta, sx, sy) = (t, x, y);
                        break 'retry;
                    }
                }
                nudge *= 2.0;
            }
        }
    }
    if !valid(sx, sy, theta) {
        return Err(GeometryError::PaperSingular {
            theta_deg: theta * (180.0 / core::f32::consts::PI),
        });
    }
    let (s, c) = (math::sin(theta), math::cos(theta));
    // Tᵀ = diag(Sx, Sy)·R(θ)ᵀ.
    let to_unit = [[sx * c, sx * s], [-sy * s, sy * c]];
    Ok(PaperDecomposition {
        theta,
        scales: [sx, sy],
        to_unit,
        cheated,
    })
}
