//! Projections (issue 77, item 2): how a post-classified ray's samples become a pixel when they
//! are not composited. [`Blend::Maximum`], [`Blend::Minimum`] and [`Blend::Average`] project the
//! *reconstructed value* along the ray, then classify the one projected value (as VTK's,
//! ParaView's and napari's projections do; for a monotone transfer function projecting the
//! classified colour instead gives the same picture).
//!
//! # The continuous model
//! The field is post-classification's normalised reconstruction f̄(x) = Σw·f / Σw (a convex
//! combination of the neighbouring samples, constant up to the volume's faces; see
//! [`super`]), on each ray's chord through the sample box [`super::sample_box`]:
//! - maximum: M = max f̄ over the chord; minimum: m = min f̄ over the chord;
//! - average: A = (1/L)·∫ f̄ dl over the chord of length L;
//!
//! and the pixel is the transfer function's colour and opacity at that value, unshaded,
//! over the background ([`super::Classify::projection`]). A ray that misses the box (or meets no
//! sample with a weight) shows the background.
//!
//! # What the slabs compute
//! The slabs sample f̄ at their mid-planes, T apart along the ray (T the slab's chord), so the
//! projections are of samples:
//! - **average**: the midpoint rule, each sample weighted by the part of its slab's chord
//!   inside the box: Σ f̄ₖ·ℓₖ / Σ ℓₖ (second order in T);
//! - **maximum and minimum**: the extreme sample f̄ₖ and its two neighbours along the ray,
//!   f̄ₖ₋₁ and f̄ₖ₊₁, fitted by a parabola whose vertex is the projection:
//!   f̄ₖ − (f̄ₖ₊₁ − f̄ₖ₋₁)² / (8·(f̄ₖ₊₁ − 2f̄ₖ + f̄ₖ₋₁)). It is exact where f̄ is locally quadratic
//!   (the error of the plain extreme sample, up to T²·|f̄″|/8, falls to O(T³)); the vertex lies
//!   within half a sample of the extreme one, so it never leaves the bracket, and an extreme at
//!   the chord's first or last sample is taken as it is. The classic sheet-buffer maximum (a
//!   max over per-sheet footprint sums) approximates the maximum of the field averaged over a
//!   sheet's thickness; the mid-plane samples approximate the field itself.
//!
//! # Per-pixel state
//! While a frame renders, each image pixel holds its projection so far in its four floats
//! (no other buffer): maximum and minimum keep [extreme, the sample before it, the sample after
//! it, the latest sample] (NaN where there is none yet); average keeps [Σ f̄ℓ, Σ ℓ, 0, 0].
//! Samples arrive in compositing order; the parabola is symmetric, so either order gives the
//! same projection.

/// How a ray's samples become a pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Blend {
    /// The emission–absorption integral: each sample classified and composited (the default).
    #[default]
    Composite,
    /// Maximum-intensity projection (MIP).
    Maximum,
    /// Minimum-intensity projection (MinIP).
    Minimum,
    /// Average-intensity projection.
    Average,
}

impl Blend {
    /// Every blend, in the order `--blend` lists them.
    pub const ALL: [Blend; 4] = [
        Blend::Composite,
        Blend::Maximum,
        Blend::Minimum,
        Blend::Average,
    ];

    /// The name `--blend` and the JSON use: `composite`, `mip`, `minip`, `average`.
    pub fn name(self) -> &'static str {
        match self {
            Blend::Composite => "composite",
            Blend::Maximum => "mip",
            Blend::Minimum => "minip",
            Blend::Average => "average",
        }
    }

    /// The blend named `name` (see [`Blend::name`]).
    pub fn from_name(name: &str) -> Option<Blend> {
        Blend::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Whether samples are projected rather than composited.
    pub fn projects(self) -> bool {
        self != Blend::Composite
    }

    /// The value at or below which a sample need not be read, given the classifier's
    /// `transparent` bound: that bound when compositing, −∞ for a projection (no value is
    /// transparent to a minimum).
    pub fn transparent_bound(self, transparent: f32) -> f32 {
        if self.projects() {
            f32::NEG_INFINITY
        } else {
            transparent
        }
    }

    /// A pixel's state before any sample (see the module docs).
    pub fn start(self) -> [f32; 4] {
        match self {
            Blend::Maximum | Blend::Minimum => [f32::NAN; 4],
            Blend::Composite | Blend::Average => [0.0; 4],
        }
    }

    /// Folds one sample `value` whose slab's chord lies `fraction` ∈ (0, 1] inside the sample
    /// box into a pixel's `state` (nothing for [`Blend::Composite`]).
    #[inline]
    pub fn fold(self, state: &mut [f32; 4], value: f32, fraction: f32) {
        let better = |a: f32, b: f32| match self {
            Blend::Maximum => a > b,
            _ => a < b,
        };
        match self {
            Blend::Composite => {}
            Blend::Average => {
                state[0] += value * fraction;
                state[1] += fraction;
            }
            Blend::Maximum | Blend::Minimum => {
                let [best, _, after, last] = *state;
                if best.is_nan() || better(value, best) {
                    // A new extreme: its predecessor is the latest sample, its successor is
                    // still to come.
                    *state = [value, last, f32::NAN, value];
                } else {
                    if after.is_nan() {
                        // The extreme was the latest sample: this one follows it.
                        state[2] = value;
                    }
                    state[3] = value;
                }
            }
        }
    }

    /// The projected value of a pixel's `state`: `None` where no sample was folded (or for
    /// [`Blend::Composite`]).
    pub fn projected(self, state: [f32; 4]) -> Option<f32> {
        match self {
            Blend::Composite => None,
            Blend::Average => (state[1] > 0.0).then(|| state[0] / state[1]),
            Blend::Maximum | Blend::Minimum => {
                let [best, before, after, _] = state;
                if best.is_nan() {
                    return None;
                }
                if before.is_nan() || after.is_nan() {
                    return Some(best);
                }
                Some(vertex(before, best, after))
            }
        }
    }
}

