//! VTK XML ImageData (`.vti`): one piece, point data, one component; `format` ascii, binary
//! (base64 inline) or appended (raw or base64); uncompressed or compressed by any of VTK 9's three
//! compressors (`vtkZLibDataCompressor`, `vtkLZ4DataCompressor`, `vtkLZMADataCompressor`); header
//! type UInt32 or UInt64; either byte order; `Spacing` and `Direction` (row-major) give the grid.

use super::{compress, numbers};
use crate::io::volume::{
    at, byte_len, check_spacing, decode, decode_ascii, SampleType, Volume, AXIS_ALIGNED,
};
use crate::CliError;
use base64::Engine as _;
use std::path::Path;

/// Decodes base64 text that may be several separately padded streams back to back (VTK encodes
/// a compressed array's header and its blocks separately), ignoring whitespace.
fn base64_segments(text: &[u8]) -> Result<Vec<u8>, String> {
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|b| !b.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    let mut start = 0;
    let mut i = 0;
    while i < clean.len() {
        if clean[i] == b'=' {
            while i < clean.len() && clean[i] == b'=' {
                i += 1;
            }
            base64::engine::general_purpose::STANDARD
                .decode_vec(&clean[start..i], &mut out)
                .map_err(|e| format!("bad base64 data: {e}"))?;
            start = i;
        } else {
            i += 1;
        }
    }
    if start < clean.len() {
        base64::engine::general_purpose::STANDARD
            .decode_vec(&clean[start..], &mut out)
            .map_err(|e| format!("bad base64 data: {e}"))?;
    }
    Ok(out)
}

/// What the XML says about the image and its data array.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    pub header64: bool,
    pub compressor: Compressor,
    pub format: Format,
    /// `NumberOfComponents`: components per point, interleaved (1 to 4).
    pub components: usize,
    /// A `RectilinearGrid`'s coordinate arrays (x, y, z: type and where), empty for an image.
    pub coordinates: Vec<(SampleType, Format)>,
}

/// How each data block is compressed (the `compressor` attribute of `VTKFile`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compressor {
    /// No `compressor` attribute: one header word (the byte count), then the data.
    None,
    /// `vtkZLibDataCompressor`: a zlib stream per block.
    Zlib,
    /// `vtkLZ4DataCompressor`: an LZ4 block (no frame) per block.
    Lz4,
    /// `vtkLZMADataCompressor`: an `.xz` stream per block.
    Lzma,
}

/// Where the array's data are.
#[derive(Clone, Debug, PartialEq)]
pub enum Format {
    /// Whitespace-separated numbers inside the DataArray.
    Ascii(Vec<u8>),
    /// Base64 inside the DataArray.
    Binary(Vec<u8>),
    /// In the AppendedData section at this offset.
    Appended { offset: usize },
}

/// The AppendedData section: its bytes after the `_` marker, and whether they are raw (not base64).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Appended<'a> {
    pub bytes: &'a [u8],
    pub raw: bool,
}

/// Splits a file at `<AppendedData`: the XML text, and the appended section if there is one.
fn split_appended(bytes: &[u8]) -> Result<(String, Option<Appended<'_>>), String> {
    let tag = b"<AppendedData";
    match bytes.windows(tag.len()).position(|w| w == tag) {
        None => Ok((
            String::from_utf8(bytes.to_vec()).map_err(|_| "XML is not UTF-8 text".to_string())?,
            None,
        )),
        Some(p) => {
            let head = std::str::from_utf8(&bytes[..p])
                .map_err(|_| "XML is not UTF-8 text".to_string())?;
            let rest = &bytes[p..];
            let gt = rest
                .iter()
                .position(|&b| b == b'>')
                .ok_or("AppendedData tag is not closed")?;
            let open =
                std::str::from_utf8(&rest[..gt]).map_err(|_| "AppendedData tag is not text")?;
            let raw = !open.contains("base64");
            let body = &rest[gt + 1..];
            let us = body
                .iter()
                .position(|&b| b == b'_')
                .ok_or("AppendedData has no '_' marker")?;
            Ok((
                format!("{head}</VTKFile>"),
                Some(Appended {
                    bytes: &body[us + 1..],
                    raw,
                }),
            ))
        }
    }
}

/// Deepest element nesting a `.vti` may have. VTK writes 5 levels (VTKFile, ImageData, Piece,
/// PointData, DataArray); the XML parser recurses per level, so a file nested thousands deep
/// would exhaust the stack. Checked by [`check_depth`] before parsing.
pub const MAX_XML_DEPTH: usize = 64;

