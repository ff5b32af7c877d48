//! Volume file formats. Each module parses its header with a pure function (`parse_header`, also
//! the fuzz targets' entry point) and loads the samples, validating the header against the data;
//! every error names the file and the field.
//!
//! | extension | module |
//! |---|---|
//! | `.nrrd`, `.nhdr` | [`nrrd`] |
//! | `.vti` | [`vti`] |
//! | `.vtr` (a rectilinear grid: per-axis coordinates, [`crate::io::grid`]) | [`vtr`] |
//! | `.vtk` | [`vtk`] |
//! | `.mhd`, `.mha` | [`metaimage`] |
//! | `.nii`, `.nii.gz`, `.hdr` + `.img` / `.img.gz` | [`nifti`] (NIfTI-1, NIfTI-2, Analyze 7.5) |
//! | anything, with `--dims --type` | [`raw`] |

pub mod compress;
pub mod metaimage;
pub mod nifti;
pub mod nrrd;
pub mod raw;
pub mod vti;
pub mod vtk;
pub mod vtr;

use crate::io::stream::Layout;
use crate::io::volume::{at, byte_len, Data, SampleType, Samples, Volume};
use crate::CliError;
use std::path::Path;

/// Parses exactly `n` whitespace-separated numbers of field `what` (for messages).
pub fn numbers<T: std::str::FromStr>(s: &str, n: usize, what: &str) -> Result<Vec<T>, String> {
    let v: Vec<T> = s
        .split_whitespace()
        .map(|x| x.parse().ok())
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{what}: '{s}' is not {n} numbers"))?;
    if v.len() != n {
        return Err(format!("{what}: expected {n} numbers, found {}", v.len()));
    }
    Ok(v)
}

/// A text header's key–value fields in file order (NRRD's `key: value` lines, keys in lower case;
/// MetaImage's `Key = value`): the first field with a key wins.
pub struct Fields(pub Vec<(String, String)>);

impl Fields {
    /// The first field with one of these keys.
    pub fn get(&self, keys: &[&str]) -> Option<&str> {
        self.0
            .iter()
            .find(|(k, _)| keys.contains(&k.as_str()))
            .map(|(_, v)| v.as_str())
    }

    /// Field `k`, which must be there.
    pub fn need(&self, k: &str) -> Result<&str, String> {
        self.get(&[k])
            .ok_or_else(|| format!("missing header field '{k}'"))
    }
}

/// What streaming needs from an uncompressed file's header: where its samples are, and the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Streamable {
    pub layout: Layout,
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
}

/// The dims of a volume of `components` interleaved components per voxel read as scalars (the
/// first axis `components` times longer), for the byte count; an error if that overflows.
pub fn interleaved(dims: [usize; 3], components: usize) -> Result<[usize; 3], String> {
    let wide = dims[0]
        .checked_mul(components)
        .ok_or("the data are too large to address")?;
    Ok([wide, dims[1], dims[2]])
}

/// Why a file of several components per voxel is refused where one is read as a scalar volume.
pub fn several_components(n: usize) -> String {
    format!(
        "{n} components per voxel: `footprint render` classifies them (one --tf per component, or \
         4 as RGBA; docs/components.md), loaded whole; read as one scalar they would render a \
         wrong image"
    )
}

/// Splits samples holding `n` interleaved components per voxel into `n` arrays of one.
pub fn split_components(samples: &Samples, n: usize) -> Vec<Samples> {
    macro_rules! split {
        ($($v:ident),*) => {
            match samples {
                $(Samples::$v(d) => (0..n)
                    .map(|c| Samples::$v(Data::from(
                        d.iter().skip(c).step_by(n).copied().collect::<Vec<_>>(),
                    )))
                    .collect(),)*
                // Never read from a file.
                Samples::Coloured(_) => Vec::new(),
            }
        };
    }
    split!(U8, I8, U16, I16, U32, I32, F32, F64)
}

/// A file's samples of `components` per voxel as volumes on one grid (dims, spacing,
/// directions): one volume, or one per component.
pub fn grid_volumes(
    (dims, spacing, directions): ([usize; 3], [f32; 3], [[f32; 3]; 3]),
    samples: Samples,
    components: usize,
) -> Vec<Volume> {
    let parts = match components {
        1 => vec![samples],
        n => split_components(&samples, n),
    };
    parts
        .into_iter()
        .map(|s| {
            let mut v = Volume::new(dims, spacing, s);
            v.directions = directions;
            v
        })
        .collect()
}

/// A file's one volume, refusing several components (`load_components` reads those).
pub fn scalar(path: &Path, mut parts: Vec<Volume>) -> Result<Volume, CliError> {
    if parts.len() != 1 {
        return Err(at(path, several_components(parts.len())));
    }
    Ok(parts.remove(0))
}

/// The components of a file of 2 to 4 components per voxel (MetaImage, VTK XML image data),
/// each a volume of its own; `None` for a file of one component, or of another format.
pub fn load_components(path: &Path, array: Option<&str>) -> Result<Option<Vec<Volume>>, CliError> {
    match header_format(path) {
        Some("MetaImage") => metaimage::load_components(path),
        Some("VTK XML image data") => vti::load_components(path, array),
        _ => Ok(None),
    }
}

