//! NRRD (`.nrrd` with attached data, `.nhdr` with a detached data file).
//!
//! Read: magic `NRRD0001`–`NRRD0005`; `type` (every spelling of the spec), `dimension: 3`, `sizes`,
//! `spacings` or `space directions` (a general grid-to-world matrix; `space origin` is accepted and
//! not needed for rendering), `endian`, `encoding` (`raw`, `gzip`/`gz`, `ascii`/`text`/`txt`),
//! `data file` / `datafile` (relative to the header), `line skip` / `lineskip`, `byte skip` /
//! `byteskip` (−1 for raw: the data are the file's last bytes). `#` comments and `key:=value`
//! pairs are ignored; other fields (`kinds`, `centers`, `space`, …) are accepted and ignored.

use super::{compress, numbers, Fields};
use crate::io::volume::{
    at, byte_len, check_spacing, decode, decode_ascii, SampleType, Volume, AXIS_ALIGNED,
};
use crate::CliError;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

/// How the data are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    Raw,
    Gzip,
    Ascii,
}

/// A parsed NRRD header.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub ty: SampleType,
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    pub big_endian: bool,
    pub encoding: Encoding,
    /// The detached data file as written (relative to the header), if any.
    pub data_file: Option<String>,
    pub line_skip: usize,
    /// −1: the data are the last bytes of the (raw) file.
    pub byte_skip: i64,
    /// Bytes of header, including the blank line that ends it (where attached data start).
    pub header_len: usize,
}

/// Parses `(x,y,z)`.
fn vector(s: &str) -> Option<[f32; 3]> {
    let inner = s.trim().strip_prefix('(')?.strip_suffix(')')?;
    let v: Vec<f32> = inner
        .split(',')
        .map(|x| x.trim().parse().ok())
        .collect::<Option<_>>()?;
    (v.len() == 3 && v.iter().all(|x| x.is_finite())).then(|| [v[0], v[1], v[2]])
}

/// Parses a header from the start of `bytes`.
pub fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    if !(bytes.len() >= 8 && bytes.starts_with(b"NRRD000") && (b'1'..=b'5').contains(&bytes[7])) {
        return Err("not an NRRD file (expected magic NRRD0001 to NRRD0005)".into());
    }
    let (fields, header_len) = read_fields(bytes)?;
    let tyname = fields.need("type")?;
    let ty = SampleType::parse(tyname)
        .ok_or_else(|| format!("type: '{tyname}' is not a supported sample type"))?;
    let dimension = fields.need("dimension")?;
    if dimension.trim() != "3" {
        return Err(format!("dimension: expected 3, found '{dimension}'"));
    }
    let sizes = fields.need("sizes")?;
    let dims: Vec<usize> = numbers(sizes, 3, "sizes")?;
    let dims = [dims[0], dims[1], dims[2]];
    byte_len(dims, ty)?;
    let (spacing, directions) = orientation(&fields)?;
    check_spacing(spacing)?;
    if let Some(o) = fields.get(&["space origin"]) {
        vector(o).ok_or_else(|| format!("space origin: '{o}' is not a 3-vector"))?;
    }
    let enc = fields.need("encoding")?;
    let encoding = match enc {
        "raw" => Encoding::Raw,
        "gzip" | "gz" => Encoding::Gzip,
        "ascii" | "text" | "txt" => Encoding::Ascii,
        other => {
            return Err(format!(
                "encoding: '{other}' is not supported (raw, gzip, ascii)"
            ))
        }
    };
    let big_endian = match fields.get(&["endian"]) {
        Some("big") => true,
        Some("little") => false,
        None if ty.size() == 1 || encoding == Encoding::Ascii => false,
        None => {
            return Err(
                "missing header field 'endian' (required for multi-byte binary types)".into(),
            )
        }
        Some(other) => return Err(format!("endian: expected little or big, found '{other}'")),
    };
    let byte_skip = number(&fields, &["byte skip", "byteskip"], "byte skip")?;
    if byte_skip < -1 || (byte_skip == -1 && encoding != Encoding::Raw) {
        return Err(format!(
            "byte skip: {byte_skip} is not allowed with {enc} encoding"
        ));
    }
    let line_skip = number(&fields, &["line skip", "lineskip"], "line skip")?;
    let line_skip =
        usize::try_from(line_skip).map_err(|_| format!("line skip: {line_skip} is negative"))?;
    let data_file = fields.get(&["data file", "datafile"]).map(str::to_string);
    if data_file
        .as_deref()
        .is_some_and(|d| d.starts_with("LIST") || d.contains('%'))
    {
        return Err("data file: lists and formatted file names are not supported".into());
    }
    Ok(Header {
        ty,
        dims,
        spacing,
        directions,
        big_endian,
        encoding,
        data_file,
        line_skip,
        byte_skip,
        header_len,
    })
}

