//! Shading: turning a voxel's sample into premultiplied RGBA before it is splatted (the paper
//! shades samples, then reconstructs).
//!
//! Every mode starts from a [`TransferFunction`]: a caller-supplied lookup table of straight
//! (non-premultiplied) RGBA over a value window. Its opacity α is the opacity of a slab one
//! *reference distance* thick (one world unit); the renderer corrects it for the
//! actual distance between sheets along the view ray, α' = 1 − (1 − α)^(Δ/d_ref), so the picture
//! does not change when only the sampling along the view changes. Colour is emission–absorption:
//! premultiplied colour = colour × α'.

use crate::frame::FrameSetup;
use crate::math;
use crate::splat::BufferError;
use glam::Vec3;

mod labels;
pub mod presets;
mod transfer;

pub use labels::{Label, Labels};
pub use presets::{Preset, LUT_SIZE};
pub use transfer::{TransferFunction, TransferFunctionError, RAMP_MIN_OPACITY};

/// Phong lighting coefficients (a head-light at the viewer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Ambient term.
    pub ambient: f32,
    /// Diffuse term (two-sided: |n·l|).
    pub diffuse: f32,
    /// Specular term.
    pub specular: f32,
    /// Specular exponent.
    pub shininess: f32,
}

impl Default for Phong {
    fn default() -> Self {
        Phong {
            ambient: 0.25,
            diffuse: 0.65,
            specular: 0.3,
            shininess: 24.0,
        }
    }
}

/// How samples are shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// Transfer-function colour and opacity, no lighting.
    Emission,
    /// Transfer function, lit by Phong with gradient normals (central differences that honour the
    /// grid spacing).
    Phong(Phong),
    /// Levoy's iso-surface opacity around `value` (1988): α = α_v (1 − |f_v − f| / (r |∇f|)) where
    /// that is positive, with α_v = `opacity` and r = `thickness` (world units); colour from the
    /// transfer function at `value`, Phong-lit. (The transfer function's opacity is not used.)
    Iso {
        /// The iso-value f_v.
        value: f32,
        /// Peak opacity α_v, in (0, 1].
        opacity: f32,
        /// Surface thickness r, world units.
        thickness: f32,
        /// Lighting.
        phong: Phong,
    },
    /// The paper's Image 11: the grid coordinates as 3D texture indices (colour = (i, j, k)
    /// normalised to [0, 1]), transfer-function opacity, Phong-lit.
    Texture(Phong),
}

impl Shading {
    /// Whether this mode needs the gradient (and so the neighbouring sheets).
    pub fn needs_gradient(&self) -> bool {
        !matches!(self, Shading::Emission)
    }
}

/// A classification (a transfer function, or a label table) with a shading mode.
#[derive(Clone, Copy, Debug)]
pub struct Shader<'a> {
    /// Classification by value (unused where `labels` is given).
    pub tf: TransferFunction<'a>,
    /// Classification by label ([`Labels`]): each sample's exact value looked up in the table
    /// instead of the transfer function. `None` for a volume of measurements.
    pub labels: Option<Labels<'a>>,
    /// Lighting and opacity mode.
    pub shading: Shading,
}

/// Per-frame shading state: the head-light (toward the viewer, so the half vector equals it) in
/// world space, and the opacity-correction exponent Δ/d_ref.
#[derive(Clone, Copy, Debug)]
pub struct Lighting {
    light: Vec3,
    half: Vec3,
    opacity_exponent: f32,
}

impl Lighting {
    /// The lighting of `frame`.
    pub fn new(frame: &FrameSetup) -> Self {
        let l = frame.to_viewer_world;
        Lighting {
            light: l,
            half: l,
            opacity_exponent: frame.sheet_distance / frame.reference_distance,
        }
    }

    /// The lighting of `frame` with opacity per world unit (an exponent of one, no correction to
    /// the sheet distance): what image slabs and the continuous reference integrate along a ray.
    pub fn per_world_unit(frame: &FrameSetup) -> Self {
        Lighting {
            opacity_exponent: 1.0,
            ..Lighting::new(frame)
        }
    }

    /// The same light with the opacity correction α' = 1 − (1 − α)^`exponent` (a layer
    /// `exponent` reference distances deep; one: no correction).
    pub fn with_opacity_exponent(self, exponent: f32) -> Self {
        Lighting {
            opacity_exponent: exponent,
            ..self
        }
    }
}

impl<'a> Shader<'a> {
    /// A shader of `tf` under `shading`, classifying by value.
    pub fn new(tf: TransferFunction<'a>, shading: Shading) -> Self {
        Shader {
            tf,
            labels: None,
            shading,
        }
    }

