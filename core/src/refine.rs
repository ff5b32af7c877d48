//! Adaptive refinement: the paper's "adaptive re-sampling" (Westover 1990, last section) for
//! magnified volumes.
//!
//! "If nearby input samples vary widely, or produce colors that vary widely, the renderer can
//! interpolate new values between the input samples along grid directions and adjust the
//! appropriate grid spacing on the fly." Here the grid stays *rectilinear*: along each grid axis,
//! the interval between coarse samples i and i + 1 is split into `factors[i]` ∈ {1, 2, 4} equal
//! steps ([`RefinedAxis`]), so the refined samples are the tensor product of three sorted lists of
//! positions. A sample inside a refined interval has spacing 1/f on both sides; a coarse sample
//! at the border of two intervals split differently has a different spacing on each side — the
//! paper's asymmetric case ("the scale factor may be 4.0 for positive i and 2.0 for negative i"),
//! [`RefinedSample::spacing`].
//!
//! # Rectilinear grids
//! The same axes carry a *rectilinear* grid, whose samples stand at given positions
//! ([`RefinedAxis::rectilinear`]: strictly increasing, in the frame's grid steps) instead of one
//! step apart: each sample's spacings are its distances to its neighbours, the kernel of each
//! sample is scaled per side to them (the asymmetric case above, for any scale), and an interval
//! may still be split into 1, 2 or 4 equal steps. The field such a grid stands for is the uniform
//! grid's composed with the piecewise-linear map from position to sample index (per axis), so
//! the kernels still sum to what the uniform lattice's do (a partition of unity): each kernel is
//! the uniform one scaled, interval by interval, to the length of the interval it lies over, and
//! the per-side scaling is exact out to the sample's neighbours.
//!
//! # Interpolation
//! New values come from the tensor-product Catmull–Rom cubic through the 4 × 4 × 4 nearest coarse
//! samples ([`catmull_rom`]). It passes through the samples, reproduces quadratics (third-order
//! error, where linear interpolation is second-order and adds nothing a Gaussian splat of the
//! coarse samples lacks), and its derivative at a sample is the central difference the renderer
//! already shades with, so refined and unrefined samples are lit alike. It overshoots near steps
//! (by at most 1/8 of the step); the transfer function clamps values to its window.
//!
//! # Choosing the factors
//! [`factor_for`]: an interval whose neighbouring samples' classified colours differ by `v` (the
//! largest over the plane of the interval and over the four premultiplied channels) is split into
//! the fewest of 1, 2, 4 steps that brings `v / f` to the threshold, and never into steps that
//! project closer than a minimum on screen.

use core::fmt;

/// The largest refinement factor (steps per coarse interval).
pub const MAX_FACTOR: u8 = 4;

/// Why a refinement could not be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum RefineError {
    /// A factor other than 1, 2 or 4.
    BadFactor {
        /// Grid axis (0 = i, 1 = j, 2 = k).
        axis: usize,
        /// Interval (between coarse samples `interval` and `interval + 1`).
        interval: usize,
        /// The factor given.
        factor: u8,
    },
    /// An axis with the wrong number of factors (one per interval: samples − 1).
    Length {
        /// Grid axis.
        axis: usize,
        /// Factors expected.
        expected: usize,
        /// Factors given.
        got: usize,
    },
    /// A threshold that is not a non-negative finite number.
    BadThreshold {
        /// The threshold given.
        value: f32,
    },
    /// A rectilinear position that is not finite or not above the one before it.
    Position {
        /// Grid axis.
        axis: usize,
        /// The sample.
        index: usize,
        /// Its position.
        value: f32,
    },
}

impl fmt::Display for RefineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadFactor {
                axis,
                interval,
                factor,
            } => write!(
                f,
                "refinement factor {factor} on axis {axis}, interval {interval}: factors are 1, 2 or 4"
            ),
            Self::Length {
                axis,
                expected,
                got,
            } => write!(
                f,
                "axis {axis} has {got} refinement factors, expected {expected} (one per interval)"
            ),
            Self::BadThreshold { value } => write!(
                f,
                "refinement threshold {value} is not a non-negative finite number"
            ),
            Self::Position { axis, index, value } => write!(
                f,
                "axis {axis}, coordinate {index}: {value} is not finite and above the one before \
                 (coordinates must increase strictly)"
            ),
        }
    }
}

impl core::error::Error for RefineError {}

