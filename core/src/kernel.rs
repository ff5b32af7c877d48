//! Reconstruction kernels and the generic footprint they define.
//!
//! # Coordinates
//! A kernel lives in *unit coordinates* `u`: a grid-index offset divided by the kernel's support
//! radius `R = spread` (in voxel spacings, the same in each grid direction). The kernel's region is
//! the unit ball |u| ≤ 1 (the paper's *unit region sphere*); its footprint, the integral along the
//! view direction, lives on the unit disc |u| ≤ 1 (or, for the separable bilinear model, the square
//! [−1,1]²).
//!
//! # Families
//! - [`Kernel::Gaussian`]: a 3D radial kernel h(r) = exp(−r²/2σ²), truncated at r = 1, with
//!   σ = 1/`sigmas` in unit coordinates (`sigmas` standard deviations fit in the radius). Its
//!   footprint is the exact line integral through the ball, in closed form with erf:
//!   F(ρ) = e^(−ρ²/2σ²) · σ√(2π) · erf(√(1−ρ²) / (σ√2)) for ρ = |u| < 1.
//! - 2D footprint models (the paper's Image 3), defined directly on the disc or square:
//!   [`Kernel::Cone`] F = 1 − ρ; [`Kernel::Sinc`] F = sinc(Lρ) = sin(πLρ)/(πLρ) with L lobes;
//!   [`Kernel::Bilinear`] F = (1 − |u₀|)(1 − |u₁|), separable and oriented along the sheet's grid
//!   axes (not radial).
//!
//! # Normalisation
//! [`Kernel::integral`] is ∫∫ F(u) d²u over the footprint's domain, in closed form. The generic table
//! stores F / integral, so the footprint integrates to exactly one over its domain; see
//! [`crate::table`] for what that means for a flat field.

use crate::math;
use core::f32::consts::PI;
use core::fmt;

/// Longest kernel spec, in bytes, that [`Kernel::parse`] accepts and [`Kernel::write_spec`] writes.
pub const MAX_SPEC_LEN: usize = 64;

/// A reconstruction kernel or footprint model. Construct with [`Kernel::parse`] or the
/// constructors, which validate the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kernel {
    /// 3D Gaussian, truncated at the support radius. `spread` = support radius in voxel spacings
    /// (the paper's 160 % is 1.6); `sigmas` = standard deviations that fit in that radius (2.5).
    Gaussian {
        /// Support radius, voxel spacings.
        spread: f32,
        /// Standard deviations per support radius.
        sigmas: f32,
    },
    /// 2D cone model F = 1 − ρ on the unit disc.
    Cone {
        /// Support radius, voxel spacings.
        spread: f32,
    },
    /// 2D radial sinc model with `lobes` lobes inside the support (zeros at ρ = k/lobes).
    Sinc {
        /// Support radius, voxel spacings.
        spread: f32,
        /// Number of lobes inside the radius; odd (even counts integrate to zero).
        lobes: u8,
    },
    /// 2D separable bilinear (tent × tent) model on the square, aligned with the sheet's grid axes.
    Bilinear {
        /// Half-width of the tent, voxel spacings.
        spread: f32,
    },
}

/// Whether a footprint is radial (depends on |u| only) or separable along the sheet's grid axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Radial: any map taking the projected ellipse to the unit circle is right.
    Radial,
    /// Separable along the two in-sheet grid axes: the map must keep their orientation.
    Separable,
}

/// Why a kernel spec was rejected. `at` is the byte offset in the spec string.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum KernelSpecError {
    /// The spec is empty or longer than [`MAX_SPEC_LEN`].
    BadLength {
        /// Length found, bytes.
        len: usize,
    },
    /// The name before `:` is not a known kernel.
    UnknownKernel,
    /// A `key=value` pair has a key this kernel does not take.
    UnknownParameter {
        /// Byte offset of the key.
        at: usize,
    },
    /// A parameter appears twice.
    DuplicateParameter {
        /// Byte offset of the second occurrence.
        at: usize,
    },
    /// A parameter is not `key=value`, or the value is not a number.
    BadNumber {
        /// Byte offset of the value.
        at: usize,
    },
    /// A parameter value is outside its allowed range (inclusive bounds).
    OutOfRange {
        /// Parameter name.
        param: &'static str,
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
    /// `sinc` lobes must be odd: with an even count the footprint integrates to zero.
    EvenLobes,
}

impl fmt::Display for KernelSpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::BadLength { len } => {
                write!(
                    f,
                    "kernel spec must be 1 to {MAX_SPEC_LEN} bytes, got {len}"
                )
            }
            Self::UnknownKernel => {
                f.write_str("unknown kernel (expected gaussian, cone, sinc or bilinear)")
            }
            Self::UnknownParameter { at } => write!(f, "unknown kernel parameter at byte {at}"),
            Self::DuplicateParameter { at } => write!(f, "kernel parameter repeated at byte {at}"),
            Self::BadNumber { at } => write!(f, "expected key=number at byte {at}"),
            Self::OutOfRange { param, min, max } => {
                write!(f, "kernel parameter {param} must be in [{min}, {max}]")
            }
            Self::EvenLobes => {
                f.write_str("sinc lobes must be odd (an even count integrates to zero)")
            }
        }
    }
}