/// Refuses XML nested deeper than `limit` elements, by a linear scan that never recurses: start
/// tags (`<name …>`, not `</…>`, `<?…?>`, `<!…>` or self-closing `…/>`) open a level, end tags
/// close one; quoted attribute values, comments and CDATA are skipped.
pub fn check_depth(xml: &str, limit: usize) -> Result<(), String> {
    let b = xml.as_bytes();
    let (mut i, mut depth) = (0usize, 0usize);
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &xml[i..];
        if rest.starts_with("<!--") {
            i += rest.find("-->").map_or(b.len() - i, |e| e + 3);
            continue;
        }
        if rest.starts_with("<![CDATA[") {
            i += rest.find("]]>").map_or(b.len() - i, |e| e + 3);
            continue;
        }
        let closing = rest.starts_with("</");
        let special = rest.starts_with("<?") || rest.starts_with("<!");
        // Find this tag's '>' outside quotes.
        let mut j = i + 1;
        let mut quote = 0u8;
        while j < b.len() {
            match (quote, b[j]) {
                (0, b'"' | b'\'') => quote = b[j],
                (q, c) if q != 0 && c == q => quote = 0,
                (0, b'>') => break,
                _ => {}
            }
            j += 1;
        }
        let self_closing = j > i && b[j - 1] == b'/';
        if closing {
            depth = depth.saturating_sub(1);
        } else if !special && !self_closing {
            depth += 1;
            if depth > limit {
                return Err(format!(
                    "XML nested deeper than {limit} elements (a VTK image file needs 5)"
                ));
            }
        }
        i = j + 1;
    }
    Ok(())
}

/// Parses the XML of a `.vti` (the appended section, if any, is returned separately).
pub fn parse_header(bytes: &[u8]) -> Result<(Header, Option<Appended<'_>>), String> {
    parse_header_array(bytes, None)
}

/// [`parse_header`], choosing the point-data array named `array` (default: the `Scalars`
/// attribute's, else the first); a name the file lacks is an error listing its arrays.
pub fn parse_header_array<'a>(
    bytes: &'a [u8],
    array: Option<&str>,
) -> Result<(Header, Option<Appended<'a>>), String> {
    parse_dataset(bytes, array, "ImageData")
}

