//! What the pilots share: a well-spread hash that places samples, and a candidate's estimated
//! error. A leaf: it imports no other pipeline module.

/// A candidate's error at the sampled pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// 10·log₁₀(1/m), m the sampled MSE (RGB), dB.
    pub estimate_db: f64,
    /// The same with the MSE's upper confidence bound (the pilot's: [`super::pilot`] over
    /// pixels, [`super::level_pilot`] over rows): what is compared with the target, dB.
    pub bound_db: f64,
    /// The same with the MSE's lower confidence bound, m − z·s/√n·√(1 − n/total) (at least 0):
    /// where even this falls short of a target, more samples would not reach it, dB.
    pub hope_db: f64,
}

impl Estimate {
    /// The estimate of `values` (one squared error per sampling unit, RGB mean) sampled from
    /// `total` units: their mean m and standard deviation s give m, and the upper bound
    /// m + z·s/√n·√(1 − n/total) (m itself when every unit is sampled), and the lower one
    /// m − z·s/√n·√(1 − n/total). A NaN error reaches nothing.
    pub fn of(values: &[f64], total: usize, z: f64) -> Estimate {
        let n = values.len().max(1) as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = if values.len() > 1 {
            values.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        let finite = (1.0 - n / total.max(1) as f64).max(0.0);
        let half = z * (var / n * finite).sqrt();
        let bound = mean + half;
        let db = |mse: f64| {
            if mse > 0.0 {
                -10.0 * mse.log10()
            } else if mse == 0.0 {
                f64::INFINITY
            } else {
                f64::NAN // a NaN error: never "reaches" anything
            }
        };
        Estimate {
            estimate_db: db(mean),
            bound_db: db(bound),
            // (`max` would turn a NaN into 0.)
            hope_db: db(if mean - half < 0.0 { 0.0 } else { mean - half }),
        }
    }
}

/// SplitMix64's finaliser: a well-spread hash of one word.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
