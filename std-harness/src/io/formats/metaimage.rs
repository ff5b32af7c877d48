//! MetaImage (`.mhd` with a detached data file, `.mha` with `ElementDataFile = LOCAL`): `NDims = 3`,
//! `DimSize`, `ElementType` (`MET_UCHAR` … `MET_DOUBLE`), `ElementSpacing` (or `ElementSize`),
//! `ElementByteOrderMSB` / `BinaryDataByteOrderMSB`, `CompressedData` (zlib), `HeaderSize`,
//! `TransformMatrix` (row i is grid axis i's direction). `ElementNumberOfChannels` 2 to 4
//! (interleaved components) are read by [`load_components`] alone; [`load`] and streaming refuse
//! them.

use super::{compress, numbers, Fields};
use crate::io::volume::{at, byte_len, check_spacing, decode, SampleType, Volume, AXIS_ALIGNED};
use crate::CliError;
use std::path::{Path, PathBuf};

/// A parsed MetaImage header.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    pub compressed: bool,
    /// `None` for LOCAL (data follow the header).
    pub data_file: Option<String>,
    /// HeaderSize: bytes to skip in the data file (−1: the data are its last bytes).
    pub header_size: i64,
    /// Bytes of header text (where LOCAL data start).
    pub header_len: usize,
    /// `ElementNumberOfChannels`: components per voxel, interleaved (1 to 4).
    pub components: usize,
}

fn is_true(v: &str) -> bool {
    v.eq_ignore_ascii_case("true") || v == "1"
}

/// Parses a MetaImage header from the start of `bytes` (up to and including `ElementDataFile`).
pub fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    let (fields, header_len) = read_fields(bytes)?;
    let get = |keys: &[&str]| fields.get(keys);
    let need = |k: &str| fields.need(k);
    if let Some(t) = get(&["ObjectType"]) {
        if t != "Image" {
            return Err(format!("ObjectType: expected Image, found '{t}'"));
        }
    }
    if need("NDims")? != "3" {
        return Err(format!("NDims: expected 3, found '{}'", need("NDims")?));
    }
    let ds = need("DimSize")?;
    let d: Vec<usize> = numbers(ds, 3, "DimSize")?;
    let dims = [d[0], d[1], d[2]];
    let ty = element_type(need("ElementType")?)?;
    // Several components per voxel lie interleaved in the data (RGBA, channels): 1 to 4.
    let components = match get(&["ElementNumberOfChannels"]).unwrap_or("1") {
        c @ ("1" | "2" | "3" | "4") => c.parse::<usize>().unwrap_or(1),
        c => {
            return Err(format!(
                "ElementNumberOfChannels = {}: 1 to 4 components per voxel are supported",
                c.chars().take(20).collect::<String>()
            ))
        }
    };
    byte_len(super::interleaved(dims, components)?, ty)?;
    let (spacing, directions) = orientation(&fields)?;
    let big_endian = get(&["ElementByteOrderMSB", "BinaryDataByteOrderMSB"]).is_some_and(is_true);
    if get(&["BinaryData"]).is_some_and(|v| !is_true(v)) {
        return Err("BinaryData = False (ASCII MetaImage) is not supported".into());
    }
    let compressed = get(&["CompressedData"]).is_some_and(is_true);
    let header_size: i64 = get(&["HeaderSize"]).map_or(Ok(0), |v| {
        v.parse()
            .map_err(|_| format!("HeaderSize: '{v}' is not a whole number"))
    })?;
    if header_size < -1 || (header_size == -1 && compressed) {
        return Err(format!("HeaderSize: {header_size} is not allowed here"));
    }
    let data_file = match need("ElementDataFile")? {
        "LOCAL" => None,
        f if f.starts_with("LIST") || f.contains('%') => {
            return Err("ElementDataFile: lists and patterns are not supported".into())
        }
        f => Some(f.to_string()),
    };
    Ok(Header {
        dims,
        spacing,
        directions,
        ty,
        big_endian,
        compressed,
        data_file,
        header_size,
        header_len,
        components,
    })
}

/// The sample type an `ElementType` names.
fn element_type(name: &str) -> Result<SampleType, String> {
    Ok(match name {
        "MET_UCHAR" => SampleType::U8,
        "MET_CHAR" => SampleType::I8,
        "MET_USHORT" => SampleType::U16,
        "MET_SHORT" => SampleType::I16,
        "MET_UINT" => SampleType::U32,
        "MET_INT" => SampleType::I32,
        "MET_FLOAT" => SampleType::F32,
        "MET_DOUBLE" => SampleType::F64,
        o => return Err(format!("ElementType: '{o}' is not supported")),
    })
}

/// The fields at the start of `bytes`, up to and including `ElementDataFile` (at most 200),
/// and the bytes of header text they take (where LOCAL data start).
fn read_fields(bytes: &[u8]) -> Result<(Fields, usize), String> {
    let mut at = 0;
    let mut fields: Vec<(String, String)> = Vec::new();
    while at < bytes.len() {
        let end = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| at + p);
        let line = std::str::from_utf8(&bytes[at..end])
            .map_err(|_| "header is not text".to_string())?
            .trim();
        at = (end + 1).min(bytes.len());
        if line.is_empty() {
            continue;
        }
        let (k, v) = line.split_once('=').ok_or_else(|| {
            format!(
                "malformed header line '{}'",
                line.chars().take(60).collect::<String>()
            )
        })?;
        let key = k.trim().to_string();
        fields.push((key.clone(), v.trim().to_string()));
        if key == "ElementDataFile" {
            break;
        }
        if fields.len() > 200 {
            return Err("header has no ElementDataFile".into());
        }
    }
    Ok((Fields(fields), at))
}