/// The vertex of the parabola through (−1, `before`), (0, `best`), (1, `after`) where `best` is
/// at least as extreme as both (so the vertex lies in [−½, ½] and between `best` and the
/// parabola's own extreme); `best` where the three are collinear.
#[inline]
pub fn vertex(before: f32, best: f32, after: f32) -> f32 {
    let d2 = after - 2.0 * best + before;
    let d1 = after - before;
    if d2 == 0.0 || !d2.is_finite() {
        return best;
    }
    let v = best - d1 * d1 / (8.0 * d2);
    // |d1| ≤ |d2| when best is extreme, so the correction is at most |d2|/8; rounding kept in.
    if v.is_finite() {
        v
    } else {
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Folding samples of a parabola gives its vertex exactly (to rounding), in either order,
    /// wherever the vertex sits between samples; an extreme at the ends is taken as it is.
    #[test]
    fn the_fold_finds_a_parabolas_vertex_in_either_order() {
        for blend in [Blend::Maximum, Blend::Minimum] {
            let sign = if blend == Blend::Maximum { -1.0 } else { 1.0 };
            for peak in [3.0f32, 3.25, 3.5, 4.7, 5.4] {
                let f = |t: f32| 2.0 + sign * 0.3 * (t - peak) * (t - peak);
                let samples: [f32; 9] = core::array::from_fn(|k| f(k as f32));
                for reverse in [false, true] {
                    let mut state = blend.start();
                    let mut order: [usize; 9] = core::array::from_fn(|k| k);
                    if reverse {
                        order.reverse();
                    }
                    for k in order {
                        blend.fold(&mut state, samples[k], 1.0);
                    }
                    let got = blend.projected(state).unwrap();
                    assert!(
                        (got - 2.0).abs() < 1e-5,
                        "{blend:?} {peak} {reverse}: {got}"
                    );
                }
            }
            // The extreme at the last sample: taken as it is.
            let mut state = blend.start();
            for k in 0..5 {
                blend.fold(&mut state, -sign * k as f32, 1.0);
            }
            assert_eq!(blend.projected(state), Some(-sign * 4.0));
        }
    }

    /// The projected maximum never falls below the largest sample nor passes it by more than
    /// the parabola allows (an eighth of the second difference), on arbitrary samples.
    #[test]
    fn the_vertex_stays_within_its_bracket() {
        let mut x = 0x2545_f491u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x % 1000) as f32 / 100.0
        };
        for _ in 0..2000 {
            let s: [f32; 7] = core::array::from_fn(|_| next());
            let mut state = Blend::Maximum.start();
            for v in s {
                Blend::Maximum.fold(&mut state, v, 1.0);
            }
            let top = s.iter().copied().fold(f32::MIN, f32::max);
            let got = Blend::Maximum.projected(state).unwrap();
            assert!(
                got >= top - 1e-5 && got <= top + 20.0 / 8.0 + 1e-4,
                "{s:?}: {got}"
            );
        }
    }

    /// The average weighs each sample by its slab's part of the chord; nothing folded is none.
    #[test]
    fn the_average_weighs_by_the_chord_inside() {
        let mut state = Blend::Average.start();
        assert_eq!(Blend::Average.projected(state), None);
        Blend::Average.fold(&mut state, 1.0, 0.5);
        Blend::Average.fold(&mut state, 4.0, 1.0);
        assert_eq!(Blend::Average.projected(state), Some(3.0));
        assert_eq!(Blend::Maximum.projected(Blend::Maximum.start()), None);
        for b in Blend::ALL {
            assert_eq!(Blend::from_name(b.name()), Some(b));
        }
    }
}
