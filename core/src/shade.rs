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
use glam::Vec3;

/// Value → straight RGBA lookup table over the window [lo, hi]; finite values outside clamp to the
/// ends. Entries are linearly interpolated. `lut` may have any length ≥ 2.
///
/// Non-finite samples (NaN, ±∞) are *missing data*: they classify as transparent, so they cost
/// nothing and never paint a pixel. (Clamping +∞ to the top of the window would show missing data
/// as the densest material.)
#[derive(Clone, Copy, Debug)]
pub struct TransferFunction<'a> {
    /// Straight RGBA entries, evenly spaced from `lo` to `hi`; each channel in [0, 1].
    pub lut: &'a [[f32; 4]],
    /// Value mapped to the first entry.
    pub lo: f32,
    /// Value mapped to the last entry (> lo).
    pub hi: f32,
}

impl TransferFunction<'_> {
    /// Straight RGBA for `value`; transparent for a non-finite value.
    #[inline]
    pub fn lookup(&self, value: f32) -> [f32; 4] {
        if !value.is_finite() {
            return [0.0; 4];
        }
        let n = self.lut.len();
        let t = (value - self.lo) / (self.hi - self.lo) * (n - 1) as f32;
        if !t.is_finite() {
            return [0.0; 4];
        }
        let t = t.clamp(0.0, (n - 1) as f32);
        let i = (t as usize).min(n - 2);
        let f = t - i as f32;
        let (a, b) = (self.lut[i], self.lut[i + 1]);
        [
            a[0] + f * (b[0] - a[0]),
            a[1] + f * (b[1] - a[1]),
            a[2] + f * (b[2] - a[2]),
            a[3] + f * (b[3] - a[3]),
        ]
    }
}

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

/// A transfer function with a shading mode.
#[derive(Clone, Copy, Debug)]
pub struct Shader<'a> {
    /// Classification.
    pub tf: TransferFunction<'a>,
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
}

impl Shader<'_> {
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
        let (rgb, alpha, phong, g) = match self.shading {
            Shading::Emission => {
                let c = self.tf.lookup(value);
                ([c[0], c[1], c[2]], c[3], None, Vec3::ZERO)
            }
            Shading::Phong(p) => {
                let c = self.tf.lookup(value);
                if !(c[3] > 0.0) {
                    return [0.0; 4];
                }
                ([c[0], c[1], c[2]], c[3], Some(p), gradient())
            }
            Shading::Texture(p) => {
                let c = self.tf.lookup(value);
                if !(c[3] > 0.0) {
                    return [0.0; 4];
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
                let c = self.tf.lookup(iso);
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
            return [0.0; 4];
        }
        let alpha = alpha.min(1.0);
        let mut light = 1.0;
        let mut spec = 0.0;
        if let Some(p) = phong {
            let mag = g.length();
            if mag > 0.0 {
                let n = g / mag;
                let ndl = math::abs(n.dot(lighting.light));
                let ndh = math::abs(n.dot(lighting.half));
                light = p.ambient + p.diffuse * ndl;
                spec = p.specular * math::powf(ndh, p.shininess);
            } else {
                // No gradient (a homogeneous region): lit as if facing the light.
                light = p.ambient + p.diffuse;
                spec = 0.0;
            }
        }
        let corrected = if lighting.opacity_exponent == 1.0 {
            alpha
        } else {
            1.0 - math::powf(1.0 - alpha, lighting.opacity_exponent)
        };
        let shade = |c: f32| ((c * light + spec).min(1.0)) * corrected;
        [shade(rgb[0]), shade(rgb[1]), shade(rgb[2]), corrected]
    }
}

/// A voxel sample type the renderer reads: anything the harness loads, converted to f32.
pub trait Sample: Copy {
    /// The sample as f32 (NaN for a missing value is allowed: it classifies as transparent).
    fn to_f32(self) -> f32;
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
