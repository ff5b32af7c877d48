//! A volume already in memory as a [`SheetSource`]: a `&[T]` with x fastest, then y, then z (a C
//! array `[z][y][x]`, the layout of raw files, NRRD, NIfTI and VTK image data), for any sample
//! type the core shades ([`Sample`]: u8, i8, u16, i16, u32, i32, f32, f64).
//!
//! Sheets are copied out in the renderer's in-sheet layout (row-major over the frame's in-sheet
//! axes, the lower axis fastest; see [`crate::geometry::in_sheet_axes`]), so a caller never needs
//! to know it: hand the volume to [`crate::source::render_from`].

use crate::geometry::in_sheet_axes;
use crate::render::RenderError;
use crate::shade::Sample;
use crate::source::SheetSource;
use core::fmt;

/// Why a slice cannot be a volume of the given dimensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum VolumeError {
    /// A dimension is zero.
    EmptyDimension {
        /// The dimensions given.
        dims: [usize; 3],
    },
    /// The slice's length is not the product of the dimensions (or that product overflows).
    Length {
        /// The dimensions given.
        dims: [usize; 3],
        /// Samples in the slice.
        got: usize,
    },
}

impl fmt::Display for VolumeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::EmptyDimension { dims } => {
                write!(f, "volume dimensions {dims:?} include a zero")
            }
            Self::Length { dims, got } => write!(
                f,
                "volume of {}x{}x{} needs that many samples, the slice holds {got}",
                dims[0], dims[1], dims[2]
            ),
        }
    }
}

impl core::error::Error for VolumeError {}

/// A borrowed in-memory volume (see the [module docs](self)).
#[derive(Clone, Copy, Debug)]
pub struct MemoryVolume<'a, T> {
    data: &'a [T],
    dims: [usize; 3],
}

impl<'a, T: Sample> MemoryVolume<'a, T> {
    /// Wraps `data` (x fastest, then y, then z) as a volume of `dims` = [x, y, z] samples.
    pub fn new(data: &'a [T], dims: [usize; 3]) -> Result<Self, VolumeError> {
        if dims.contains(&0) {
            return Err(VolumeError::EmptyDimension { dims });
        }
        let len = dims[0]
            .checked_mul(dims[1])
            .and_then(|v| v.checked_mul(dims[2]));
        if len != Some(data.len()) {
            return Err(VolumeError::Length {
                dims,
                got: data.len(),
            });
        }
        Ok(MemoryVolume { data, dims })
    }

    /// Dimensions [x, y, z], samples.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The sample at grid index (i, j, k).
    pub fn at(&self, i: usize, j: usize, k: usize) -> T {
        self.data[i + self.dims[0] * (j + self.dims[1] * k)]
    }

    /// The smallest and largest finite sample as f32 (a transfer function's window), or `None`
    /// if no sample is finite.
    pub fn range(&self) -> Option<(f32, f32)> {
        self.data
            .iter()
            .map(|v| v.to_f32())
            .filter(|v| v.is_finite())
            .fold(None, |r, v| match r {
                None => Some((v, v)),
                Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
            })
    }
}

impl<T: Sample> SheetSource for MemoryVolume<'_, T> {
    type Sample = T;
    type Error = RenderError;

    /// Copies sheet `index` along `axis` into `out` (exactly `dims[a] × dims[b]` samples).
    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [T]) -> Result<(), RenderError> {
        let axis = axis.min(2);
        if index >= self.dims[axis] {
            return Err(RenderError::SheetIndex {
                index,
                count: self.dims[axis],
            });
        }
        let (a, b) = in_sheet_axes(axis);
        let (na, nb) = (self.dims[a], self.dims[b]);
        if out.len() != na * nb {
            return Err(RenderError::SheetLength {
                expected: na * nb,
                got: out.len(),
            });
        }
        copy_sheet(self.data, self.dims, axis, index, out, |x| x);
        Ok(())
    }
}

/// Copies sheet `index` along grid axis `axis` of `data` (a `dims` volume, x fastest) into the
/// first `dims[a] × dims[b]` entries of `out`, row-major over the in-sheet axes (a, b) =
/// [`in_sheet_axes`]`(axis)` with a fastest, converting each sample with `convert`. Panics if
/// `index` or `out` does not fit (callers check: [`MemoryVolume`] returns typed errors).
pub fn copy_sheet<T: Copy, U>(
    data: &[T],
    dims: [usize; 3],
    axis: usize,
    index: usize,
    out: &mut [U],
    convert: impl Fn(T) -> U,
) {
    let (a, b) = in_sheet_axes(axis);
    let (na, nb) = (dims[a], dims[b]);
    let stride = [1, dims[0], dims[0] * dims[1]];
    let base = index * stride[axis];
    for (v, row) in out[..na * nb].chunks_exact_mut(na).enumerate() {
        let start = base + v * stride[b];
        if stride[a] == 1 {
            for (o, &x) in row.iter_mut().zip(&data[start..start + na]) {
                *o = convert(x);
            }
        } else {
            for (u, o) in row.iter_mut().enumerate() {
                *o = convert(data[start + u * stride[a]]);
            }
        }
    }
}

