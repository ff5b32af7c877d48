//! How samples become the renderer's values: [`ValueMap`], the identity but for wide samples
//! (u32, i32, f64) that f32 cannot resolve (the third hostile campaign: u32 values near 2³² made
//! one value, f64 past 3.4·10³⁸ made missing). What a volume's samples say of their map and
//! range is [`super::ranges`] (this file names no volume, so `volume.rs` can hold a map).

/// How a volume's samples become the f32 values the renderer classifies:
/// value = (sample − `offset`) · `scale`, computed in f64 and then rounded to f32 once.
///
/// The identity for every type f32 holds exactly (u8, i8, u16, i16, f32), and for wide samples
/// (u32, i32, f64) whose range f32 resolves. Where it does not, [`ValueMap::for_range`] rebases
/// them: u32 values 4 294 967 290 … 4 294 967 295 are 0 … 5 (f32 would make them one value),
/// f64 values past f32's range (3.4·10³⁸, which f32 makes infinite, so missing) are scaled by a
/// power of two. Windows are given and reported in the data's own units (f64) and mapped through
/// the same map ([`ValueMap::from_data`], [`ValueMap::to_data`]), so the transfer function sees
/// the window arithmetic done in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValueMap {
    /// Subtracted first, data units.
    pub offset: f64,
    /// Then multiplied by (a power of two, so exact).
    pub scale: f64,
}

impl Default for ValueMap {
    fn default() -> Self {
        ValueMap::IDENTITY
    }
}

/// Fewest f32 steps the identity must leave across a wide volume's range (2¹⁶): fewer, and the
/// samples are rebased.
const MIN_STEPS: f64 = 65_536.0;

impl ValueMap {
    /// value = sample.
    pub const IDENTITY: ValueMap = ValueMap {
        offset: 0.0,
        scale: 1.0,
    };

    /// The map for wide samples whose finite values span `lo` ..= `hi` (data units; `lo > hi`:
    /// none is finite): the identity where f32 holds that range finitely with at least 2¹⁶
    /// steps across it (or it is a single value); otherwise `offset` = `lo` and
    /// `scale` the power of two that brings the span to at most 2⁶⁴.
    pub fn for_range(lo: f64, hi: f64) -> ValueMap {
        if !(lo <= hi) || !lo.is_finite() || !hi.is_finite() {
            return ValueMap::IDENTITY;
        }
        let top = lo.abs().max(hi.abs());
        let finite = (top as f32).is_finite() && top < 2f64.powi(126);
        let exact = |v: f64| f64::from(v as f32) == v;
        let resolved = if hi == lo {
            // One value: nothing to tell apart (rounded, as any sample f32 cannot hold).
            true
        } else {
            // One f32 step at the range's largest magnitude.
            let step = f64::from(f32::EPSILON) * top;
            (hi - lo) >= step * MIN_STEPS
                || (exact(lo) && exact(hi) && (hi - lo) >= 1.0 && top <= 16_777_216.0)
        };
        if finite && resolved {
            return ValueMap::IDENTITY;
        }
        let span = hi - lo;
        let e = if span > 0.0 {
            span.log2().ceil() as i32 - 64
        } else {
            0
        };
        ValueMap {
            offset: lo,
            scale: 2f64.powi(-e.max(0)),
        }
    }

    /// Whether values are the samples themselves.
    pub fn is_identity(&self) -> bool {
        *self == ValueMap::IDENTITY
    }

    /// A sample (data units) as the renderer's value.
    #[inline]
    pub fn apply(&self, sample: f64) -> f32 {
        ((sample - self.offset) * self.scale) as f32
    }

    /// A window bound or other value in data units (a `--window`, an iso value) as the
    /// renderer's value: [`ValueMap::apply`].
    pub fn from_data(&self, v: f64) -> f32 {
        self.apply(v)
    }

    /// A renderer's value back in data units (a window for the JSON, `info`, the legend).
    pub fn to_data(&self, v: f32) -> f64 {
        f64::from(v) / self.scale + self.offset
    }

    /// A window in data units as the renderer's.
    pub fn window_from_data(&self, w: [f64; 2]) -> [f32; 2] {
        w.map(|v| self.from_data(v))
    }

    /// A renderer's window in data units.
    pub fn window_to_data(&self, w: [f32; 2]) -> [f64; 2] {
        w.map(|v| self.to_data(v))
    }
}