/// One sample of a refined axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefinedSample {
    /// The coarse sample at or below it.
    pub coarse: usize,
    /// Its offset from `coarse`, coarse steps, in [0, 1).
    pub frac: f32,
    /// Distance to the previous and to the next sample, the frame's grid steps (at an end of the
    /// axis, the one neighbour's distance on both sides; 1 for an axis one sample long).
    pub spacing: [f32; 2],
    /// Position along the axis, the frame's grid steps: `coarse + frac` on a uniform grid; on a
    /// rectilinear one, `frac` of the way along the coarse interval.
    pub at: f32,
    /// Coarse (index) steps per grid step here, which turns a derivative per coarse step into
    /// one per grid step: 1 on a uniform grid; on a rectilinear one the inverse of the interval's
    /// length inside it, and at a coarse sample 2 / (the sum of its two intervals), so that the
    /// Catmull–Rom slope there (the central difference) becomes the non-uniform central
    /// difference (one-sided at an end).
    pub rate: f32,
}

impl RefinedSample {
    /// Position along the axis, the frame's grid steps.
    pub fn position(&self) -> f32 {
        self.at
    }

    /// The mean of the two spacings: the share of the axis this sample stands for.
    pub fn width(&self) -> f32 {
        0.5 * (self.spacing[0] + self.spacing[1])
    }
}

/// One grid axis of `n` coarse samples with each interval split into `factors[i]` steps.
#[derive(Clone, Copy, Debug)]
pub struct RefinedAxis<'a> {
    n: usize,
    factors: &'a [u8],
    /// A rectilinear axis's sample positions (grid steps, strictly increasing); `None`: one step
    /// apart from 0.
    positions: Option<&'a [f32]>,
}

impl<'a> RefinedAxis<'a> {
    /// Axis `axis` (for errors) of `n` ≥ 1 coarse samples, `factors` one per interval (n − 1), each
    /// 1, 2 or 4.
    pub fn new(axis: usize, n: usize, factors: &'a [u8]) -> Result<Self, RefineError> {
        let expected = n.saturating_sub(1);
        if factors.len() != expected {
            return Err(RefineError::Length {
                axis,
                expected,
                got: factors.len(),
            });
        }
        if let Some((interval, &factor)) = factors
            .iter()
            .enumerate()
            .find(|(_, &f)| !matches!(f, 1 | 2 | 4))
        {
            return Err(RefineError::BadFactor {
                axis,
                interval,
                factor,
            });
        }
        Ok(RefinedAxis {
            n,
            factors,
            positions: None,
        })
    }

    /// Axis `axis` of a rectilinear grid: its samples at `positions` (the frame's grid steps,
    /// finite and strictly increasing), each interval split into `factors[i]` steps as for
    /// [`RefinedAxis::new`] (all ones: the grid as it is).
    pub fn rectilinear(
        axis: usize,
        positions: &'a [f32],
        factors: &'a [u8],
    ) -> Result<Self, RefineError> {
        let n = positions.len();
        let mut previous = f32::NEG_INFINITY;
        for (index, &value) in positions.iter().enumerate() {
            if !(value.is_finite() && value > previous) {
                return Err(RefineError::Position { axis, index, value });
            }
            previous = value;
        }
        let uniform = Self::new(axis, n, factors)?;
        Ok(RefinedAxis {
            positions: Some(positions),
            ..uniform
        })
    }

    /// Whether the samples stand at given positions ([`RefinedAxis::rectilinear`]).
    pub fn is_rectilinear(&self) -> bool {
        self.positions.is_some()
    }

    /// Coarse samples.
    pub fn coarse_len(&self) -> usize {
        self.n
    }

    /// Refined samples: 1 + Σ factors (0 for an empty axis).
    pub fn len(&self) -> usize {
        if self.n == 0 {
            return 0;
        }
        1 + self.factors.iter().map(|&f| usize::from(f)).sum::<usize>()
    }

    /// Whether the axis has no samples.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The refined sample `m` steps past coarse sample `i` (m < `factors[i]`; m = 0 for the last).
    pub fn sample(&self, i: usize, m: usize) -> RefinedSample {
        // Interval k's length and its refined step, grid steps.
        let length = |k: usize| self.positions.map_or(1.0, |p| p[k + 1] - p[k]);
        let step = |k: usize| length(k) / f32::from(self.factors[k]);
        let right = (i + 1 < self.n).then(|| step(i));
        let left = if m > 0 {
            right
        } else {
            i.checked_sub(1).map(step)
        };
        let (l, r) = match (left, right) {
            (Some(l), Some(r)) => (l, r),
            (Some(l), None) => (l, l),
            (None, Some(r)) => (r, r),
            (None, None) => (1.0, 1.0),
        };
        let frac = match right {
            Some(_) => m as f32 / f32::from(self.factors[i]),
            None => 0.0,
        };
        let (at, rate) = match self.positions {
            None => (i as f32 + frac, 1.0),
            Some(p) => {
                let inside = (i + 1 < self.n).then(|| length(i));
                let rate = match (m, i.checked_sub(1).map(length), inside) {
                    (1.., _, Some(li)) => 1.0 / li,
                    (_, Some(lp), Some(li)) => 2.0 / (lp + li),
                    (_, Some(lp), None) => 1.0 / lp,
                    (_, None, Some(li)) => 1.0 / li,
                    _ => 1.0,
                };
                (p[i] + frac * inside.unwrap_or(0.0), rate)
            }
        };
        RefinedSample {
            coarse: i,
            frac,
            spacing: [l, r],
            at,
            rate,
        }
    }