impl core::error::Error for KernelSpecError {}

const SPREAD_RANGE: (f32, f32) = (0.05, 64.0);
const SIGMAS_RANGE: (f32, f32) = (0.1, 10.0);
const LOBES_RANGE: (f32, f32) = (1.0, 15.0);

fn check(param: &'static str, v: f32, (min, max): (f32, f32)) -> Result<f32, KernelSpecError> {
    if v.is_finite() && v >= min && v <= max {
        Ok(v)
    } else {
        Err(KernelSpecError::OutOfRange { param, min, max })
    }
}

impl Kernel {
    /// The paper's Gaussian: spread 160 %, 2.5 standard deviations in the radius.
    pub const PAPER_GAUSSIAN: Kernel = Kernel::Gaussian {
        spread: 1.6,
        sigmas: 2.5,
    };

    /// A validated Gaussian (`spread` in voxel spacings, 0.05–64; `sigmas` 0.1–10).
    pub fn gaussian(spread: f32, sigmas: f32) -> Result<Self, KernelSpecError> {
        Ok(Kernel::Gaussian {
            spread: check("spread", spread, SPREAD_RANGE)?,
            sigmas: check("sigmas", sigmas, SIGMAS_RANGE)?,
        })
    }

    /// A validated cone model.
    pub fn cone(spread: f32) -> Result<Self, KernelSpecError> {
        Ok(Kernel::Cone {
            spread: check("spread", spread, SPREAD_RANGE)?,
        })
    }

    /// A validated sinc model (`lobes` odd, 1–15).
    pub fn sinc(spread: f32, lobes: u8) -> Result<Self, KernelSpecError> {
        check("lobes", f32::from(lobes), LOBES_RANGE)?;
        if lobes.is_multiple_of(2) {
            return Err(KernelSpecError::EvenLobes);
        }
        Ok(Kernel::Sinc {
            spread: check("spread", spread, SPREAD_RANGE)?,
            lobes,
        })
    }

    /// A validated bilinear model.
    pub fn bilinear(spread: f32) -> Result<Self, KernelSpecError> {
        Ok(Kernel::Bilinear {
            spread: check("spread", spread, SPREAD_RANGE)?,
        })
    }

    /// Parses `name[:key=value[,key=value…]]`, e.g. `gaussian:spread=1.6,sigmas=2.5`.
    ///
    /// Names and defaults: `gaussian` (spread=1.6, sigmas=2.5), `cone` (spread=1), `sinc`
    /// (spread=5, lobes=5: zeros fall on whole voxel spacings), `bilinear` (spread=1: the tents of
    /// neighbours sum to one). Whitespace is not allowed.
    pub fn parse(spec: &str) -> Result<Self, KernelSpecError> {
        if spec.is_empty() || spec.len() > MAX_SPEC_LEN {
            return Err(KernelSpecError::BadLength { len: spec.len() });
        }
        let (name, params) = match spec.find(':') {
            Some(i) => (&spec[..i], Some((i + 1, &spec[i + 1..]))),
            None => (spec, None),
        };
        // Parameter slots: spread, sigmas, lobes.
        let keys: &[&str] = match name {
            "gaussian" => &["spread", "sigmas"],
            "cone" | "bilinear" => &["spread"],
            "sinc" => &["spread", "lobes"],
            _ => return Err(KernelSpecError::UnknownKernel),
        };
        let mut values: [Option<f32>; 2] = [None, None];
        if let Some((mut offset, list)) = params {
            for item in list.split(',') {
                let eq = item
                    .find('=')
                    .ok_or(KernelSpecError::BadNumber { at: offset })?;
                let (key, value) = (&item[..eq], &item[eq + 1..]);
                let slot = keys
                    .iter()
                    .position(|k| *k == key)
                    .ok_or(KernelSpecError::UnknownParameter { at: offset })?;
                if values[slot].is_some() {
                    return Err(KernelSpecError::DuplicateParameter { at: offset });
                }
                let v: f32 = value.parse().map_err(|_| KernelSpecError::BadNumber {
                    at: offset + eq + 1,
                })?;
                values[slot] = Some(v);
                offset += item.len() + 1;
            }
        }
        match name {
            "gaussian" => Kernel::gaussian(values[0].unwrap_or(1.6), values[1].unwrap_or(2.5)),
            "cone" => Kernel::cone(values[0].unwrap_or(1.0)),
            "bilinear" => Kernel::bilinear(values[0].unwrap_or(1.0)),
            _ => {
                let lobes = values[1].unwrap_or(5.0);
                check("lobes", lobes, LOBES_RANGE)?;
                if lobes != math::floor(lobes) {
                    return Err(KernelSpecError::OutOfRange {
                        param: "lobes",
                        min: LOBES_RANGE.0,
                        max: LOBES_RANGE.1,
                    });
                }
                // In range 1–15 and whole, so the cast is exact.
                Kernel::sinc(values[0].unwrap_or(5.0), lobes as u8)
            }
        }
    }