    /// A shader classifying a label volume by `labels`, unlit ([`Shading::Emission`]): the
    /// picture holds the labels' colours and their composites only (see [`Labels`]).
    pub fn labelled(labels: Labels<'a>) -> Self {
        Shader {
            tf: TransferFunction {
                lut: &labels::CLEAR,
                lo: 0.0,
                hi: 1.0,
            },
            labels: Some(labels),
            shading: Shading::Emission,
        }
    }
}

impl Shader<'_> {
    /// Checks that the classification can classify: the transfer function, and the label table
    /// where there is one.
    pub fn check(&self) -> Result<(), TransferFunctionError> {
        self.tf.check()?;
        match self.labels {
            Some(l) => l.check(),
            None => Ok(()),
        }
    }

    /// Straight RGBA the classification gives `value`: its label's, or the transfer function's.
    #[inline]
    pub fn lookup(&self, value: f32) -> [f32; 4] {
        match &self.labels {
            Some(l) => l.lookup(value),
            None => self.tf.lookup(value),
        }
    }

    /// The premultiplied RGBA of a pixel shown as `value` alone (a projection's pixel): the
    /// classification's colour times its opacity, as [`TransferFunction::pixel`] gives it.
    #[inline]
    pub fn pixel(&self, value: f32) -> [f32; 4] {
        transfer::premultiplied(self.lookup(value))
    }

    /// Premultiplied RGBA for one voxel, opacity-corrected. `value` is the sample; `gradient` is
    /// called only when the mode needs it and the voxel is not already transparent, and returns the
    /// world-space gradient (value units per world unit); `index` is the voxel's grid index and
    /// `dims` the volume's dimensions (for texture colouring). A result with α = 0 is skipped.
    #[inline]
    pub fn shade(
        &self,
        lighting: &Lighting,
        value: f32,
        gradient: impl FnOnce() -> Vec3,
        index: [usize; 3],
        dims: [usize; 3],
    ) -> [f32; 4] {
        self.shade_with(lighting, None, value, gradient, index, dims)
    }

    /// [`Shader::shade`] with the opacity correction read from `table` (built for this frame)
    /// instead of computed with a power per voxel; `None` computes it exactly.
    pub fn shade_with(
        &self,
        lighting: &Lighting,
        table: Option<&OpacityTable<'_>>,
        value: f32,
        gradient: impl FnOnce() -> Vec3,
        index: [usize; 3],
        dims: [usize; 3],
    ) -> [f32; 4] {
        self.shade_coloured(lighting, table, value, None, gradient, index, dims)
    }

    /// [`Shader::shade_with`] for a sample that may carry its own straight colour (see
    /// [`Sample::colour`]): emission and Phong use `colour`, when given, instead of the transfer
    /// function's colour at `value` (the opacity still comes from `value`); iso-surfaces and the
    /// texture colour as always.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn shade_coloured(
        &self,
        lighting: &Lighting,
        table: Option<&OpacityTable<'_>>,
        value: f32,
        colour: Option<[f32; 3]>,
        gradient: impl FnOnce() -> Vec3,
        index: [usize; 3],
        dims: [usize; 3],
    ) -> [f32; 4] {
        let Some((mut rgb, alpha, phong, g)) = self.classify(value, gradient, index, dims) else {
            return [0.0; 4];
        };
        let mut light = 1.0;
        let mut spec = 0.0;
        if let Some(p) = phong {
            let mag = g.length();
            if mag > 0.0 {
                let n = g / mag;
                let ndl = math::abs(n.dot(lighting.light));
                let ndh = math::abs(n.dot(lighting.half));
                light = p.ambient + p.diffuse * ndl;
                spec = p.specular * math::powi_or_powf(ndh, p.shininess);
            } else {
                // No gradient (a homogeneous region): lit as if facing the light.
                light = p.ambient + p.diffuse;
                spec = 0.0;
            }
        }
        if let (Some(c), Shading::Emission | Shading::Phong(_)) = (colour, self.shading) {
            rgb = c;
        }
        let corrected = match table {
            Some(t) => t.correct(alpha),
            None => correct_opacity(alpha, lighting.opacity_exponent),
        };
        let shade = |c: f32| ((c * light + spec).min(1.0)) * corrected;
        [shade(rgb[0]), shade(rgb[1]), shade(rgb[2]), corrected]
    }

    /// The values a voxel is [`visible`](Shader::visible) at, whatever its gradient or position,
    /// when they are exactly one interval: the transfer function's
    /// [`visible_interval`](TransferFunction::visible_interval) where the shading takes opacity
    /// from it (emission, Phong, texture), `None` for an iso-surface. A bisection of about 96
    /// lookups: call it once per sheet or frame, not per voxel.
    pub fn visible_interval(&self) -> Option<(f32, f32)> {
        match self.shading {
            // Values between labels are transparent: not one interval.
            _ if self.labels.is_some() => None,
            Shading::Emission | Shading::Phong(_) | Shading::Texture(_) => {
                self.tf.visible_interval()
            }
            Shading::Iso { .. } => None,
        }
    }

    /// A value at or below which no voxel is [`visible`](Shader::visible), whatever its
    /// gradient or position: the transfer function's
    /// [`transparent_at_or_below`](TransferFunction::transparent_at_or_below) where the shading
    /// takes opacity from it (emission, Phong, texture), −∞ for an iso-surface (whose opacity
    /// depends on the distance to the iso-value instead). Computed by a bisection of about 64
    /// lookups: call it once per sheet or frame, not per voxel.
    pub fn transparent_at_or_below(&self) -> f32 {
        match self.shading {
            Shading::Emission | Shading::Phong(_) | Shading::Texture(_) => match &self.labels {
                Some(l) => l.transparent_at_or_below(),
                None => self.tf.transparent_at_or_below(),
            },
            Shading::Iso { .. } => f32::NEG_INFINITY,
        }
    }

    /// Whether a voxel of `value` can be seen at all (opacity above zero before the per-view
    /// correction), whatever the view: what [`crate::render::classify_sheet`] keeps.
    #[inline]
    pub fn visible(&self, value: f32, gradient: impl FnOnce() -> Vec3) -> bool {
        self.classify(value, gradient, [0; 3], [1; 3]).is_some()
    }

    /// The view-independent half of shading: straight colour, opacity in (0, 1], the lighting to
    /// apply and the gradient; `None` for a transparent voxel.
    #[inline]
    #[allow(clippy::type_complexity)]
    fn classify(
        &self,
        value: f32,
        gradient: impl FnOnce() -> Vec3,
        index: [usize; 3],
        dims: [usize; 3],
    ) -> Option<([f32; 3], f32, Option<Phong>, Vec3)> {
        let (rgb, alpha, phong, g) = match self.shading {
            Shading::Emission => {
                let c = self.lookup(value);
                ([c[0], c[1], c[2]], c[3], None, Vec3::ZERO)
            }
            Shading::Phong(p) => {
                let c = self.lookup(value);
                if !(c[3] > 0.0) {
                    return None;
                }
                ([c[0], c[1], c[2]], c[3], Some(p), gradient())
            }
            Shading::Texture(p) => {
                let c = self.lookup(value);
                if !(c[3] > 0.0) {
                    return None;
                }
                let t = |i: usize| {
                    if dims[i] > 1 {
                        index[i] as f32 / (dims[i] - 1) as f32
                    } else {
                        0.5
                    }
                };
                ([t(0), t(1), t(2)], c[3], Some(p), gradient())
            }
            Shading::Iso {
                value: iso,
                opacity,
                thickness,
                phong,
            } => {
                let c = self.lookup(iso);
                let g = gradient();
                let mag = g.length();
                let alpha = if mag > 0.0 {
                    opacity * (1.0 - math::abs(iso - value) / (thickness * mag))
                } else if value == iso {
                    opacity
                } else {
                    0.0
                };
                ([c[0], c[1], c[2]], alpha, Some(phong), g)
            }
        };
        if !(alpha > 0.0) {
            return None;
        }
        Some((rgb, alpha.min(1.0), phong, g))
    }
}