/// `ElementSpacing` (or `ElementSize`; default 1) and the axis directions, row i of
/// `TransformMatrix` (or `Rotation`, `Orientation`) grid axis i's.
fn orientation(fields: &Fields) -> Result<([f32; 3], [[f32; 3]; 3]), String> {
    let spacing = match fields.get(&["ElementSpacing", "ElementSize"]) {
        Some(s) => {
            let v: Vec<f32> = numbers(s, 3, "ElementSpacing")?;
            [v[0], v[1], v[2]]
        }
        None => [1.0; 3],
    };
    check_spacing(spacing)?;
    let directions = match fields.get(&["TransformMatrix", "Rotation", "Orientation"]) {
        Some(s) => {
            let v: Vec<f32> = numbers(s, 9, "TransformMatrix")?;
            let mut d = AXIS_ALIGNED;
            for (i, row) in d.iter_mut().enumerate() {
                let r = [v[3 * i], v[3 * i + 1], v[3 * i + 2]];
                *row = super::axis_step(r)
                    .ok_or_else(|| format!("TransformMatrix: row {i} is zero"))?
                    .1;
            }
            d
        }
        None => AXIS_ALIGNED,
    };
    Ok((spacing, directions))
}

/// Loads a MetaImage volume of one component per voxel (more are refused: see
/// [`load_components`]).
pub fn load(path: &Path) -> Result<Volume, CliError> {
    super::scalar(path, load_all(path)?)
}

/// The components of a MetaImage of 2 to 4 components per voxel, each a volume of its own;
/// `None` for one component.
pub fn load_components(path: &Path) -> Result<Option<Vec<Volume>>, CliError> {
    Ok(Some(load_all(path)?).filter(|parts| parts.len() > 1))
}

/// A MetaImage's volumes, one per component.
fn load_all(path: &Path) -> Result<Vec<Volume>, CliError> {
    let (h, samples) = read(path)?;
    Ok(super::grid_volumes(
        (h.dims, h.spacing, h.directions),
        samples,
        h.components,
    ))
}

/// Reads a MetaImage's header and every sample (components interleaved).
///
/// The data (after the header, or in `ElementDataFile`) are read as a stream for exactly the
/// bytes the header declares (`HeaderSize` bytes skipped, then the samples, or a zlib stream
/// inflated to exactly them); what follows is never read, so a larger or endless data file costs
/// only the volume. `HeaderSize = -1` (the data are the file's last bytes) needs a regular file.
fn read(path: &Path) -> Result<(Header, crate::io::volume::Samples), CliError> {
    let bytes = crate::io::read_file(path)?;
    let h = parse_header(&bytes).map_err(|e| at(path, e))?;
    let (source, mut reader, len): (PathBuf, Box<dyn std::io::BufRead>, Option<u64>) =
        match &h.data_file {
            Some(name) => {
                let source = path.parent().unwrap_or(Path::new(".")).join(name);
                let d = crate::io::open_data(&source)?;
                (source, Box::new(d.reader), d.len)
            }
            None => {
                let data = &bytes[h.header_len..];
                (path.to_path_buf(), Box::new(data), Some(data.len() as u64))
            }
        };
    let err = |e: String| at(&source, e);
    let need = super::interleaved(h.dims, h.components)
        .and_then(|d| byte_len(d, h.ty))
        .map_err(err)?;
    let short = |found: u64| {
        err(format!(
            "expected {need} bytes of {}x{}x{} {:?}, found {found}",
            h.dims[0], h.dims[1], h.dims[2], h.ty
        ))
    };
    let skip = if h.header_size == -1 && !h.compressed {
        let len = len.ok_or_else(|| {
            err(
                "HeaderSize = -1 (data at the end of the file) needs a regular file, whose \
                 length is known"
                    .into(),
            )
        })?;
        len.checked_sub(need as u64).ok_or_else(|| short(len))?
    } else {
        u64::try_from(h.header_size).unwrap_or(0)
    };
    crate::io::skip_exactly(&mut reader, skip, "HeaderSize").map_err(err)?;
    if let Some(extra) = len.and_then(|l| l.checked_sub(skip + need as u64)) {
        if !h.compressed {
            crate::io::note_trailing(&source, extra);
        }
    }
    let body = if h.compressed {
        compress::unzlib_stream(reader, need).map_err(err)?
    } else {
        crate::io::read_exactly(reader, need as u64, "the samples").map_err(|e| {
            err(format!(
                "{}x{}x{} {:?} = {need} bytes: {e}",
                h.dims[0], h.dims[1], h.dims[2], h.ty
            ))
        })?
    };
    let samples = decode(&body, h.ty, h.big_endian).map_err(err)?;
    Ok((h, samples))
}

/// Where the samples of an uncompressed MetaImage are, and its grid, for streaming.
pub fn raw_layout(path: &Path) -> Result<super::Streamable, CliError> {
    // The header up to its ElementDataFile line, however long (read_header bounds it).
    let head = crate::io::read_header(path, |b| {
        b.windows(15)
            .position(|w| w == b"ElementDataFile")
            .is_some_and(|at| b[at..].contains(&b'\n'))
    })?;
    let h = parse_header(&head).map_err(|e| at(path, e))?;
    if h.compressed {
        return Err(at(
            path,
            "streaming needs uncompressed data (CompressedData = False)",
        ));
    }
    if h.components != 1 {
        return Err(at(path, super::several_components(h.components)));
    }
    super::raw_data_at(
        path,
        super::RawHeader {
            data_file: h.data_file.as_deref(),
            header_len: h.header_len,
            skip: h.header_size,
            dims: h.dims,
            ty: h.ty,
            big_endian: h.big_endian,
            spacing: h.spacing,
            directions: h.directions,
        },
    )
}
