//! The two absorption models a layer (a sheet of object slicing, a slab of image slicing) can
//! composite, and the conversions each needs.
//!
//! A pre-classified voxel carries a straight colour c and an opacity α₁ over one world unit of
//! thickness. Reconstructed by the kernel w (lattice weights summing to one) it defines a
//! continuous field, and there are two ways to read it:
//!
//! - [`Absorption::Opacity`] (the default): opacity and premultiplied colour are reconstructed,
//!   α(x) = Σᵥ w(x − v)·α₁ᵥ and C(x) = Σᵥ w(x − v)·α₁ᵥcᵥ, and light crossing a length l of
//!   constant α keeps (1 − α)ˡ. It is the continuous form of what the paper's sheets splat, and it
//!   is well posed for opaque voxels (α₁ = 1: the ray ends there) without any constant.
//! - [`Absorption::Extinction`]: extinction is reconstructed, σ(x) = Σᵥ w(x − v)·σᵥ with
//!   σᵥ = −ln(1 − α₁ᵥ), emission σᵥcᵥ likewise, and light keeps e^(−∫σ). An opaque voxel has no
//!   finite σ: α₁ is capped at [`MAX_UNIT_ALPHA`], and the image moves with the cap.
//!
//! A layer accumulates, per pixel, the integral of the reconstructed quantity along the ray inside
//! it ([A, C] = ∫α, ∫C, or [τ, E] = ∫σ, ∫σc) and is composited as one premultiplied RGBA layer
//! ([`opacity_layer`], [`extinction_layer`]). Only the order inside a layer is approximated (and,
//! for opacity, α by its mean over the layer's chord), so thinner layers converge to the model.

use crate::math;

/// The most opacity per world unit the extinction model takes as is; above it α counts as this
/// (σ ≈ 13.8 per world unit).
pub const MAX_UNIT_ALPHA: f32 = 1.0 - 1e-6;

/// Which continuous field a layer's accumulation stands for (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Absorption {
    /// Opacity and premultiplied colour reconstructed; no cap.
    #[default]
    Opacity,
    /// Extinction and emission reconstructed; opacity capped at [`MAX_UNIT_ALPHA`].
    Extinction,
}

impl Absorption {
    /// The name the command line and the JSON use: `opacity` or `extinction`.
    pub fn name(self) -> &'static str {
        match self {
            Absorption::Opacity => "opacity",
            Absorption::Extinction => "extinction",
        }
    }

    /// What a layer of this model accumulates for a voxel shaded to premultiplied `rgba` (its
    /// opacity over the thickness the caller integrates it for): the same `rgba` (colour and
    /// channels below zero made zero) for opacity; [σc, σ] with σ = −ln(1 − min(α,
    /// [`MAX_UNIT_ALPHA`])) for extinction. `None` for a transparent (or NaN) voxel.
    #[inline]
    pub fn voxel_value(self, rgba: [f32; 4]) -> Option<[f32; 4]> {
        if !(rgba[3] > 0.0) {
            return None;
        }
        let k = match self {
            Absorption::Opacity => 1.0,
            Absorption::Extinction => {
                let a = rgba[3].min(MAX_UNIT_ALPHA);
                -math::ln(1.0 - a) / a
            }
        };
        Some([
            rgba[0].max(0.0) * k,
            rgba[1].max(0.0) * k,
            rgba[2].max(0.0) * k,
            rgba[3] * k,
        ])
    }

    /// One layer's accumulation `acc` as a premultiplied layer, the layer `chord` world units
    /// deep along the ray (only the opacity model uses it).
    #[inline]
    pub fn layer(self, acc: [f32; 4], chord: f32) -> [f32; 4] {
        match self {
            Absorption::Opacity => opacity_layer(acc, chord),
            Absorption::Extinction => extinction_layer(acc),
        }
    }
}

/// An extinction layer's accumulated [E, τ] (E = ∫σc, τ = ∫σ along the ray) as a premultiplied
/// layer: α = 1 − e^(−τ), colour E·α/τ. NaN or negative sums count as zero.
#[inline]
pub fn extinction_layer(acc: [f32; 4]) -> [f32; 4] {
    // max, not clamp: NaN becomes 0.
    let tau = acc[3].max(0.0);
    let (alpha, k) = if tau > 1e-3 {
        let alpha = 1.0 - math::exp(-tau);
        (alpha, alpha / tau)
    } else {
        // Series to τ³: relative error < τ³/24 < 5·10⁻¹¹.
        let k = 1.0 - tau * (0.5 - tau / 6.0);
        (tau * k, k)
    };
    [
        acc[0].max(0.0) * k,
        acc[1].max(0.0) * k,
        acc[2].max(0.0) * k,
        alpha,
    ]
}

/// An opacity layer's accumulated [C, A] (C = ∫α·c, A = ∫α along a chord `chord` world units
/// long) as a premultiplied layer: the mean opacity ᾱ = A/chord held over the chord,
/// α = 1 − (1 − ᾱ)^chord, emitting the mean straight colour C/A. ᾱ ≥ 1 is opaque (no cap), and
/// NaN or negative sums count as zero; a chord that is not positive makes the layer transparent.
#[inline]
pub fn opacity_layer(acc: [f32; 4], chord: f32) -> [f32; 4] {
    let a = acc[3];
    if !(a > 0.0 && chord > 0.0) {
        return [0.0; 4];
    }
    let mean = a / chord;
    if mean >= 1.0 {
        let k = 1.0 / a;
        return [
            acc[0].max(0.0) * k,
            acc[1].max(0.0) * k,
            acc[2].max(0.0) * k,
            1.0,
        ];
    }
    // The layer's optical depth τ = −chord·ln(1 − ᾱ) = A·(−ln(1 − ᾱ)/ᾱ), by its series where ᾱ
    // is small (to ᾱ³: relative error < ᾱ³/4 < 2.5·10⁻¹⁰), so a faint layer keeps its bits.
    let per = if mean < 1e-3 {
        1.0 + mean * (0.5 + mean / 3.0)
    } else {
        -math::ln(1.0 - mean) / mean
    };
    // E = C·τ/A and τ: the extinction layer of the same depth.
    extinction_layer([acc[0] * per, acc[1] * per, acc[2] * per, a * per])
}