    /// Calls `f` on every refined sample, ascending or descending.
    pub fn for_each<E>(
        &self,
        ascending: bool,
        mut f: impl FnMut(RefinedSample) -> Result<(), E>,
    ) -> Result<(), E> {
        let Some(last) = self.n.checked_sub(1) else {
            return Ok(());
        };
        if ascending {
            for (i, &k) in self.factors.iter().enumerate() {
                for m in 0..usize::from(k) {
                    f(self.sample(i, m))?;
                }
            }
            f(self.sample(last, 0))
        } else {
            f(self.sample(last, 0))?;
            for (i, &k) in self.factors.iter().enumerate().rev() {
                for m in (0..usize::from(k)).rev() {
                    f(self.sample(i, m))?;
                }
            }
            Ok(())
        }
    }
}

/// Catmull–Rom weights for the coarse samples at offsets −1, 0, 1, 2 from the sample below a
/// point `t` ∈ [0, 1) steps past it, and the weights of the derivative (per coarse step).
/// At t = 0 they are (0, 1, 0, 0) and (−½, 0, ½, 0): the sample and its central difference.
#[inline]
pub fn catmull_rom(t: f32) -> ([f32; 4], [f32; 4]) {
    let (t2, t3) = (t * t, t * t * t);
    (
        [
            0.5 * (-t3 + 2.0 * t2 - t),
            0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2),
        ],
        [
            0.5 * (-3.0 * t2 + 4.0 * t - 1.0),
            0.5 * (9.0 * t2 - 10.0 * t),
            0.5 * (-9.0 * t2 + 8.0 * t + 1.0),
            0.5 * (3.0 * t2 - 2.0 * t),
        ],
    )
}