    /// Writes the canonical spec (all parameters, shortest round-trip numbers), which
    /// [`Kernel::parse`] reads back to an equal kernel.
    pub fn write_spec<W: fmt::Write>(&self, w: &mut W) -> fmt::Result {
        match *self {
            Kernel::Gaussian { spread, sigmas } => {
                write!(w, "gaussian:spread={spread},sigmas={sigmas}")
            }
            Kernel::Cone { spread } => write!(w, "cone:spread={spread}"),
            Kernel::Sinc { spread, lobes } => write!(w, "sinc:spread={spread},lobes={lobes}"),
            Kernel::Bilinear { spread } => write!(w, "bilinear:spread={spread}"),
        }
    }

    /// The canonical spec as a fixed-capacity string.
    pub fn spec(&self) -> heapless::String<MAX_SPEC_LEN> {
        let mut s = heapless::String::new();
        // Every canonical spec is far shorter than MAX_SPEC_LEN (four short numbers at most).
        let _ = self.write_spec(&mut s);
        s
    }

    /// Support radius R in voxel spacings.
    pub fn spread(&self) -> f32 {
        match *self {
            Kernel::Gaussian { spread, .. }
            | Kernel::Cone { spread }
            | Kernel::Sinc { spread, .. }
            | Kernel::Bilinear { spread } => spread,
        }
    }

    /// Radial or separable (see [`Shape`]).
    pub fn shape(&self) -> Shape {
        match self {
            Kernel::Bilinear { .. } => Shape::Separable,
            _ => Shape::Radial,
        }
    }

    /// The unnormalised footprint F(u) at unit coordinates `u` (zero outside the domain). For the
    /// Gaussian this is the exact line integral of the 3D kernel through the unit ball.
    pub fn footprint(&self, u: [f32; 2]) -> f32 {
        match *self {
            Kernel::Gaussian { sigmas, .. } => inside_disc(u).map_or(0.0, |rho2| {
                let half_chord = math::sqrt(1.0 - rho2);
                math::exp(-rho2 * 0.5 * sigmas * sigmas)
                    * (SQRT_2PI / sigmas)
                    * math::erf(half_chord * sigmas * core::f32::consts::FRAC_1_SQRT_2)
            }),
            Kernel::Cone { .. } => inside_disc(u).map_or(0.0, |rho2| 1.0 - math::sqrt(rho2)),
            Kernel::Sinc { lobes, .. } => inside_disc(u).map_or(0.0, |rho2| {
                let x = PI * f32::from(lobes) * math::sqrt(rho2);
                // sin(x)/x loses nothing near 0 with this Taylor step (error < x⁴/120 < 1e-18).
                if x < 1e-4 {
                    1.0 - x * x / 6.0
                } else {
                    math::sin(x) / x
                }
            }),
            Kernel::Bilinear { .. } => {
                let (a, b) = (math::abs(u[0]), math::abs(u[1]));
                if a >= 1.0 || b >= 1.0 {
                    0.0
                } else {
                    (1.0 - a) * (1.0 - b)
                }
            }
        }
    }

    /// ∫∫ F(u) d²u over the footprint's domain (closed form): the normalising constant of the
    /// generic table. For the Gaussian this is the kernel's integral over the unit ball,
    /// 4π ∫₀¹ r² e^(−r²/2σ²) dr = 4π [ √π erf(a)/(4a³) − e^(−a²)/(2a²) ], a = 1/(σ√2).
    pub fn integral(&self) -> f32 {
        match *self {
            Kernel::Gaussian { sigmas, .. } => {
                let a = sigmas * core::f32::consts::FRAC_1_SQRT_2;
                let a2 = a * a;
                4.0 * PI
                    * (math::sqrt(PI) * math::erf(a) / (4.0 * a2 * a) - math::exp(-a2) / (2.0 * a2))
            }
            Kernel::Cone { .. } => PI / 3.0,
            Kernel::Sinc { lobes, .. } => {
                // 2π ∫₀¹ sinc(Lρ) ρ dρ = 2(1 − cos πL)/(πL²) = 4/(πL²) for odd L.
                let l = f32::from(lobes);
                4.0 / (PI * l * l)
            }
            Kernel::Bilinear { .. } => 1.0,
        }
    }
}

const SQRT_2PI: f32 = 2.506_628_3;

/// ρ² = |u|² when `u` is strictly inside the unit disc.
#[inline]
fn inside_disc(u: [f32; 2]) -> Option<f32> {
    let rho2 = u[0] * u[0] + u[1] * u[1];
    (rho2 < 1.0).then_some(rho2)
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write_spec(f)
    }
}

impl core::str::FromStr for Kernel {
    type Err = KernelSpecError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Kernel::parse(s)
    }
}
