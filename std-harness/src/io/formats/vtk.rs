//! Legacy VTK (`.vtk`) `DATASET STRUCTURED_POINTS`, ASCII or BINARY (big-endian, as the format
//! requires): `DIMENSIONS`, `SPACING` (or the older `ASPECT_RATIO`), `ORIGIN`, `POINT_DATA`,
//! `SCALARS name type [1]`, `LOOKUP_TABLE`.

use crate::io::volume::{at, byte_len, check_spacing, decode, decode_ascii, SampleType, Volume};
use crate::CliError;
use std::path::Path;

/// A parsed legacy header and where its data start.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub ty: SampleType,
    pub binary: bool,
    /// Byte offset of the first data byte.
    pub data_start: usize,
}

/// Parses the header of a legacy `.vtk` file.
pub fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    let mut lines = Vec::new();
    let mut at = 0;
    // The header is line-oriented: read lines until LOOKUP_TABLE (which ends it).
    while at < bytes.len() && lines.len() < 64 {
        let end = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| at + p);
        let line = std::str::from_utf8(&bytes[at..end])
            .map_err(|_| "header is not text".to_string())?
            .trim()
            .to_string();
        at = (end + 1).min(bytes.len());
        let done = line.to_ascii_uppercase().starts_with("LOOKUP_TABLE");
        lines.push(line);
        if done {
            break;
        }
    }
    if !lines
        .first()
        .is_some_and(|l| l.starts_with("# vtk DataFile"))
    {
        return Err("not a legacy VTK file (expected '# vtk DataFile Version')".into());
    }
    if lines.len() < 3 {
        return Err("header ends early".into());
    }
    let binary = match lines[2].to_ascii_uppercase().as_str() {
        "ASCII" => false,
        "BINARY" => true,
        o => return Err(format!("line 3: expected ASCII or BINARY, found '{o}'")),
    };
    let (mut dims, mut spacing, mut ty, mut points, mut dataset, mut lut) =
        (None, None, None, None, None, false);
    for line in &lines[3..] {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(key) = words.first() else { continue };
        let nums = |n: usize| -> Result<Vec<f64>, String> {
            let v: Vec<f64> = words[1..]
                .iter()
                .map(|w| w.parse().ok())
                .collect::<Option<_>>()
                .ok_or_else(|| format!("{key}: '{line}' has a non-number"))?;
            if v.len() != n {
                return Err(format!("{key}: expected {n} numbers, found {}", v.len()));
            }
            Ok(v)
        };
        match key.to_ascii_uppercase().as_str() {
            "DATASET" => dataset = words.get(1).map(|s| s.to_ascii_uppercase()),
            "DIMENSIONS" => {
                let v = nums(3)?;
                if v.iter()
                    .any(|&x| !(x >= 1.0 && x.fract() == 0.0 && x < 1e12))
                {
                    return Err(format!(
                        "DIMENSIONS: '{line}' are not positive whole numbers"
                    ));
                }
                dims = Some([v[0] as usize, v[1] as usize, v[2] as usize]);
            }
            "SPACING" | "ASPECT_RATIO" => {
                let v = nums(3)?;
                spacing = Some([v[0] as f32, v[1] as f32, v[2] as f32]);
            }
            "ORIGIN" => {
                nums(3)?;
            }
            "POINT_DATA" => {
                let v = nums(1)?;
                points = Some(v[0]);
            }
            "SCALARS" => {
                let t = words.get(2).ok_or("SCALARS: missing type")?;
                if let Some(c) = words.get(3) {
                    if *c != "1" {
                        return Err(format!("SCALARS: {c} components (only 1 is supported)"));
                    }
                }
                ty = Some(match *t {
                    "unsigned_char" | "bit" => SampleType::U8,
                    "char" => SampleType::I8,
                    "unsigned_short" => SampleType::U16,
                    "short" => SampleType::I16,
                    "unsigned_int" => SampleType::U32,
                    "int" => SampleType::I32,
                    "float" => SampleType::F32,
                    "double" => SampleType::F64,
                    o => return Err(format!("SCALARS: type '{o}' is not supported")),
                });
            }
            "LOOKUP_TABLE" => lut = true,
            "CELL_DATA" | "FIELD" | "VECTORS" | "NORMALS" => {
                return Err(format!("{key} before the scalars is not supported"))
            }
            _ => {}
        }
    }
    if dataset.as_deref() != Some("STRUCTURED_POINTS") {
        return Err(format!(
            "DATASET: expected STRUCTURED_POINTS, found {}",
            dataset.as_deref().unwrap_or("none")
        ));
    }
    let dims = dims.ok_or("missing DIMENSIONS")?;
    let ty = ty.ok_or("missing SCALARS")?;
    if !lut {
        return Err("missing LOOKUP_TABLE after SCALARS".into());
    }
    let n = byte_len(dims, ty)? / ty.size();
    if points != Some(n as f64) {
        return Err(format!(
            "POINT_DATA: expected {n} (the DIMENSIONS' product), found {points:?}"
        ));
    }
    let spacing = spacing.unwrap_or([1.0; 3]);
    check_spacing(spacing)?;
    Ok(Header {
        dims,
        spacing,
        ty,
        binary,
        data_start: at,
    })
}

/// Loads a legacy `.vtk` volume.
pub fn load(path: &Path) -> Result<Volume, CliError> {
    let bytes = crate::io::read_file(path)?;
    let h = parse_header(&bytes).map_err(|e| at(path, e))?;
    let need = byte_len(h.dims, h.ty).map_err(|e| at(path, e))?;
    let data = &bytes[h.data_start..];
    let samples = if h.binary {
        // Anything after the samples (a trailing newline, further sections) is ignored.
        let body = data.get(..need).ok_or_else(|| {
            at(
                path,
                format!(
                    "binary data truncated: need {need} bytes, found {}",
                    data.len()
                ),
            )
        })?;
        decode(body, h.ty, true).map_err(|e| at(path, e))?
    } else {
        // ASCII: exactly the point count, then anything that is not a number ends the data.
        let end = data
            .windows(2)
            .position(|w| w[0] == b'\n' && w[1].is_ascii_alphabetic())
            .map_or(data.len(), |p| p + 1);
        decode_ascii(&data[..end], h.ty, need / h.ty.size()).map_err(|e| at(path, e))?
    };
    Ok(Volume::new(h.dims, h.spacing, samples))
}
