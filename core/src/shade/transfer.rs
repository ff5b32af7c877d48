//! The transfer function: value → straight RGBA over a window, its lookup, and the exact bounds
//! of the values it makes visible (which the classifier tests instead of looking each value up).

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

/// Why a transfer function cannot classify.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum TransferFunctionError {
    /// The lookup table has fewer than two entries.
    TooFewEntries {
        /// Entries given.
        len: usize,
    },
    /// The window is empty, reversed or not finite (`lo` must be below `hi`).
    Window {
        /// Value mapped to the first entry.
        lo: f32,
        /// Value mapped to the last entry.
        hi: f32,
    },
    /// An entry has a channel outside [0, 1] or not finite.
    Entry {
        /// Index of the entry.
        index: usize,
    },
    /// A label table ([`super::Labels`]) with no label.
    NoLabels,
    /// A label whose value is not finite or not above the one before it (labels must be sorted
    /// by strictly increasing value).
    LabelOrder {
        /// Index of the label.
        index: usize,
    },
    /// A label with a channel outside [0, 1] or not finite.
    LabelEntry {
        /// Index of the label.
        index: usize,
    },
}

impl core::fmt::Display for TransferFunctionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TooFewEntries { len } => write!(
                f,
                "transfer function has {len} entries; it needs at least 2"
            ),
            Self::Window { lo, hi } => write!(
                f,
                "transfer function window {lo}..{hi} is empty: the low end must be below the high end"
            ),
            Self::Entry { index } => write!(
                f,
                "transfer function entry {index} has a channel outside [0, 1]"
            ),
            Self::NoLabels => write!(f, "the label table has no label"),
            Self::LabelOrder { index } => write!(
                f,
                "label {index} is not finite or not above the label before it (labels must be \
                 sorted by increasing value, each once)"
            ),
            Self::LabelEntry { index } => {
                write!(f, "label {index} has a channel outside [0, 1]")
            }
        }
    }
}

impl core::error::Error for TransferFunctionError {}

