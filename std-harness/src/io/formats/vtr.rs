//! VTK XML RectilinearGrid (`.vtr`): one piece whose point data are read as a `.vti`'s are
//! ([`super::vti`]: every format, compressor, header type and byte order, one component), and
//! whose `Coordinates` hold three one-component arrays, the x, y and z coordinate of every
//! sample along each axis (any numeric type, any format). The coordinates must be finite and
//! strictly increasing ([`crate::io::grid::Coordinates`] says why and what is refused); the
//! volume gets their mean spacing and carries them ([`Volume::grid`]).

use super::vti::{array_samples, parse_dataset, Appended, Header};
use crate::io::grid::Coordinates;
use crate::io::volume::{at, byte_len, Samples, Volume, AXIS_ALIGNED};
use crate::CliError;
use std::path::Path;

/// The dataset a `.vtr` holds.
const KIND: &str = "RectilinearGrid";

/// Parses the XML of a `.vtr` (the appended section, if any, returned separately): the point-data
/// array named `array` (default as for a `.vti`), and the coordinate arrays.
pub fn parse_header_array<'a>(
    bytes: &'a [u8],
    array: Option<&str>,
) -> Result<(Header, Option<Appended<'a>>), String> {
    parse_dataset(bytes, array, KIND)
}

/// Loads a `.vtr` volume: the point-data array named `array` (or the default) on its grid.
pub fn load(path: &Path, array: Option<&str>) -> Result<Volume, CliError> {
    let bytes = crate::io::read_file(path)?;
    let err = |e: String| at(path, e);
    let (h, appended) = parse_header_array(&bytes, array).map_err(err)?;
    let need = super::interleaved(h.dims, h.components)
        .and_then(|d| byte_len(d, h.ty))
        .map_err(err)?;
    let samples = array_samples(&h, appended, (h.ty, &h.format), need).map_err(err)?;
    let mut axes: [Vec<f64>; 3] = Default::default();
    for (a, (ty, format)) in h.coordinates.iter().enumerate() {
        let need = byte_len([h.dims[a], 1, 1], *ty).map_err(err)?;
        let values = array_samples(&h, appended, (*ty, format), need)
            .map_err(|e| err(format!("{} coordinates: {e}", ["x", "y", "z"][a])))?;
        axes[a] = wide(&values);
    }
    let grid = Coordinates::new(axes, h.dims).map_err(err)?;
    let geometry = (h.dims, grid.mean_spacing(), AXIS_ALIGNED);
    let mut volume = super::scalar(path, super::grid_volumes(geometry, samples, h.components))?;
    volume.grid = Some(std::sync::Arc::new(grid));
    Ok(volume)
}

/// Every sample as f64 (coordinates: an f32 would merge close ones far from the origin).
fn wide(s: &Samples) -> Vec<f64> {
    fn all<T: Copy + Into<f64>>(v: &[T]) -> Vec<f64> {
        v.iter().map(|&x| x.into()).collect()
    }
    match s {
        Samples::U8(v) => all(v),
        Samples::I8(v) => all(v),
        Samples::U16(v) => all(v),
        Samples::I16(v) => all(v),
        Samples::U32(v) => all(v),
        Samples::I32(v) => all(v),
        Samples::F32(v) => all(v),
        Samples::F64(v) => all(v),
        // Never decoded from a file.
        Samples::Coloured(_) => Vec::new(),
    }
}