/// The factor for an interval whose neighbouring samples differ by `variation` (any unit the
/// threshold shares; see the module docs): the smallest of 1, 2, 4 with `variation / f ≤
/// threshold`, capped at 4 and at `max` (steps must not project closer than the caller's limit;
/// `max` is rounded down to 1, 2 or 4). A NaN variation does not refine.
pub fn factor_for(variation: f32, threshold: f32, max: u8) -> Result<u8, RefineError> {
    if !(threshold >= 0.0 && threshold.is_finite()) {
        return Err(RefineError::BadThreshold { value: threshold });
    }
    let cap = match max {
        0 | 1 => 1,
        2 | 3 => 2,
        _ => MAX_FACTOR,
    };
    let want = if !(variation > threshold) {
        1
    } else if variation <= 2.0 * threshold {
        2
    } else {
        MAX_FACTOR
    };
    Ok(want.min(cap))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_positions_and_spacings() {
        let f = [1u8, 2, 4];
        let axis = RefinedAxis::new(0, 4, &f).unwrap();
        assert_eq!(axis.len(), 8);
        let mut got = [(0.0f32, [0.0f32; 2]); 8];
        let mut n = 0;
        axis.for_each::<()>(true, |s| {
            got[n] = (s.position(), s.spacing);
            n += 1;
            Ok(())
        })
        .unwrap();
        let want = [
            (0.0, [1.0, 1.0]),
            (1.0, [1.0, 0.5]),
            (1.5, [0.5, 0.5]),
            (2.0, [0.5, 0.25]),
            (2.25, [0.25, 0.25]),
            (2.5, [0.25, 0.25]),
            (2.75, [0.25, 0.25]),
            (3.0, [0.25, 0.25]),
        ];
        assert_eq!(got, want);
        // Every spacing is the distance to the neighbour on that side.
        for k in 1..8 {
            assert_eq!(got[k].0 - got[k - 1].0, got[k].1[0]);
            assert_eq!(got[k].0 - got[k - 1].0, got[k - 1].1[1]);
        }
        let mut back = [0.0f32; 8];
        let mut n = 0;
        axis.for_each::<()>(false, |s| {
            back[n] = s.position();
            n += 1;
            Ok(())
        })
        .unwrap();
        back.reverse();
        assert_eq!(back, got.map(|g| g.0));
    }

    #[test]
    fn rectilinear_positions_spacings_and_rates() {
        let p = [0.0f32, 1.0, 3.0, 3.5];
        let axis = RefinedAxis::rectilinear(1, &p, &[1, 2, 1]).unwrap();
        assert!(axis.is_rectilinear());
        assert_eq!(axis.len(), 5);
        let mut got = [(0.0f32, [0.0f32; 2], 0.0f32, 0usize, 0.0f32); 5];
        let mut n = 0;
        axis.for_each::<()>(true, |s| {
            got[n] = (s.position(), s.spacing, s.rate, s.coarse, s.frac);
            n += 1;
            Ok(())
        })
        .unwrap();
        let want = [
            (0.0, [1.0, 1.0], 1.0, 0, 0.0),
            // Between intervals of 1 and 2: the non-uniform central difference's 2 / 3.
            (1.0, [1.0, 1.0], 2.0 / 3.0, 1, 0.0),
            // Inside the split interval: half of it on each side, 1 / its length.
            (2.0, [1.0, 1.0], 0.5, 1, 0.5),
            (3.0, [1.0, 0.5], 2.0 / 2.5, 2, 0.0),
            (3.5, [0.5, 0.5], 2.0, 3, 0.0),
        ];
        assert_eq!(got, want);
        for k in 1..5 {
            assert_eq!(got[k].0 - got[k - 1].0, got[k].1[0]);
            assert_eq!(got[k].0 - got[k - 1].0, got[k - 1].1[1]);
        }
        // A uniform axis is the rectilinear one at 0, 1, 2, ...
        let uniform = RefinedAxis::new(0, 4, &[1, 2, 4]).unwrap();
        let at = RefinedAxis::rectilinear(0, &[0.0, 1.0, 2.0, 3.0], &[1, 2, 4]).unwrap();
        let every = |axis: &RefinedAxis| {
            let mut out = [None; 8];
            let mut n = 0;
            axis.for_each::<()>(true, |s| {
                out[n] = Some(s);
                n += 1;
                Ok(())
            })
            .unwrap();
            out
        };
        let (a, b) = (every(&uniform), every(&at));
        assert_eq!(a, b);
        // Refused: a coordinate that repeats, goes back, or is NaN; a count that is not the
        // samples'.
        for bad in [[0.0, 1.0, 1.0], [0.0, 2.0, 1.0], [0.0, f32::NAN, 2.0]] {
            assert!(matches!(
                RefinedAxis::rectilinear(2, &bad, &[1, 1]),
                Err(RefineError::Position {
                    axis: 2,
                    index: 2 | 1,
                    ..
                })
            ));
        }
        assert!(matches!(
            RefinedAxis::rectilinear(0, &[0.0, 1.0], &[1, 1]),
            Err(RefineError::Length { .. })
        ));
    }

    #[test]
    fn one_sample_and_refusals() {
        let axis = RefinedAxis::new(2, 1, &[]).unwrap();
        assert_eq!(axis.len(), 1);
        assert_eq!(axis.sample(0, 0).spacing, [1.0, 1.0]);
        assert!(matches!(
            RefinedAxis::new(1, 3, &[1, 3]),
            Err(RefineError::BadFactor {
                axis: 1,
                interval: 1,
                factor: 3
            })
        ));
        assert!(matches!(
            RefinedAxis::new(0, 3, &[1]),
            Err(RefineError::Length { .. })
        ));
        assert!(factor_for(1.0, f32::NAN, 4).is_err());
        assert!(factor_for(1.0, -1.0, 4).is_err());
    }

    #[test]
    fn factors_follow_the_threshold_and_the_cap() {
        assert_eq!(factor_for(0.05, 0.1, 4), Ok(1));
        assert_eq!(factor_for(0.15, 0.1, 4), Ok(2));
        assert_eq!(factor_for(0.5, 0.1, 4), Ok(4));
        assert_eq!(factor_for(0.5, 0.1, 3), Ok(2));
        assert_eq!(factor_for(0.5, 0.1, 1), Ok(1));
        assert_eq!(factor_for(f32::NAN, 0.1, 4), Ok(1));
        assert_eq!(factor_for(0.0, 0.0, 4), Ok(1));
    }

    #[test]
    fn catmull_rom_interpolates_and_reproduces_quadratics() {
        let q = |x: f32| 0.3 * x * x - 1.2 * x + 0.7;
        let dq = |x: f32| 0.6 * x - 1.2;
        for k in 0..=16 {
            let t = k as f32 / 16.0;
            let (w, d) = catmull_rom(t);
            let v: f32 = (0..4).map(|i| w[i] * q(i as f32 - 1.0)).sum();
            let g: f32 = (0..4).map(|i| d[i] * q(i as f32 - 1.0)).sum();
            assert!((v - q(t)).abs() < 1e-5, "value at {t}: {v} vs {}", q(t));
            assert!((g - dq(t)).abs() < 1e-4, "slope at {t}: {g} vs {}", dq(t));
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
            assert!(d.iter().sum::<f32>().abs() < 1e-6);
        }
        assert_eq!(
            catmull_rom(0.0),
            ([0.0, 1.0, 0.0, 0.0], [-0.5, 0.0, 0.5, 0.0])
        );
    }
}