/// The fields of the header at the start of `bytes` (after the magic line, up to the blank
/// line that ends it) and the header's length in bytes, that line included.
fn read_fields(bytes: &[u8]) -> Result<(Fields, usize), String> {
    let mut at = 0;
    let mut fields = Vec::new();
    let mut first = true;
    loop {
        let end = bytes[at..].iter().position(|&b| b == b'\n').map(|p| at + p);
        let line_bytes = &bytes[at..end.unwrap_or(bytes.len())];
        at = end.map_or(bytes.len(), |e| e + 1);
        let line = std::str::from_utf8(line_bytes).map_err(|_| "header is not text".to_string())?;
        let line = line.trim_end_matches('\r');
        if first {
            first = false;
        } else if line.is_empty() {
            break;
        } else if !line.starts_with('#') {
            if let Some((k, v)) = line.split_once(": ") {
                fields.push((k.trim().to_ascii_lowercase(), v.trim().to_string()));
            } else if !line.contains(":=") {
                return Err(format!(
                    "malformed header line '{}'",
                    line.chars().take(60).collect::<String>()
                ));
            }
        }
        if end.is_none() {
            break;
        }
    }
    Ok((Fields(fields), at))
}

/// A whole-number field (0 if absent).
fn number(fields: &Fields, keys: &[&str], name: &str) -> Result<i64, String> {
    fields.get(keys).map_or(Ok(0), |v| {
        v.trim()
            .parse()
            .map_err(|_| format!("{name}: '{v}' is not a whole number"))
    })
}

/// Spacing and axis directions: from `space directions` (three vectors "(x,y,z)",
/// separated by spaces), else `spacings` along the axes, else unit spacing.
fn orientation(fields: &Fields) -> Result<([f32; 3], [[f32; 3]; 3]), String> {
    if let Some(sd) = fields.get(&["space directions"]) {
        let parts: Vec<&str> = sd
            .split(')')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .collect();
        if parts.len() != 3 {
            return Err(format!(
                "space directions: expected 3 vectors, found '{sd}'"
            ));
        }
        let mut spacing = [0.0f32; 3];
        let mut dirs = AXIS_ALIGNED;
        for (c, p) in parts.iter().enumerate() {
            let v = vector(&format!("{p})"))
                .ok_or_else(|| format!("space directions: '{p})' is not a 3-vector"))?;
            (spacing[c], dirs[c]) = super::axis_step(v)
                .ok_or_else(|| format!("space directions: vector {} has zero length", c + 1))?;
        }
        Ok((spacing, dirs))
    } else if let Some(s) = fields.get(&["spacings"]) {
        let v: Vec<f32> = numbers(s, 3, "spacings")?;
        Ok(([v[0], v[1], v[2]], AXIS_ALIGNED))
    } else {
        Ok(([1.0; 3], AXIS_ALIGNED))
    }
}

/// Longest run of bytes `line skip` may pass over, in all (16 MiB): a data file without line
/// breaks (e.g. an endless device) is an error after this much, not a read without end.
const LINE_SKIP_LIMIT: u64 = 16 << 20;

/// Skips `n` lines of `r`; returns the bytes skipped.
fn skip_lines(r: &mut impl BufRead, n: usize) -> Result<u64, String> {
    let mut skipped = 0u64;
    for i in 0..n {
        let mut line = Vec::new();
        let got = (&mut *r)
            .take(LINE_SKIP_LIMIT - skipped)
            .read_until(b'\n', &mut line)
            .map_err(|e| format!("cannot read: {e}"))?;
        skipped += got as u64;
        if line.last() != Some(&b'\n') {
            return Err(if skipped >= LINE_SKIP_LIMIT {
                format!(
                    "line skip: no end of line {} within {LINE_SKIP_LIMIT} bytes",
                    i + 1
                )
            } else {
                format!("line skip: the data have only {i} lines")
            });
        }
    }
    Ok(skipped)
}

/// The file holding the data and the header's view of it.
fn data_source(path: &Path, h: &Header) -> PathBuf {
    match &h.data_file {
        Some(name) => path.parent().unwrap_or(Path::new(".")).join(name),
        None => path.to_path_buf(),
    }
}