/// [`parse_header_array`] of a VTK XML file of dataset `kind`: `ImageData`, or
/// `RectilinearGrid` (`super::vtr`; its coordinate arrays in [`Header::coordinates`], its
/// spacing 1).
pub(super) fn parse_dataset<'a>(
    bytes: &'a [u8],
    array: Option<&str>,
    kind: &str,
) -> Result<(Header, Option<Appended<'a>>), String> {
    let (xml, appended) = split_appended(bytes)?;
    check_depth(&xml, MAX_XML_DEPTH)?;
    let doc = roxmltree::Document::parse(&xml).map_err(|e| format!("not valid XML: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "VTKFile" || root.attribute("type") != Some(kind) {
        return Err(format!(
            "not a VTK XML {kind} file (VTKFile type=\"{kind}\")"
        ));
    }
    let (big_endian, header64, compressor) = encoding(root)?;
    let image = root
        .children()
        .find(|n| n.has_tag_name(kind))
        .ok_or_else(|| format!("no {kind} element"))?;
    let (dims, spacing, directions) = geometry(image)?;
    let (ty, format, components) = data_array(choose_array(image, array)?)?;
    let coordinates = if kind == "RectilinearGrid" {
        coordinate_arrays(image)?
    } else {
        Vec::new()
    };
    byte_len(super::interleaved(dims, components)?, ty)?;
    if matches!(format, Format::Appended { .. }) && appended.is_none() {
        return Err("appended DataArray but no AppendedData section".into());
    }
    Ok((
        Header {
            dims,
            spacing,
            directions,
            ty,
            big_endian,
            header64,
            compressor,
            format,
            components,
            coordinates,
        },
        appended,
    ))
}

type Node<'a, 'input> = roxmltree::Node<'a, 'input>;

/// The `VTKFile` element's byte order (big-endian?), header width (64-bit?) and compressor.
fn encoding(root: Node<'_, '_>) -> Result<(bool, bool, Compressor), String> {
    let big_endian = match root.attribute("byte_order") {
        Some("BigEndian") => true,
        Some("LittleEndian") | None => false,
        Some(o) => {
            return Err(format!(
                "byte_order: '{o}' is not LittleEndian or BigEndian"
            ))
        }
    };
    let header64 = match root.attribute("header_type") {
        Some("UInt64") => true,
        Some("UInt32") | None => false,
        Some(o) => return Err(format!("header_type: '{o}' is not UInt32 or UInt64")),
    };
    let compressor = match root.attribute("compressor") {
        None | Some("") => Compressor::None,
        Some("vtkZLibDataCompressor") => Compressor::Zlib,
        Some("vtkLZ4DataCompressor") => Compressor::Lz4,
        Some("vtkLZMADataCompressor") => Compressor::Lzma,
        Some(o) => {
            return Err(format!(
                "compressor: '{o}' is not one of VTK's (vtkZLibDataCompressor, \
                 vtkLZ4DataCompressor, vtkLZMADataCompressor)"
            ))
        }
    };
    Ok((big_endian, header64, compressor))
}

/// Dimensions, spacing and axis directions.
type Geometry = ([usize; 3], [f32; 3], [[f32; 3]; 3]);

/// The `ImageData` element's dimensions (from `WholeExtent`), spacing and axis directions.
fn geometry(image: Node<'_, '_>) -> Result<Geometry, String> {
    let extent: Vec<i64> = numbers(
        image.attribute("WholeExtent").ok_or("no WholeExtent")?,
        6,
        "WholeExtent",
    )?;
    let mut dims = [0usize; 3];
    for a in 0..3 {
        // Checked: an extent near the ends of i64 must not wrap into a small volume.
        let d = extent[2 * a + 1]
            .checked_sub(extent[2 * a])
            .and_then(|d| d.checked_add(1))
            .ok_or_else(|| format!("WholeExtent: axis {a} spans more than 2^63 points"))?;
        dims[a] = usize::try_from(d)
            .ok()
            .filter(|&d| d > 0)
            .ok_or_else(|| format!("WholeExtent: axis {a} is empty"))?;
    }
    let spacing: Vec<f32> = match image.attribute("Spacing") {
        Some(s) => numbers(s, 3, "Spacing")?,
        None => vec![1.0; 3],
    };
    let spacing = [spacing[0], spacing[1], spacing[2]];
    check_spacing(spacing)?;
    let directions = match image.attribute("Direction") {
        // Row-major 3×3 whose columns are the axis directions.
        Some(s) => {
            let m: Vec<f32> = numbers(s, 9, "Direction")?;
            let mut d = AXIS_ALIGNED;
            for (c, col) in d.iter_mut().enumerate() {
                let v = [m[c], m[3 + c], m[6 + c]];
                *col = super::axis_step(v)
                    .ok_or_else(|| format!("Direction: column {c} is zero"))?
                    .1;
            }
            d
        }
        None => AXIS_ALIGNED,
    };
    Ok((dims, spacing, directions))
}

/// The one piece's point-data array named `array`, else the `Scalars` attribute's, else the
/// first.
fn choose_array<'a, 'input>(
    image: Node<'a, 'input>,
    array: Option<&str>,
) -> Result<Node<'a, 'input>, String> {
    let pieces: Vec<_> = image
        .children()
        .filter(|n| n.has_tag_name("Piece"))
        .collect();
    if pieces.len() != 1 {
        return Err(format!("expected one Piece, found {}", pieces.len()));
    }
    let (point_data, arrays) = arrays_in(pieces[0], "PointData", "Piece has no PointData")?;
    let names = || {
        arrays
            .iter()
            .map(|a| a.attribute("Name").unwrap_or("(unnamed)"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let named = |name: &str| arrays.iter().find(|a| a.attribute("Name") == Some(name));
    let found = match (array, point_data.attribute("Scalars")) {
        (Some(name), _) => named(name)
            .ok_or_else(|| format!("no point-data array '{name}' (the file has: {})", names()))?,
        (None, Some(name)) => named(name)
            .or(arrays.first())
            .ok_or("PointData has no scalar DataArray")?,
        (None, None) => arrays.first().ok_or("PointData has no scalar DataArray")?,
    };
    Ok(*found)
}

/// An element and the `DataArray`s in it.
type Arrays<'a, 'input> = (Node<'a, 'input>, Vec<Node<'a, 'input>>);
/// `piece`'s child element `tag` and the `DataArray`s in it; `missing` where it has none.
fn arrays_in<'a, 'input>(
    piece: Node<'a, 'input>,
    tag: &str,
    missing: &str,
) -> Result<Arrays<'a, 'input>, String> {
    let holder = piece
        .children()
        .find(|n| n.has_tag_name(tag))
        .ok_or(missing)?;
    let arrays = holder
        .children()
        .filter(|n| n.has_tag_name("DataArray"))
        .collect();
    Ok((holder, arrays))
}

/// The `RectilinearGrid` element's coordinate arrays: its one piece's `Coordinates`, exactly
/// three `DataArray`s of one component (x, y, z), each's type and where its values are.
fn coordinate_arrays(grid: Node<'_, '_>) -> Result<Vec<(SampleType, Format)>, String> {
    let piece = grid
        .children()
        .find(|n| n.has_tag_name("Piece"))
        .ok_or("no Piece")?;
    let (_, arrays) = arrays_in(
        piece,
        "Coordinates",
        "Piece has no Coordinates (a RectilinearGrid needs its x, y and z coordinates)",
    )?;
    if arrays.len() != 3 {
        return Err(format!(
            "Coordinates hold {} DataArrays, expected 3 (x, y, z)",
            arrays.len()
        ));
    }
    arrays
        .iter()
        .zip(["x", "y", "z"])
        .map(|(a, name)| {
            let (ty, format, components) = data_array(*a)?;
            if components != 1 {
                return Err(format!(
                    "{name} coordinates have {components} components, expected 1"
                ));
            }
            Ok((ty, format))
        })
        .collect()
}

/// A `DataArray`'s sample type, where its values are, and its components per point (1 to 4).
fn data_array(array: Node<'_, '_>) -> Result<(SampleType, Format, usize), String> {
    let components = match array.attribute("NumberOfComponents").unwrap_or("1") {
        c @ ("1" | "2" | "3" | "4") => c.parse::<usize>().unwrap_or(1),
        c => {
            return Err(format!(
                "NumberOfComponents: {} (1 to 4 components are supported)",
                c.chars().take(20).collect::<String>()
            ))
        }
    };
    let tyname = array.attribute("type").ok_or("DataArray has no type")?;
    let ty = match tyname {
        "Int8" => SampleType::I8,
        "UInt8" => SampleType::U8,
        "Int16" => SampleType::I16,
        "UInt16" => SampleType::U16,
        "Int32" => SampleType::I32,
        "UInt32" => SampleType::U32,
        "Float32" => SampleType::F32,
        "Float64" => SampleType::F64,
        o => return Err(format!("DataArray type '{o}' is not supported")),
    };
    let text = || array.text().unwrap_or("").as_bytes().to_vec();
    let format = match array.attribute("format").unwrap_or("ascii") {
        "ascii" => Format::Ascii(text()),
        "binary" => Format::Binary(text()),
        "appended" => {
            let off = array
                .attribute("offset")
                .ok_or("appended DataArray has no offset")?;
            Format::Appended {
                offset: off
                    .trim()
                    .parse()
                    .map_err(|_| format!("offset: '{off}' is not a whole number"))?,
            }
        }
        o => {
            return Err(format!(
                "DataArray format '{o}' is not ascii, binary or appended"
            ))
        }
    };
    Ok((ty, format, components))
}

/// Reads header words (UInt32 or UInt64) from `b` at word index `i`.
fn word(b: &[u8], i: usize, h: &Header) -> Result<usize, String> {
    let size = if h.header64 { 8 } else { 4 };
    let s = b
        .get(i * size..(i + 1) * size)
        .ok_or("data block header is truncated")?;
    let v = match (h.header64, h.big_endian) {
        (false, false) => u64::from(u32::from_le_bytes(s.try_into().expect("4"))),
        (false, true) => u64::from(u32::from_be_bytes(s.try_into().expect("4"))),
        (true, false) => u64::from_le_bytes(s.try_into().expect("8")),
        (true, true) => u64::from_be_bytes(s.try_into().expect("8")),
    };
    usize::try_from(v).map_err(|_| "data block header value is too large".to_string())
}

/// Decodes a binary block stream (header words, then data), compressed or not, into exactly `need`
/// bytes.
fn block_stream(b: &[u8], h: &Header, need: usize) -> Result<Vec<u8>, String> {
    let size = if h.header64 { 8 } else { 4 };
    if h.compressor == Compressor::None {
        let n = word(b, 0, h)?;
        if n != need {
            return Err(format!(
                "data block holds {n} bytes, the extent needs {need}"
            ));
        }
        return b
            .get(size..size + n)
            .map(<[u8]>::to_vec)
            .ok_or_else(|| format!("data are truncated: expected {n} bytes"));
    }
    let blocks = word(b, 0, h)?;
    let block_size = word(b, 1, h)?;
    let last = word(b, 2, h)?;
    if blocks == 0 || blocks > need.max(1) || block_size == 0 {
        return Err(format!(
            "compressed header: {blocks} blocks of {block_size} bytes is not plausible"
        ));
    }
    let last = if last == 0 { block_size } else { last };
    let total = (blocks - 1)
        .checked_mul(block_size)
        .and_then(|t| t.checked_add(last))
        .ok_or("compressed header overflows")?;
    if total != need {
        return Err(format!(
            "compressed data hold {total} bytes, the extent needs {need}"
        ));
    }
    let mut at = (3 + blocks) * size;
    // Grows as blocks inflate (each checked against its declared size): no reservation of a
    // declared total the data may not hold.
    let mut out: Vec<u8> = Vec::new();
    for k in 0..blocks {
        let c = word(b, 3 + k, h)?;
        let chunk = b
            .get(at..at.checked_add(c).ok_or("block size overflows")?)
            .ok_or("compressed data are truncated")?;
        let expect = if k + 1 == blocks { last } else { block_size };
        let block = match h.compressor {
            Compressor::Lz4 => compress::unlz4(chunk, expect)?,
            Compressor::Lzma => compress::unxz(chunk, expect)?,
            _ => compress::unzlib(chunk, expect)?,
        };
        out.try_reserve(block.len())
            .map_err(|_| crate::io::alloc_failed(out.len() + block.len(), "the inflated data"))?;
        out.extend(block);
        at += c;
    }
    Ok(out)
}

/// Loads a `.vti` volume: the point-data array named `array`, or the default (see
/// [`parse_header_array`]).
pub fn load(path: &Path, array: Option<&str>) -> Result<Volume, CliError> {
    super::scalar(path, load_all(path, array)?)
}

/// The components of a `.vti` array of 2 to 4 components per point, each a volume of its own;
/// `None` for one component.
pub fn load_components(path: &Path, array: Option<&str>) -> Result<Option<Vec<Volume>>, CliError> {
    Ok(Some(load_all(path, array)?).filter(|parts| parts.len() > 1))
}

/// A `.vti` array's volumes, one per component.
fn load_all(path: &Path, array: Option<&str>) -> Result<Vec<Volume>, CliError> {
    let (h, samples) = read(path, array)?;
    Ok(super::grid_volumes(
        (h.dims, h.spacing, h.directions),
        samples,
        h.components,
    ))
}

/// Reads a `.vti`'s header and every sample of its array (components interleaved).
fn read(
    path: &Path,
    array: Option<&str>,
) -> Result<(Header, crate::io::volume::Samples), CliError> {
    let bytes = crate::io::read_file(path)?;
    let (h, appended) = parse_header_array(&bytes, array).map_err(|e| at(path, e))?;
    let need = super::interleaved(h.dims, h.components)
        .and_then(|d| byte_len(d, h.ty))
        .map_err(|e| at(path, e))?;
    let samples = array_samples(&h, appended, (h.ty, &h.format), need).map_err(|e| at(path, e))?;
    Ok((h, samples))
}

/// The `need` bytes of one array of type `ty` stored as `format` (ascii, base64, or in the
/// `appended` section), decoded; the file's encoding (byte order, header words, compressor) is
/// `h`'s.
pub(super) fn array_samples(
    h: &Header,
    appended: Option<Appended<'_>>,
    (ty, format): (SampleType, &Format),
    need: usize,
) -> Result<crate::io::volume::Samples, String> {
    Ok(match format {
        Format::Ascii(text) => decode_ascii(text, ty, need / ty.size())?,
        Format::Binary(text) => decode(
            &block_stream(&base64_segments(text)?, h, need)?,
            ty,
            h.big_endian,
        )?,
        Format::Appended { offset } => {
            let Appended {
                bytes: section,
                raw,
            } = appended.ok_or("appended DataArray but no AppendedData section")?;
            let start = section
                .get(*offset..)
                .ok_or_else(|| format!("appended offset {offset} is past the end"))?;
            let bytes = if raw {
                block_stream(start, h, need)?
            } else {
                let end = start.iter().position(|&b| b == b'<').unwrap_or(start.len());
                block_stream(&base64_segments(&start[..end])?, h, need)?
            };
            decode(&bytes, ty, h.big_endian)?
        }
    })
}