/// A voxel sample type the renderer reads: anything the harness loads, converted to f32.
pub trait Sample: Copy {
    /// Whether samples of this type may carry a colour ([`Sample::colour`]).
    const COLOURED: bool = false;

    /// The sample as f32 (NaN for a missing value is allowed: it classifies as transparent).
    fn to_f32(self) -> f32;

    /// A straight colour (each channel in [0, 1]) the sample carries, to be used instead of the
    /// transfer function's colour at its value by emission and Phong shading: what a pre-filtered
    /// level of detail carries (`crate::lod::Coloured`). `None`, the default, for plain data.
    #[inline]
    fn colour(self) -> Option<[f32; 3]> {
        None
    }
}

macro_rules! sample_as_f32 {
    ($($t:ty),*) => {$(
        impl Sample for $t {
            #[inline]
            fn to_f32(self) -> f32 {
                self as f32
            }
        }
    )*};
}
sample_as_f32!(u8, i8, u16, i16, u32, i32, f32, f64);

/// α' = 1 − (1 − α)^e, exactly (one power).
#[inline]
fn correct_opacity(alpha: f32, exponent: f32) -> f32 {
    if exponent == 1.0 {
        alpha
    } else {
        1.0 - math::powf(1.0 - alpha, exponent)
    }
}