/// Splits a grid axis's world step into (spacing, unit direction); `None` if it is zero or not
/// finite.
pub fn axis_step(v: [f32; 3]) -> Option<(f32, [f32; 3])> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| (len, v.map(|x| x / len)))
}

/// What the header of an uncompressed file says, for [`raw_data_at`].
pub struct RawHeader<'a> {
    pub data_file: Option<&'a str>,
    pub header_len: usize,
    pub skip: i64,
    pub dims: [usize; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
}

/// Where the samples of an uncompressed file are, for streaming: the data file (`data_file`
/// relative to the header at `path`, or `path` itself with the data after `header_len` bytes) and
/// the byte offset `skip` bytes in (−1: the file's last bytes). Checks the file holds them exactly.
pub fn raw_data_at(path: &Path, h: RawHeader<'_>) -> Result<Streamable, CliError> {
    let RawHeader {
        data_file,
        header_len,
        skip,
        dims,
        ty,
        big_endian,
        spacing,
        directions,
    } = h;
    let source = match data_file {
        Some(name) => path.parent().unwrap_or(Path::new(".")).join(name),
        None => path.to_path_buf(),
    };
    let need = byte_len(dims, ty).map_err(|e| at(path, e))? as u64;
    let len = crate::io::regular_file_len(&source)?;
    let start = if data_file.is_some() {
        0
    } else {
        header_len as u64
    };
    let offset = if skip == -1 {
        len.saturating_sub(need)
    } else {
        start + skip.max(0) as u64
    };
    if len != offset + need {
        return Err(at(
            &source,
            format!(
                "expected {need} bytes of data after offset {offset}, the file has {len} bytes"
            ),
        ));
    }
    let layout = Layout {
        path: source,
        offset,
        dims,
        ty,
        big_endian,
        values: crate::io::volume::ValueMap::IDENTITY,
    };
    Ok(Streamable {
        layout,
        spacing,
        directions,
    })
}

/// What [`header_format`] calls a `.vtr`: a rectilinear grid, which renders through per-sample
/// footprints (`args::resolve` has its rules).
pub const RECTILINEAR: &str = "VTK XML rectilinear grid";

/// Whether `path` names a rectilinear grid (a `.vtr`): what the plan's rules read before the
/// file is.
pub fn is_rectilinear(path: &Path) -> bool {
    header_format(path) == Some(RECTILINEAR)
}

/// The formats by extension, for messages.
pub const EXTENSIONS: &str =
    ".nrrd, .nhdr, .vti, .vtr, .vtk, .mhd, .mha, .nii, .nii.gz, .hdr/.img \
     (NIfTI or Analyze pair, either half may be .gz), or raw with --dims and --type";

/// The format `path`'s extension names, if it is one with a header (NRRD, VTK XML image data,
/// legacy VTK, MetaImage, NIfTI); `None` for anything else (raw data, unknown).
pub fn header_format(path: &Path) -> Option<&'static str> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match name.rsplit('.').next().unwrap_or("") {
        "nrrd" | "nhdr" => Some("NRRD"),
        "vti" => Some("VTK XML image data"),
        "vtr" => Some(RECTILINEAR),
        "vtk" => Some("legacy VTK"),
        "mhd" | "mha" => Some("MetaImage"),
        "nii" | "hdr" => Some("NIfTI"),
        "gz" if name.ends_with(".nii.gz") || name.ends_with(".hdr.gz") => Some("NIfTI"),
        // An image file is half of a pair only if its header is beside it; alone it is raw data.
        "img" | "gz" if has_pair_header(path) => Some("NIfTI"),
        _ => None,
    }
}

/// Whether `path` is a `.img` / `.img.gz` with its pair's `.hdr` beside it.
fn has_pair_header(path: &Path) -> bool {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    (lower.ends_with(".img") || lower.ends_with(".img.gz"))
        && nifti::pair_paths(path).is_some_and(|(hdr, _)| hdr.is_file())
}

/// Loads `path` by its extension; `raw` options (from `--dims`/`--type`) make it headerless raw.
pub fn load(path: &Path, raw: Option<&raw::RawOptions>) -> Result<Volume, CliError> {
    load_array(path, raw, None)
}

/// [`load`], rendering the point-data array named `array` of a VTK file (`.vtk`, `.vti`); other
/// formats hold one array, and naming one is an error.
pub fn load_array(
    path: &Path,
    raw: Option<&raw::RawOptions>,
    array: Option<&str>,
) -> Result<Volume, CliError> {
    // Before the extension decides anything: a directory or a special file is named as such.
    crate::io::regular_file_len(path)?;
    let vtk = path.extension().is_some_and(|e| {
        ["vtk", "vti", "vtr"]
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    });
    if array.is_some() && (raw.is_some() || !vtk) {
        return Err(at(
            path,
            "--array picks one of several arrays in a VTK file (.vtk, .vti, .vtr); this format \
             holds one",
        ));
    }
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
        "vti" => vti::load(path, array),
        "vtr" => vtr::load(path, array),
        "vtk" => vtk::load(path, array),
        "mhd" | "mha" => metaimage::load(path),
        "nii" | "hdr" => nifti::load(path),
        "gz" if name.ends_with(".nii.gz") || name.ends_with(".hdr.gz") => nifti::load(path),
        "img" | "gz" if has_pair_header(path) => nifti::load(path),
        _ => Err(at(
            path,
            format!("unknown volume format (use {EXTENSIONS})"),
        )),
    }
}
