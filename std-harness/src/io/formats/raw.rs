//! Headerless raw volumes: x fastest, dimensions, type, byte order and spacing from the command
//! line.

use crate::io::volume::{at, byte_len, check_spacing, decode, SampleType, Volume};
use crate::CliError;
use std::path::Path;

/// What the command line says about a raw file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawOptions {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Sample type.
    pub ty: SampleType,
    /// Byte order.
    pub big_endian: bool,
    /// World units per voxel.
    pub spacing: [f32; 3],
}

/// Reads a headerless raw volume; its size must be exactly what the options say.
pub fn load(path: &Path, o: &RawOptions) -> Result<Volume, CliError> {
    let need = byte_len(o.dims, o.ty).map_err(|e| at(path, e))?;
    check_spacing(o.spacing).map_err(|e| at(path, e))?;
    let bytes = crate::io::read_file(path)?;
    if bytes.len() != need {
        return Err(at(
            path,
            format!(
                "expected {need} bytes for {}x{}x{} {:?}, found {}",
                o.dims[0],
                o.dims[1],
                o.dims[2],
                o.ty,
                bytes.len()
            ),
        ));
    }
    Ok(Volume::new(
        o.dims,
        o.spacing,
        decode(&bytes, o.ty, o.big_endian).map_err(|e| at(path, e))?,
    ))
}