/// Entries of the opacity table the harness uses (any length ≥ 2 works).
pub const OPACITY_TABLE_LEN: usize = 4097;

/// Above this α the table hands over to the exact power: for exponents below one the correction
/// has unbounded curvature as α → 1, which linear interpolation cannot follow.
const OPACITY_TABLE_TOP: f32 = 63.0 / 64.0;

/// One frame's opacity correction α' = 1 − (1 − α)^e (e = distance between sheets along a ray ÷
/// the reference distance) tabulated at `len` evenly spaced α in [0, 63/64] and interpolated
/// linearly, so a voxel costs a lookup instead of a power; α above 63/64 (rare: nearly opaque
/// material) is computed exactly. Interpolation error, with 1 − α ≥ 1/64 and h = (63/64)/(len − 1):
/// at most h²/8 · max|C''| = h²/8 · e|e − 1| · 64^max(0, 2 − e); for `len` = 4097 that is below
/// 1.8·10⁻⁶ (plus f32 rounding; tested below 3·10⁻⁶) for every e in [0.1, 10], far under the
/// 8-bit step. The entries themselves carry the math backend's power error (libm: a few ulp;
/// micromath: its stated bound, `ERROR_BOUNDS.powf_unit_abs`), as the exact path would.
#[derive(Clone, Copy, Debug)]
pub struct OpacityTable<'a> {
    entries: &'a [f32],
    exponent: f32,
}

impl<'a> OpacityTable<'a> {
    /// Fills `buffer` (at least 2 entries; [`OPACITY_TABLE_LEN`] recommended) for `lighting`'s
    /// frame.
    pub fn build(lighting: &Lighting, buffer: &'a mut [f32]) -> Result<Self, BufferError> {
        let n = buffer.len();
        if n < 2 {
            return Err(BufferError::TooSmall { needed: 2, got: n });
        }
        let e = lighting.opacity_exponent;
        for (i, v) in buffer.iter_mut().enumerate() {
            *v = correct_opacity(OPACITY_TABLE_TOP * i as f32 / (n - 1) as f32, e);
        }
        Ok(OpacityTable {
            entries: buffer,
            exponent: e,
        })
    }

    /// α' for `alpha` in [0, 1].
    #[inline]
    pub fn correct(&self, alpha: f32) -> f32 {
        if self.exponent == 1.0 {
            return alpha;
        }
        if !(alpha <= OPACITY_TABLE_TOP) {
            return correct_opacity(alpha, self.exponent);
        }
        let n = self.entries.len();
        let t = alpha * ((n - 1) as f32 / OPACITY_TABLE_TOP);
        let i = (t as usize).min(n - 2);
        let f = t - i as f32;
        let (a, b) = (self.entries[i], self.entries[i + 1]);
        a + f * (b - a)
    }
}

#[cfg(test)]
mod opacity_table_tests {
    use super::*;

    #[test]
    fn table_matches_the_exact_power() {
        let mut buf = [0.0f32; OPACITY_TABLE_LEN];
        for e in [0.1f32, 0.3, 0.5, 0.9, 1.0, 1.5, 2.0, 3.7, 10.0] {
            let lighting = Lighting {
                light: Vec3::Z,
                half: Vec3::Z,
                opacity_exponent: e,
            };
            let t = OpacityTable::build(&lighting, &mut buf).unwrap();
            let mut worst = 0.0f64;
            for k in 0..=200_000u32 {
                let a = k as f32 / 200_000.0;
                let exact = 1.0 - (1.0 - f64::from(a)).powf(f64::from(e));
                worst = worst.max((f64::from(t.correct(a)) - exact).abs());
            }
            // The interpolation's own bound, plus the error the math backend's power brings into
            // the table's entries (a few ulp with libm; micromath's stated bound otherwise).
            let bound = 3e-6 + f64::from(crate::math::ERROR_BOUNDS.powf_unit_abs);
            assert!(worst < bound, "exponent {e}: worst error {worst:.2e}");
            assert_eq!(t.correct(0.0), 0.0, "transparent stays transparent");
        }
    }
}
