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

/// Nodes of [`OpacityLayers`]' table over the mean opacity.
pub const OPACITY_LAYER_NODES: usize = 2048;

/// The longest chord (world units) [`OpacityLayers`] tabulates.
pub const OPACITY_LAYER_MAX_CHORD: f32 = 16.0;

/// Mean opacities at or above this are composited by [`opacity_layer`] itself (the table's
/// function has a cusp at ᾱ = 1 for chords shorter than one world unit).
pub const OPACITY_LAYER_TABLE_MAX: f32 = 0.96875;

/// [`opacity_layer`] for one chord, tabulated: a layer's opacity is A·h(ᾱ) and its colour C·h(ᾱ)
/// with h(ᾱ) = (1 − (1 − ᾱ)^L)/(ᾱ·L) (L the chord, world units; h(0) = 1), smooth on
/// [0, [`OPACITY_LAYER_TABLE_MAX`]), so a slab pixel costs a table read and a lerp instead of a
/// logarithm and an exponential. The table holds [`OPACITY_LAYER_NODES`] + 1 nodes of h computed
/// by [`opacity_layer`]; mean opacities past the table, NaN and non-positive sums take
/// [`opacity_layer`]. Linear interpolation errs by at most Δ²/8 · max|h″| (Δ the node step), and
/// h″ grows as L²: for chords of 1/8 to [`OPACITY_LAYER_MAX_CHORD`] world units and every mean
/// opacity, the composited colour and opacity move by less than 10⁻⁵ (tested against
/// [`opacity_layer`]); longer chords are not tabulated.
#[derive(Clone, Debug)]
pub struct OpacityLayers {
    chord: f32,
    h: [f32; OPACITY_LAYER_NODES + 1],
}

impl OpacityLayers {
    /// The table for layers `chord` world units deep (positive and at most
    /// [`OPACITY_LAYER_MAX_CHORD`], else every layer takes [`opacity_layer`]).
    pub fn new(chord: f32) -> Self {
        let mut h = [1.0f32; OPACITY_LAYER_NODES + 1];
        if Self::tabulates(chord) {
            for (i, h) in h.iter_mut().enumerate().skip(1) {
                let a = OPACITY_LAYER_TABLE_MAX * i as f32 / OPACITY_LAYER_NODES as f32 * chord;
                *h = opacity_layer([0.0, 0.0, 0.0, a], chord)[3] / a;
            }
        }
        OpacityLayers { chord, h }
    }

    fn tabulates(chord: f32) -> bool {
        chord > 0.0 && chord <= OPACITY_LAYER_MAX_CHORD
    }

    /// The chord the table is for, world units.
    pub fn chord(&self) -> f32 {
        self.chord
    }

    /// [`opacity_layer`]`(acc, self.chord())`, from the table where the mean opacity lies in it.
    #[inline]
    pub fn layer(&self, acc: [f32; 4]) -> [f32; 4] {
        let (a, chord) = (acc[3], self.chord);
        let mean = a / chord;
        if !(a > 0.0 && Self::tabulates(chord) && mean < OPACITY_LAYER_TABLE_MAX) {
            return opacity_layer(acc, chord);
        }
        let x = mean * (OPACITY_LAYER_NODES as f32 / OPACITY_LAYER_TABLE_MAX);
        let i = (x as usize).min(OPACITY_LAYER_NODES - 1);
        let k = self.h[i] + (x - i as f32) * (self.h[i + 1] - self.h[i]);
        [
            acc[0].max(0.0) * k,
            acc[1].max(0.0) * k,
            acc[2].max(0.0) * k,
            a * k,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::{opacity_layer, OpacityLayers};

    /// The table against the layer computed in f64, beside [`opacity_layer`] itself: chords from
    /// 1/8 to 64 world units, mean opacities over [0, 1.01] (past the table and past opaque too).
    /// The table errs by at most 10⁻⁵ more than the exact layer does in the build's math backend
    /// (libm: both within about 10⁻⁶; micromath's logarithm and exponential err more, and the
    /// table, built by [`opacity_layer`], inherits that, not more).
    #[test]
    fn tabulated_layers_match_the_exact_ones() {
        for chord in [0.125f32, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.3, 8.0, 16.0, 64.0] {
            let t = OpacityLayers::new(chord);
            let (mut table, mut exact) = (0.0f64, 0.0f64);
            for i in 0..=20_200 {
                let mean = i as f32 / 20_000.0;
                let a = mean * chord;
                let acc = [0.3 * a, 0.7 * a, a, a];
                let (m, l) = (f64::from(a) / f64::from(chord), f64::from(chord));
                let alpha = if m >= 1.0 {
                    1.0
                } else {
                    1.0 - (1.0 - m).powf(l)
                };
                let k = if a > 0.0 { alpha / f64::from(a) } else { 0.0 };
                let truth = acc.map(|c| f64::from(c) * k);
                let err = |got: [f32; 4]| {
                    got.iter()
                        .zip(&truth)
                        .map(|(g, w)| (f64::from(*g) - w).abs())
                        .fold(0.0, f64::max)
                };
                table = table.max(err(t.layer(acc)));
                exact = exact.max(err(opacity_layer(acc, chord)));
            }
            assert!(
                table < exact + 1e-5,
                "chord {chord}: table {table:.3e}, exact layer {exact:.3e}"
            );
        }
        // The table is read (not the exact layer with other bits) where it applies.
        let t = OpacityLayers::new(3.3);
        let differ = (1..1000)
            .map(|i| [0.2, 0.3, 0.4, i as f32 * 3.2e-3])
            .filter(|&acc| t.layer(acc) != opacity_layer(acc, 3.3))
            .count();
        assert!(differ > 100, "{differ} of 999 layers read from the table");
        // NaN and negative sums as the exact layer has them.
        let t = OpacityLayers::new(2.0);
        assert_eq!(t.layer([1.0, 1.0, 1.0, f32::NAN]), [0.0; 4]);
        assert_eq!(t.layer([1.0, 1.0, 1.0, -0.5]), [0.0; 4]);
    }
}
