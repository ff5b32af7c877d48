//! What a volume's samples say of their values: the [`ValueMap`] they need
//! ([`ValueMap::for_samples`]), whether they are wide, and their finite range in f64. Apart from
//! `values.rs` so that `volume.rs` (which holds a map) and `values.rs` import in one direction.

use super::values::ValueMap;
use super::volume::{Samples, Volume};

impl ValueMap {
    /// The map for `samples`: [`ValueMap::for_range`] of their finite range for u32, i32 and f64;
    /// the identity for every other type.
    pub fn for_samples(samples: &Samples) -> ValueMap {
        match samples {
            Samples::U32(_) | Samples::I32(_) | Samples::F64(_) => {
                let (lo, hi) = finite_range(samples);
                ValueMap::for_range(lo, hi)
            }
            _ => ValueMap::IDENTITY,
        }
    }
}

impl Volume {
    /// Whether the samples are u32, i32 or f64 (which f32 may not hold: [`ValueMap`]).
    pub fn is_wide(&self) -> bool {
        matches!(
            self.samples,
            Samples::U32(_) | Samples::I32(_) | Samples::F64(_)
        )
    }

    /// Smallest and largest finite sample in the data's own units, f64 (of those stored, for a
    /// brick); (+∞, −∞) when no sample is finite.
    pub fn sample_range(&self) -> (f64, f64) {
        finite_range(&self.samples)
    }
}

/// Smallest and largest finite sample of `samples`, f64, exactly; (+∞, −∞) when none is finite.
fn finite_range(samples: &Samples) -> (f64, f64) {
    fn over<T: Copy>(v: &[T], to: impl Fn(T) -> f64) -> (f64, f64) {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                let v = to(x);
                if v.is_finite() {
                    (lo.min(v), hi.max(v))
                } else {
                    (lo, hi)
                }
            })
    }
    match samples {
        Samples::U8(v) => over(v, f64::from),
        Samples::I8(v) => over(v, f64::from),
        Samples::U16(v) => over(v, f64::from),
        Samples::I16(v) => over(v, f64::from),
        Samples::U32(v) => over(v, f64::from),
        Samples::I32(v) => over(v, f64::from),
        Samples::F32(v) => over(v, f64::from),
        Samples::F64(v) => over(v, |x| x),
        Samples::Coloured(v) => over(v, |x| f64::from(x.value)),
    }
}

#[cfg(test)]
mod tests {
    use super::{Samples, ValueMap, Volume};

    /// Wide samples f32 cannot resolve are rebased exactly where needed: u32 4 294 967 290 …
    /// 295 stay six values (f32 makes them one), f64 past f32's range stays finite, and samples
    /// f32 holds keep the identity (the same bits as before the map existed).
    #[test]
    fn value_maps_keep_wide_samples_apart() {
        let near_top: Vec<u32> = (4_294_967_290..=4_294_967_295).collect();
        let v = Volume::new([6, 1, 1], [1.0; 3], Samples::U32(near_top.clone().into()));
        assert!(!v.values.is_identity());
        let values: Vec<f32> = (0..6).map(|n| v.value(n)).collect();
        assert_eq!(values, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        for (k, &x) in near_top.iter().enumerate() {
            assert_eq!(v.values.to_data(values[k]), f64::from(x));
        }
        let huge = Volume::new([2, 1, 1], [1.0; 3], Samples::F64(vec![1e300, 3e300].into()));
        assert!(huge.range().0.is_finite() && huge.range().1 > huge.range().0);
        let back = huge.values.to_data(huge.range().1);
        assert!((back - 3e300).abs() <= 3e300 * 1e-6, "{back}");
        for s in [
            Samples::U32(vec![0, 1 << 30, 4_000_000_000].into()),
            Samples::I32(vec![-5, 7].into()),
            Samples::F64(vec![0.25, 1e30, -3.0].into()),
            Samples::U16(vec![1, 2].into()),
        ] {
            assert!(ValueMap::for_samples(&s).is_identity(), "{s:?}");
        }
        // A window in data units maps through the same map, in f64.
        let w = v
            .values
            .window_from_data([4_294_967_291.0, 4_294_967_294.0]);
        assert_eq!(w, [1.0, 4.0]);
    }
}
