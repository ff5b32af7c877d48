//! Volumes in memory: dimensions, spacing, orientation and samples, and the sample decoding every
//! loader shares (the loaders themselves are in [`super::formats`]).
//!
//! Data are x-fastest: sample (i, j, k) is at `i + dims[0]·(j + dims[1]·k)`.

use super::brick::BrickPlace;
use crate::CliError;
use footprint::lod::Coloured;
use std::path::Path;

pub use super::values::ValueMap;

/// Sample storage, by type.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    U8(Data<u8>),
    I8(Data<i8>),
    U16(Data<u16>),
    I16(Data<i16>),
    U32(Data<u32>),
    I32(Data<i32>),
    F32(Data<f32>),
    F64(Data<f64>),
    /// A coarser level of detail averaged by extinction: values with the straight colour of
    /// their block (the core's `lod::Coloured`); never read from a file.
    Coloured(Data<Coloured>),
}

/// The samples of one type, x-fastest: owned (read from a file, computed), or shared with an
/// owner outside the harness that keeps them alive and unchanged while the volume lives (a numpy
/// array handed over by the Python package without a copy). Read as a slice either way.
pub struct Data<T: 'static>(Store<T>);

enum Store<T: 'static> {
    Owned(Vec<T>),
    Shared(std::sync::Arc<dyn AsRef<[T]> + Send + Sync>),
}

impl<T> Data<T> {
    /// Samples another owner holds: `owner.as_ref()` must give the same slice for as long as
    /// this (and every clone of it) lives.
    pub fn shared(owner: std::sync::Arc<dyn AsRef<[T]> + Send + Sync>) -> Self {
        Data(Store::Shared(owner))
    }

    /// Whether the samples are shared with an owner outside (not copied in).
    pub fn is_shared(&self) -> bool {
        matches!(self.0, Store::Shared(_))
    }
}

impl<T> std::ops::Deref for Data<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        match &self.0 {
            Store::Owned(v) => v,
            Store::Shared(owner) => (**owner).as_ref(),
        }
    }
}

impl<T> From<Vec<T>> for Data<T> {
    fn from(v: Vec<T>) -> Self {
        Data(Store::Owned(v))
    }
}

impl<T: Clone> Clone for Data<T> {
    fn clone(&self) -> Self {
        match &self.0 {
            Store::Owned(v) => Data(Store::Owned(v.clone())),
            Store::Shared(owner) => Data(Store::Shared(owner.clone())),
        }
    }
}

impl<T: PartialEq> PartialEq for Data<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T> std::fmt::Debug for Data<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {} samples",
            self.len(),
            if self.is_shared() { "shared" } else { "owned" }
        )
    }
}

/// A sample type name as written on the command line and in NRRD headers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl SampleType {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::F64 => 8,
        }
    }

    /// Parses NRRD's type names (all spellings of the NRRD spec) and short names (`u8`, `f32`, …).
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s.trim() {
            "uchar" | "unsigned char" | "uint8" | "uint8_t" | "u8" => SampleType::U8,
            "signed char" | "int8" | "int8_t" | "i8" => SampleType::I8,
            "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" | "u16" => {
                SampleType::U16
            }
            "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t"
            | "i16" => SampleType::I16,
            "uint" | "unsigned int" | "uint32" | "uint32_t" | "u32" => SampleType::U32,
            "int" | "signed int" | "int32" | "int32_t" | "i32" => SampleType::I32,
            "float" | "float32" | "f32" => SampleType::F32,
            "double" | "float64" | "f64" => SampleType::F64,
            _ => return None,
        })
    }
}

/// A volume: dimensions, spacing, orientation and samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// World units per voxel along i, j, k.
    pub spacing: [f32; 3],
    /// World direction (unit vector) of each grid axis: `directions[c]` for axis c. The identity for
    /// formats that state only spacings.
    pub directions: [[f32; 3]; 3],
    /// The samples: all `dims` of them, or, for a brick ([`Volume::brick`]), only the stored box.
    pub samples: Samples,
    /// `Some` for one brick of a volume split among processes (`footprint render` under MPI,
    /// [`super::brick`]): `dims` are the whole volume's, `samples` hold only
    /// [`BrickPlace::stored`] (the brick and its ghost layers), and only the voxels of
    /// [`BrickPlace::owned`] are rendered. Sheets read from it are the whole volume's, NaN
    /// (missing, transparent) outside the stored box.
    pub brick: Option<BrickPlace>,
    /// How samples become the renderer's f32 values ([`ValueMap`]): the identity unless wide
    /// samples need rebasing ([`ValueMap::for_samples`], set by the loaders and
    /// [`Volume::new`]).
    pub values: ValueMap,
    /// A rectilinear grid's coordinates (`.vtr`): `spacing` is then their mean ([`super::grid`]).
    pub grid: Option<std::sync::Arc<super::grid::Coordinates>>,
}