/// [`copy_sheet`] of the consecutive sheets `sheets` along `axis` (count = `sheets.len()`), into
/// the first `count × dims[a] × dims[b]` entries of `out`, sheet after sheet, each laid out as
/// [`copy_sheet`] lays it out (so the result is bit for bit `count` calls of it).
///
/// It reads the `count` samples each in-sheet position has along `axis` together. That matters
/// for `axis` 0, where those samples are adjacent in memory and one sheet's samples are `dims[0]`
/// apart: one sheet at a time uses one sample of each cache line it loads, `count` sheets at a
/// time use `count`. Panics, before writing anything, if `sheets` ends past `dims[axis]` or `out`
/// is too short (callers check, as for [`copy_sheet`]).
pub fn copy_sheets<T: Copy, U>(
    data: &[T],
    dims: [usize; 3],
    axis: usize,
    sheets: core::ops::Range<usize>,
    out: &mut [U],
    convert: impl Fn(T) -> U,
) {
    let (a, b) = in_sheet_axes(axis);
    let (na, nb) = (dims[a], dims[b]);
    let len = na * nb;
    let count = sheets.len();
    assert!(
        sheets.end <= dims[axis],
        "sheets {sheets:?} past the {} along axis {axis}",
        dims[axis]
    );
    let stride = [1, dims[0], dims[0] * dims[1]];
    let out = &mut out[..count * len];
    if axis != 0 {
        for (k, sheet) in out.chunks_exact_mut(len.max(1)).enumerate() {
            copy_sheet(data, dims, axis, sheets.start + k, sheet, &convert);
        }
        return;
    }
    // Along x: the samples of sheets `sheets` at each (y, z) are one run of `count` samples.
    // Written a tile of TILE positions along y per sheet: writing each run across the `count`
    // sheets at once would store to `count` places a sheet apart, which share cache sets when the
    // sheet's size is a multiple of 4 KiB (256 × 256 f32: measured 72 ms for the blobs' sheets
    // along x against 39 ms tiled).
    const TILE: usize = 16;
    let base = sheets.start;
    for v in 0..nb {
        for u0 in (0..na).step_by(TILE) {
            let tile = TILE.min(na - u0);
            let at = v * na + u0;
            let first = base + v * stride[b] + u0 * stride[a];
            for (k, row) in out.chunks_exact_mut(len).enumerate() {
                for (t, o) in row[at..at + tile].iter_mut().enumerate() {
                    *o = convert(data[first + t * stride[a] + k]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{copy_sheet, copy_sheets};

    /// Sheets past the volume's end along x are refused, not read from the next row.
    #[test]
    #[should_panic(expected = "past the 5 along axis 0")]
    fn copy_sheets_refuses_sheets_past_the_end() {
        let data = [0u8; 5 * 7 * 3];
        let mut out = [0u8; 3 * 7 * 3];
        copy_sheets(&data, [5, 7, 3], 0, 3..6, &mut out, |x| x);
    }

    /// A block of sheets is, bit for bit, the sheets one at a time: every axis, blocks at the
    /// start, middle and end, dimensions around the tile width (the largest volume is 17 × 33 × 4
    /// = 2244 samples).
    #[test]
    fn copy_sheets_is_copy_sheet_repeated() {
        for dims in [[5, 7, 3], [17, 33, 4], [40, 16, 2], [1, 1, 1]] {
            let data: [u16; 2244] = core::array::from_fn(|n| (n * 37 % 251) as u16);
            let data = &data[..dims[0] * dims[1] * dims[2]];
            for axis in 0..3 {
                let (a, b) = crate::geometry::in_sheet_axes(axis);
                let len = dims[a] * dims[b];
                let n = dims[axis];
                for sheets in [0..n, 0..1, n / 2..n, n - 1..n, 1.min(n)..(3.min(n))] {
                    let mut block = [0u32; 3000];
                    copy_sheets(data, dims, axis, sheets.clone(), &mut block, u32::from);
                    for (k, s) in sheets.clone().enumerate() {
                        let mut one = [0u32; 700];
                        copy_sheet(data, dims, axis, s, &mut one, u32::from);
                        assert_eq!(
                            block[k * len..(k + 1) * len],
                            one[..len],
                            "dims {dims:?} axis {axis} sheets {sheets:?} sheet {s}"
                        );
                    }
                    assert!(block[sheets.len() * len..].iter().all(|&x| x == 0));
                }
            }
        }
    }
}
