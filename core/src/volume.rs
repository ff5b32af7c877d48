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