impl TransferFunction<'_> {
    /// Checks that this transfer function can classify: at least two entries, a finite window
    /// with `lo < hi`, every channel in [0, 1].
    pub fn check(&self) -> Result<(), TransferFunctionError> {
        if self.lut.len() < 2 {
            return Err(TransferFunctionError::TooFewEntries {
                len: self.lut.len(),
            });
        }
        if !(self.lo.is_finite() && self.hi.is_finite() && self.hi > self.lo) {
            return Err(TransferFunctionError::Window {
                lo: self.lo,
                hi: self.hi,
            });
        }
        if let Some(index) = self
            .lut
            .iter()
            .position(|c| !c.iter().all(|v| (0.0..=1.0).contains(v)))
        {
            return Err(TransferFunctionError::Entry { index });
        }
        Ok(())
    }

    /// `value`'s position along the entries (0 at `lo`, n − 1 at `hi`; unclamped): a
    /// non-decreasing function of `value` (each rounded step is), never NaN for a finite value
    /// and a checked window. A window wider than `f32` can hold (`hi − lo` overflows, as for data
    /// spanning ±3.4·10³⁸) is measured in halves, which cannot overflow and round the same way
    /// (halving is exact); a value so far outside the window that its position overflows is ±∞,
    /// which [`lookup`](TransferFunction::lookup) clamps to the end entries like any other.
    #[inline]
    fn position(&self, value: f32) -> f32 {
        let scale = (self.lut.len() - 1) as f32;
        let width = self.hi - self.lo;
        if width < f32::INFINITY {
            (value - self.lo) / width * scale
        } else {
            (value * 0.5 - self.lo * 0.5) / (self.hi * 0.5 - self.lo * 0.5) * scale
        }
    }

    /// The largest value at or below which [`TransferFunction::lookup`] gives opacity exactly
    /// 0: every entry before the first with opacity above 0 is transparent, and so is every
    /// value whose position falls at or before the last of them (the blend of two zeros is
    /// zero); −∞ when the first entry is not transparent (or the function does not
    /// [`check`](TransferFunction::check)). Found by bisection over the ordered finite `f32`s
    /// on the position [`lookup`](TransferFunction::lookup) computes, which never decreases with
    /// the value, so the bound is exact, not an estimate: a classifier may skip values at or
    /// below it with one comparison.
    pub fn transparent_at_or_below(&self) -> f32 {
        if self.check().is_err() {
            return f32::NEG_INFINITY;
        }
        let Some(first) = self.lut.iter().position(|c| c[3] > 0.0) else {
            // No entry is visible: every value is transparent.
            return f32::INFINITY;
        };
        if first == 0 {
            return f32::NEG_INFINITY;
        }
        let last_clear = (first - 1) as f32;
        last_finite(|v| self.position(v) <= last_clear).unwrap_or(f32::NEG_INFINITY)
    }

    /// The finite values `[low, high]` whose [`lookup`](TransferFunction::lookup) has opacity
    /// above 0, when that set is exactly one interval: every entry from the first with opacity
    /// above 0 to the last has opacity at least [`RAMP_MIN_OPACITY`] (a ramp, a step, a plateau;
    /// not a function whose opacity returns to 0), so a classifier may test visibility with two
    /// comparisons instead of a lookup (NaN and ±∞ fail both, as the lookup makes them
    /// transparent). `None` otherwise, or when no value is visible or the function does not
    /// [`check`](TransferFunction::check).
    ///
    /// Why it is exact: with p(v) the position the lookup computes (never decreasing in v, never
    /// NaN, ±∞ clamped to the end entries) and F the first visible entry, a value with p ≥ F
    /// blends two entries of opacity ≥ 2⁻²⁰ (or reads the last), whose float blend
    /// a + f·(b − a) stays within a few 2⁻²⁴ of [a, b], so above 0; one with p in (F − 1, F)
    /// has opacity f·α_F (0 plus the product), which never decreases with v; below that, 0. So
    /// "p(v) ≥ F or opacity > 0" goes from false to true once, at `low`, found by bisection on
    /// the lookup's own arithmetic, and holds up to `high` = the largest finite `f32`
    /// (`tests/classify.rs` checks against the lookup).
    pub fn visible_interval(&self) -> Option<(f32, f32)> {
        self.check().ok()?;
        let first = self.lut.iter().position(|c| c[3] > 0.0)?;
        if self.lut[first..]
            .iter()
            .any(|c| !(c[3] >= RAMP_MIN_OPACITY))
        {
            return None;
        }
        let from = first as f32;
        let below = |v: f32| !(self.position(v) >= from || self.lookup(v)[3] > 0.0);
        let low = match last_finite(below) {
            None => -f32::MAX,
            Some(v) if v == f32::MAX => return None,
            Some(v) => next_finite_up(v),
        };
        // Every finite value above `low` is visible: positions past the last entry (overflowed
        // ones included) clamp to it, and it is visible.
        Some((low, f32::MAX))
    }

    /// The premultiplied RGBA of a pixel shown as `value` alone (a projection's pixel:
    /// `crate::render::post::Blend`): [`Self::lookup`]'s colour times its opacity, the opacity
    /// clamped to [0, 1] and taken as the pixel's, as VTK's projections take it.
    #[inline]
    pub fn pixel(&self, value: f32) -> [f32; 4] {
        premultiplied(self.lookup(value))
    }

    /// Straight RGBA for `value`; transparent for a non-finite value.
    #[inline]
    pub fn lookup(&self, value: f32) -> [f32; 4] {
        if !value.is_finite() {
            return [0.0; 4];
        }
        let n = self.lut.len();
        // Never NaN (see `position`); ±∞ clamps to the end entries.
        let t = self.position(value).clamp(0.0, (n - 1) as f32);
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

/// Straight RGBA as a pixel's premultiplied RGBA: the colour times the opacity, the opacity
/// clamped to [0, 1] (a projection's pixel, [`TransferFunction::pixel`] and
/// [`super::Shader::pixel`]).
#[inline]
pub(crate) fn premultiplied([r, g, b, a]: [f32; 4]) -> [f32; 4] {
    let a = a.clamp(0.0, 1.0);
    [r * a, g * a, b * a, a]
}

/// The lowest opacity [`TransferFunction::visible_interval`] accepts for the entries from the
/// first visible one on: 2⁻²⁰, far above the few 2⁻²⁴ a float blend of two entries can round by.
pub const RAMP_MIN_OPACITY: f32 = 1.0 / 1_048_576.0;

/// Finite `f32`s in order: their bits read as an `i32`, negative values reversed (held in an
/// `i64` so a bisection's differences cannot overflow).
fn order_key(v: f32) -> i64 {
    let b = i64::from(v.to_bits() as i32);
    if b < 0 {
        i64::from(i32::MIN) - b
    } else {
        b
    }
}

/// The `f32` of an [`order_key`].
fn from_order_key(k: i64) -> f32 {
    if k < 0 {
        f32::from_bits((i64::from(i32::MIN) - k) as u32)
    } else {
        f32::from_bits(k as u32)
    }
}

/// The next finite `f32` above a finite `v` below `f32::MAX` (−0 and +0 are one value).
fn next_finite_up(v: f32) -> f32 {
    from_order_key(order_key(v) + 1)
}

/// The largest finite value at which `holds`, a predicate that is true up to some value and
/// false above it over the finite `f32`s, is true: `None` if it is false everywhere. A
/// bisection of about 32 calls.
fn last_finite(holds: impl Fn(f32) -> bool) -> Option<f32> {
    let (mut lo, mut hi) = (order_key(-f32::MAX), order_key(f32::MAX));
    if !holds(from_order_key(lo)) {
        return None;
    }
    if holds(from_order_key(hi)) {
        return Some(f32::MAX);
    }
    // Invariant: true at lo, false at hi.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if holds(from_order_key(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(from_order_key(lo))
}