/// The identity orientation.
pub const AXIS_ALIGNED: [[f32; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl Volume {
    /// An axis-aligned volume.
    pub fn new(dims: [usize; 3], spacing: [f32; 3], samples: Samples) -> Self {
        Volume {
            dims,
            spacing,
            directions: AXIS_ALIGNED,
            values: ValueMap::for_samples(&samples),
            samples,
            brick: None,
            grid: None,
        }
    }

    /// The dims of the samples held: `dims`, or a brick's stored box.
    pub fn stored_dims(&self) -> [usize; 3] {
        self.brick.map_or(self.dims, |b| b.stored.dims())
    }

    /// The voxels of sheet `s` of `axis` this volume renders, as index ranges along the sheet's
    /// two in-sheet axes (u, v); `None` when it renders none of them. The whole sheet unless the
    /// volume is a brick.
    pub fn owned_in_sheet(
        &self,
        axis: usize,
        s: usize,
    ) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let (a, b) = footprint::geometry::in_sheet_axes(axis);
        let Some(brick) = self.brick else {
            return Some((0..self.dims[a], 0..self.dims[b]));
        };
        let o = brick.owned;
        (o.lo[axis] <= s && s < o.hi[axis]).then(|| (o.lo[a]..o.hi[a], o.lo[b]..o.hi[b]))
    }

    /// The grid-to-world matrix G: column c = `directions[c] × spacing[c]`.
    pub fn grid_to_world(&self) -> glam::Mat3 {
        let col = |c: usize| glam::Vec3::from_array(self.directions[c]) * self.spacing[c];
        glam::Mat3::from_cols(col(0), col(1), col(2))
    }

    /// Sample at linear index `n` as f32.
    #[inline]
    pub fn value(&self, n: usize) -> f32 {
        match &self.samples {
            Samples::U8(v) => f32::from(v[n]),
            Samples::I8(v) => f32::from(v[n]),
            Samples::U16(v) => f32::from(v[n]),
            Samples::I16(v) => f32::from(v[n]),
            Samples::U32(v) => self.values.apply(f64::from(v[n])),
            Samples::I32(v) => self.values.apply(f64::from(v[n])),
            Samples::F32(v) => v[n],
            Samples::F64(v) => self.values.apply(v[n]),
            Samples::Coloured(v) => v[n].value,
        }
    }

    /// The sample at linear index `n` of the whole grid (`dims`, i fastest) as f32: [`Volume::value`]
    /// for a whole volume; for a brick, its stored sample there, NaN (missing) outside the
    /// stored box. What a reader indexing the whole grid (the refinement, a probe) calls.
    #[inline]
    pub fn value_in_grid(&self, n: usize) -> f32 {
        let Some(b) = self.brick else {
            return self.value(n);
        };
        let [nx, ny, _] = self.dims;
        let g = [n % nx, (n / nx) % ny, n / (nx * ny)];
        if !b.stored.contains(g) {
            return f32::NAN;
        }
        self.stored_value(b.stored, g)
    }

    /// A brick's sample at whole-grid voxel `g`, which must lie in its stored box `stored`.
    #[inline]
    fn stored_value(&self, stored: super::brick::IndexBox, g: [usize; 3]) -> f32 {
        let (sd, l) = (stored.dims(), [0, 1, 2].map(|c| g[c] - stored.lo[c]));
        self.value(l[0] + sd[0] * (l[1] + sd[1] * l[2]))
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Bytes the samples take in memory.
    pub fn bytes(&self) -> usize {
        let per = match &self.samples {
            Samples::U8(_) | Samples::I8(_) => 1,
            Samples::U16(_) | Samples::I16(_) => 2,
            Samples::U32(_) | Samples::I32(_) | Samples::F32(_) => 4,
            Samples::F64(_) => 8,
            Samples::Coloured(_) => std::mem::size_of::<Coloured>(),
        };
        self.stored_dims()
            .iter()
            .product::<usize>()
            .saturating_mul(per)
    }

    /// Whether the volume has no voxel (never true for a loaded volume).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The finite samples at every [`sample_stride`]th index (0, s, 2s, …), ascending: at most
    /// [`SAMPLE_LIMIT`] values, the same ones a streamed file's range pass takes.
    ///
    /// A brick takes the indices of that same stride (of the whole volume) that it owns, so the
    /// bricks' samples together are the whole volume's ([`super::brick`] joins them).
    pub fn strided_sample(&self) -> Vec<f32> {
        let n = self.len();
        let mut out: Vec<f32> = match self.brick {
            None => (0..n)
                .step_by(sample_stride(n))
                .map(|i| self.value(i))
                .filter(|x| x.is_finite())
                .collect(),
            Some(b) => {
                let [nx, ny, _] = self.dims;
                (0..n)
                    .step_by(sample_stride(n))
                    .map(|i| [i % nx, (i / nx) % ny, i / (nx * ny)])
                    .filter(|&g| b.owned.contains(g))
                    .map(|g| self.stored_value(b.stored, g))
                    .filter(|x| x.is_finite())
                    .collect()
            }
        };
        out.sort_by(f32::total_cmp);
        out
    }

    /// Smallest and largest finite sample (of those stored, for a brick); (+∞, −∞) when no
    /// sample is finite.
    pub fn range(&self) -> (f32, f32) {
        // The values' range is the samples' mapped: the map is monotone, and keeps every
        // finite sample finite (`ValueMap::for_range`).
        match self.sample_range() {
            (lo, hi) if lo <= hi => (self.values.apply(lo), self.values.apply(hi)),
            _ => (f32::INFINITY, f32::NEG_INFINITY),
        }
    }

    /// Copies sheet `s` of `axis` (row-major over the other two axes, lower axis fastest) into `out`
    /// as f32.
    pub fn sheet_into(&self, axis: usize, s: usize, out: &mut [f32]) {
        self.sheets_as(axis, s..s + 1, out, |x| x);
    }

    /// Sheets `sheets` of `axis` into `out`, one after another, each as [`Volume::sheet_into`]
    /// writes it: a block read together, which is what sheets along x need to be read fast (see
    /// [`footprint::volume::copy_sheets`]).
    pub fn sheets_into(&self, axis: usize, sheets: std::ops::Range<usize>, out: &mut [f32]) {
        self.sheets_as(axis, sheets, out, |x| x);
    }

    /// Sheets `sheets` of `axis` into `out`, one after another, each sample's value (as f32)
    /// through `to`.
    fn sheets_as<O>(
        &self,
        axis: usize,
        sheets: std::ops::Range<usize>,
        out: &mut [O],
        to: impl Fn(f32) -> O,
    ) {
        match self.brick {
            None => copy_as(&self.samples, self.values, self.dims, axis, sheets, out, to),
            Some(b) => self.brick_sheets_as(b, axis, sheets, out, to),
        }
    }

    /// [`Volume::sheets_as`] for a brick: each whole-volume sheet NaN outside the stored box,
    /// the stored samples inside it.
    fn brick_sheets_as<O>(
        &self,
        b: BrickPlace,
        axis: usize,
        sheets: std::ops::Range<usize>,
        out: &mut [O],
        to: impl Fn(f32) -> O,
    ) {
        let (a, c) = footprint::geometry::in_sheet_axes(axis);
        let (na, len) = (self.dims[a], self.dims[a] * self.dims[c]);
        let sd = b.stored.dims();
        // One stored sheet, its rows swapped into place in the whole sheet.
        let mut part: Vec<O> = (0..sd[a] * sd[c]).map(|_| to(f32::NAN)).collect();
        for (s, sheet) in sheets.zip(out.chunks_exact_mut(len)) {
            sheet.iter_mut().for_each(|x| *x = to(f32::NAN));
            if !(b.stored.lo[axis] <= s && s < b.stored.hi[axis]) {
                continue;
            }
            let local = s - b.stored.lo[axis];
            copy_as(
                &self.samples,
                self.values,
                sd,
                axis,
                local..local + 1,
                &mut part,
                &to,
            );
            for (v, row) in part.chunks_exact_mut(sd[a]).enumerate() {
                let start = (b.stored.lo[c] + v) * na + b.stored.lo[a];
                sheet[start..start + sd[a]].swap_with_slice(row);
            }
        }
    }

    /// Whether the samples carry their own colours (a level of detail's, [`Samples::Coloured`]).
    pub fn is_coloured(&self) -> bool {
        matches!(self.samples, Samples::Coloured(_))
    }

    /// [`Volume::sheet_into`] keeping the colours samples carry (`None` for plain data).
    pub fn coloured_sheet_into(&self, axis: usize, s: usize, out: &mut [Coloured]) {
        use footprint::volume::copy_sheet;
        match &self.samples {
            Samples::Coloured(v) => copy_sheet(v, self.dims, axis, s, out, |x| x),
            _ => self.sheets_as(axis, s..s + 1, out, |value| Coloured {
                value,
                colour: None,
            }),
        }
    }
}

/// Sheets `sheets` of `axis` of `samples` laid out with `dims`, one after another into `out`,
/// each sample's value (as f32, wide samples through `values`) through `to` (the one per-type
/// copy behind every sheet read).
fn copy_as<O>(
    samples: &Samples,
    values: ValueMap,
    d: [usize; 3],
    a: usize,
    s: std::ops::Range<usize>,
    out: &mut [O],
    to: impl Fn(f32) -> O,
) {
    use footprint::volume::copy_sheets;
    match samples {
        Samples::U8(v) => copy_sheets(v, d, a, s, out, |x| to(f32::from(x))),
        Samples::I8(v) => copy_sheets(v, d, a, s, out, |x| to(f32::from(x))),
        Samples::U16(v) => copy_sheets(v, d, a, s, out, |x| to(f32::from(x))),
        Samples::I16(v) => copy_sheets(v, d, a, s, out, |x| to(f32::from(x))),
        Samples::U32(v) => copy_sheets(v, d, a, s, out, |x| to(values.apply(f64::from(x)))),
        Samples::I32(v) => copy_sheets(v, d, a, s, out, |x| to(values.apply(f64::from(x)))),
        Samples::F32(v) => copy_sheets(v, d, a, s, out, &to),
        Samples::F64(v) => copy_sheets(v, d, a, s, out, |x| to(values.apply(x))),
        Samples::Coloured(v) => copy_sheets(v, d, a, s, out, |x| to(x.value)),
    }
}

/// `n` values from `values` in a vector reserved fallibly (see [`crate::io::try_vec`]).
fn collect_n<T>(n: usize, values: impl Iterator<Item = T>) -> Result<Data<T>, String> {
    let mut v = crate::io::try_vec(n, "the samples")?;
    v.extend(values);
    Ok(v.into())
}

/// Decodes `bytes` (exactly `count × size` long) as samples of `ty`; memory refusing the samples
/// is an error naming the bytes, not an abort.
pub fn decode(bytes: &[u8], ty: SampleType, big_endian: bool) -> Result<Samples, String> {
    macro_rules! conv {
        ($t:ty, $variant:ident) => {{
            const N: usize = std::mem::size_of::<$t>();
            Samples::$variant(collect_n(
                bytes.len() / N,
                bytes.chunks_exact(N).map(|c| {
                    let a: [u8; N] = c.try_into().expect("chunk of N bytes");
                    if big_endian {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }
                }),
            )?)
        }};
    }
    Ok(match ty {
        SampleType::U8 => Samples::U8(collect_n(bytes.len(), bytes.iter().copied())?),
        SampleType::I8 => Samples::I8(collect_n(bytes.len(), bytes.iter().map(|&b| b as i8))?),
        SampleType::U16 => conv!(u16, U16),
        SampleType::I16 => conv!(i16, I16),
        SampleType::U32 => conv!(u32, U32),
        SampleType::I32 => conv!(i32, I32),
        SampleType::F32 => conv!(f32, F32),
        SampleType::F64 => conv!(f64, F64),
    })
}

/// Parses whitespace-separated numbers (ASCII data) as samples of `ty`; exactly `count` of them.
/// Memory is reserved for what the text can hold (a number and a separator take at least two
/// bytes), never for the declared `count`, so a header declaring far more samples than the file
/// has costs nothing; memory refusing is an error, not an abort.
pub fn decode_ascii(text: &[u8], ty: SampleType, count: usize) -> Result<Samples, String> {
    let text = std::str::from_utf8(text).map_err(|_| "ASCII data is not text".to_string())?;
    let mut values: Vec<f64> = crate::io::try_vec(count.min(text.len() / 2 + 1), "the samples")?;
    for word in text
        .split(|c: char| c.is_ascii_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
    {
        let v: f64 = word
            .parse()
            .map_err(|_| format!("'{word}' is not a number"))?;
        if values.len() == count {
            return Err(format!("more than the {count} values the header states"));
        }
        // Within the reservation: the text holds at most len / 2 + 1 words.
        values.push(v);
    }
    if values.len() != count {
        return Err(format!("expected {count} values, found {}", values.len()));
    }
    let n = values.len();
    let it = values.iter();
    Ok(match ty {
        SampleType::U8 => Samples::U8(collect_n(n, it.map(|&v| v as u8))?),
        SampleType::I8 => Samples::I8(collect_n(n, it.map(|&v| v as i8))?),
        SampleType::U16 => Samples::U16(collect_n(n, it.map(|&v| v as u16))?),
        SampleType::I16 => Samples::I16(collect_n(n, it.map(|&v| v as i16))?),
        SampleType::U32 => Samples::U32(collect_n(n, it.map(|&v| v as u32))?),
        SampleType::I32 => Samples::I32(collect_n(n, it.map(|&v| v as i32))?),
        SampleType::F32 => Samples::F32(collect_n(n, it.map(|&v| v as f32))?),
        SampleType::F64 => Samples::F64(values.into()),
    })
}

/// Largest volume accepted, voxels (2³²).
pub const MAX_VOXELS: usize = 1 << 32;

/// Bytes for `dims` samples of `ty`, or why not: a zero dimension, or more than [`MAX_VOXELS`].
pub fn byte_len(dims: [usize; 3], ty: SampleType) -> Result<usize, String> {
    if dims.contains(&0) {
        return Err(format!("dims {dims:?}: a dimension is zero"));
    }
    let n = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .filter(|&n| n <= MAX_VOXELS)
        .ok_or_else(|| format!("dims {dims:?}: more than {MAX_VOXELS} voxels"))?;
    Ok(n * ty.size())
}

/// Checks a spacing: finite and positive.
pub fn check_spacing(spacing: [f32; 3]) -> Result<(), String> {
    if spacing.iter().all(|s| s.is_finite() && *s > 0.0) {
        Ok(())
    } else {
        Err(format!("spacing {spacing:?} must be finite and positive"))
    }
}

/// Error with the file's name in front.
pub fn at(path: &Path, what: impl std::fmt::Display) -> CliError {
    CliError::input(format!("{}: {what}", path.display()))
}

/// Most values in a [`Volume::strided_sample`] (2²⁰): percentiles and the default window are taken
/// from these.
pub const SAMPLE_LIMIT: usize = 1 << 20;

/// The stride of the evenly strided sample of `n` values: every `sample_stride(n)`th value.
pub fn sample_stride(n: usize) -> usize {
    n.div_ceil(SAMPLE_LIMIT).max(1)
}

#[cfg(test)]
mod tests {
    use super::{Samples, ValueMap, Volume};

    /// `range` gives, for every sample type, the smallest and largest finite value as f32, the
    /// same as reading each sample through `value`.
    #[test]
    fn range_over_every_sample_type() {
        let vol = |samples: Samples, n: usize| Volume::new([n, 1, 1], [1.0; 3], samples);
        let cases = [
            (vol(Samples::U8(vec![7, 3, 255, 9].into()), 4), (3.0, 255.0)),
            (
                vol(Samples::I8(vec![-128, 5, 127].into()), 3),
                (-128.0, 127.0),
            ),
            (
                vol(Samples::U16(vec![500, 65535, 2].into()), 3),
                (2.0, 65535.0),
            ),
            (
                vol(Samples::I16(vec![-300, 12, 40].into()), 3),
                (-300.0, 40.0),
            ),
            (
                vol(Samples::U32(vec![1 << 30, 6].into()), 2),
                (6.0, (1u32 << 30) as f32),
            ),
            (vol(Samples::I32(vec![-9, 4, -2].into()), 3), (-9.0, 4.0)),
            (
                vol(
                    Samples::F32(vec![f32::NAN, 0.5, f32::INFINITY, -2.5].into()),
                    4,
                ),
                (-2.5, 0.5),
            ),
            // 1e300 is past f32's range: the samples are rebased (not made infinite, so
            // missing, as the third hostile campaign found), and the range is the values'.
            (
                vol(
                    Samples::F64(vec![1e300, 3.0, f64::NEG_INFINITY, 1.5].into()),
                    4,
                ),
                {
                    let m = ValueMap::for_range(1.5, 1e300);
                    assert!(!m.is_identity());
                    (m.apply(1.5), m.apply(1e300))
                },
            ),
            (
                vol(Samples::F64(vec![3.0, f64::NEG_INFINITY, 1.5].into()), 3),
                (1.5, 3.0),
            ),
            (
                vol(Samples::F32(vec![f32::NAN, f32::INFINITY].into()), 2),
                (f32::INFINITY, f32::NEG_INFINITY),
            ),
        ];
        for (v, want) in cases {
            assert_eq!(v.range(), want, "{:?}", v.samples);
            let by_value = (0..v.len()).map(|n| v.value(n)).filter(|x| x.is_finite());
            let folded = by_value.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
            assert_eq!(v.range(), folded);
        }
    }
}