/// Loads an NRRD volume.
///
/// The data (attached after the header, or in the detached `data file`) are read as a stream, for
/// exactly the bytes the header declares: `line skip` lines, `byte skip` bytes, then the samples;
/// whatever follows is never read, so a larger or endless data file (e.g. `/dev/zero`) costs only
/// the volume. `byte skip: -1` (the data are the file's last bytes) needs a length, so a regular
/// file. Gzip data are inflated as they are read, and must inflate to exactly what the header
/// declares (more is an error, found one byte past it).
pub fn load(path: &Path) -> Result<Volume, CliError> {
    let bytes = crate::io::read_file(path)?;
    let h = parse_header(&bytes).map_err(|e| at(path, e))?;
    let source = data_source(path, &h);
    let (mut reader, len): (Box<dyn BufRead>, Option<u64>) = if h.data_file.is_some() {
        let d = crate::io::open_data(&source)?;
        (Box::new(d.reader), d.len)
    } else {
        let data = &bytes[h.header_len..];
        (Box::new(data), Some(data.len() as u64))
    };
    let err = |e: String| at(&source, e);
    let need = byte_len(h.dims, h.ty).map_err(err)?;
    let count = need / h.ty.size();
    let skipped = skip_lines(&mut reader, h.line_skip).map_err(err)?;
    let samples = match h.encoding {
        Encoding::Raw => {
            let skip =
                if h.byte_skip == -1 {
                    let len = len.ok_or_else(|| {
                    err("byte skip -1 (data at the end of the file) needs a regular file, whose \
                         length is known"
                        .into())
                })?;
                    len.checked_sub(skipped + need as u64).ok_or_else(|| {
                        err(format!(
                            "header says {}x{}x{} {:?} = {need} bytes, the data have {}",
                            h.dims[0],
                            h.dims[1],
                            h.dims[2],
                            h.ty,
                            len - skipped
                        ))
                    })?
                } else {
                    u64::try_from(h.byte_skip).unwrap_or(0)
                };
            crate::io::skip_exactly(&mut reader, skip, "byte skip").map_err(err)?;
            let body =
                crate::io::read_exactly(&mut reader, need as u64, "the samples").map_err(|e| {
                    err(format!(
                        "header says {}x{}x{} {:?} = {need} bytes: {e}",
                        h.dims[0], h.dims[1], h.dims[2], h.ty
                    ))
                })?;
            if let Some(extra) = len.and_then(|l| l.checked_sub(skipped + skip + need as u64)) {
                crate::io::note_trailing(&source, extra);
            }
            decode(&body, h.ty, h.big_endian).map_err(err)?
        }
        Encoding::Gzip => {
            // Byte skip applies to the decompressed stream.
            let skip = usize::try_from(h.byte_skip).unwrap_or(0);
            let inflated = compress::gunzip_stream(reader, need + skip).map_err(err)?;
            decode(&inflated[skip..], h.ty, h.big_endian).map_err(err)?
        }
        Encoding::Ascii => {
            // A number and its separator take at most 64 bytes of sensible text.
            let limit = len.unwrap_or((count as u64).saturating_mul(64));
            let text = crate::io::read_growing(reader, limit, "the text")
                .map_err(|e| err(compress::read_error(e, "text")))?;
            decode_ascii(&text, h.ty, count).map_err(err)?
        }
    };
    Ok(Volume {
        dims: h.dims,
        spacing: h.spacing,
        directions: h.directions,
        values: crate::io::volume::ValueMap::for_samples(&samples),
        samples,
        brick: None,
        grid: None,
    })
}

/// Where the samples of a raw-encoded NRRD are, and its grid, for streaming.
pub fn raw_layout(path: &Path) -> Result<super::Streamable, CliError> {
    // The header up to its blank line, however long (read_header bounds it), never cut.
    let head = crate::io::read_header(path, |b| {
        b.windows(2).any(|w| w == b"\n\n") || b.windows(3).any(|w| w == b"\n\r\n")
    })?;
    let h = parse_header(&head).map_err(|e| at(path, e))?;
    if h.encoding != Encoding::Raw || h.line_skip != 0 {
        return Err(at(path, "streaming needs raw encoding without line skip"));
    }
    super::raw_data_at(
        path,
        super::RawHeader {
            data_file: h.data_file.as_deref(),
            header_len: h.header_len,
            skip: h.byte_skip,
            dims: h.dims,
            ty: h.ty,
            big_endian: h.big_endian,
            spacing: h.spacing,
            directions: h.directions,
        },
    )
}
