//! Volume file formats. Each module parses its header with a pure function (`parse_header`, also
//! the fuzz targets' entry point) and loads the samples, validating the header against the data;
//! every error names the file and the field.
//!
//! | extension | module |
//! |---|---|
//! | `.nrrd`, `.nhdr` | [`nrrd`] |
//! | `.vti` | [`vti`] |
//! | `.vtk` | [`vtk`] |
//! | `.mhd`, `.mha` | [`metaimage`] |
//! | `.nii`, `.nii.gz` | [`nifti`] |
//! | anything, with `--dims --type` | [`raw`] |

pub mod compress;
pub mod metaimage;
pub mod nifti;
pub mod nrrd;
pub mod raw;
pub mod vti;
pub mod vtk;

use crate::io::volume::{at, Volume};
use crate::CliError;
use std::path::Path;

/// The formats by extension, for messages.
pub const EXTENSIONS: &str =
    ".nrrd, .nhdr, .vti, .vtk, .mhd, .mha, .nii, .nii.gz, or raw with --dims and --type";

/// Loads `path` by its extension; `raw` options (from `--dims`/`--type`) make it headerless raw.
pub fn load(path: &Path, raw: Option<&raw::RawOptions>) -> Result<Volume, CliError> {
    if let Some(o) = raw {
        return raw::load(path, o);
    }
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let ext = name.rsplit('.').next().unwrap_or("");
    match ext {
        "nrrd" | "nhdr" => nrrd::load(path),
        "vti" => vti::load(path),
        "vtk" => vtk::load(path),
        "mhd" | "mha" => metaimage::load(path),
        "nii" => nifti::load(path),
        "gz" if name.ends_with(".nii.gz") => nifti::load(path),
        _ => Err(at(
            path,
            format!("unknown volume format (use {EXTENSIONS})"),
        )),
    }
}
