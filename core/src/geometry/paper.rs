//! Westover's θ/Sx/Sy decomposition of the footprint conic, as the paper prints it (misprints
//! corrected, see the [module docs](super)), kept so its failure near 45° can be measured.

use super::ellipse::{Mat2, Sym2};
use super::GeometryError;
use crate::math;

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

/// Westover's decomposition of the conic P = [[X, Z/2], [Z/2, Y]] (misprints corrected, see the
/// module docs): P = T Tᵀ with T = R(θ)·diag(Sx, Sy), θ from G = (X − Y)/(Z/2) = w − 1/w,
/// w = cot θ = (G + √(G² + 4))/2, then Sx², Sy² from the 2×2 linear system
/// `[c² s²; s² c²]·[Sx²; Sy²] = [X; Y]` whose determinant cos 2θ vanishes at 45°: the paper's
/// singularity. When |cos 2θ| < [`PAPER_SINGULAR_COS2`] the view is rotated by `cheat_deg` about the
/// view axis (the conic rotated by that angle) and the decomposition retried once, as the paper
/// does; `cheat_deg` = 0 disables that.
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
    let (mut theta, mut sx, mut sy, denom) = attempt(conic);
    let mut cheated = false;
    if math::abs(denom) < PAPER_SINGULAR_COS2 && cheat_deg != 0.0 {
        // Rotating the view by δ about z rotates the ellipse by δ: conic' = R P Rᵀ.
        let d = cheat_deg * (core::f32::consts::PI / 180.0);
        let (s, c) = (math::sin(d), math::cos(d));
        let p = conic;
        let rotated = Sym2 {
            xx: c * c * p.xx - 2.0 * c * s * p.xy + s * s * p.yy,
            xy: c * s * (p.xx - p.yy) + (c * c - s * s) * p.xy,
            yy: s * s * p.xx + 2.0 * c * s * p.xy + c * c * p.yy,
        };
        (theta, sx, sy, _) = attempt(&rotated);
        cheated = true;
    }
    if !(sx > 0.0 && sy > 0.0 && sx.is_finite() && sy.is_finite() && theta.is_finite()) {
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
