//! Legacy VTK (`.vtk`) `DATASET STRUCTURED_POINTS`, as VTK's own reader accepts it from file
//! version 1.0 to 5.1: ASCII or BINARY (big-endian, as the format requires).
//!
//! The file is read as VTK's `vtkDataReader` reads it, as whitespace-separated words rather than
//! fixed lines: line 1 is `# vtk DataFile Version x.y`, line 2 a title (possibly empty), then
//! words. Keywords are matched in either case; blank lines anywhere in the header and lines that
//! start with `#` between keywords are skipped. Geometry: `DIMENSIONS`, `SPACING` (or the 1.0-era
//! `ASPECT_RATIO`), `ORIGIN` (accepted, not needed). Data: `POINT_DATA n` and `CELL_DATA n`
//! sections in either order, each with any of `SCALARS name type [components]` + `LOOKUP_TABLE`,
//! `COLOR_SCALARS`, `VECTORS`, `NORMALS`, `TEXTURE_COORDINATES`, `TENSORS`, `TENSORS6`,
//! `GLOBAL_IDS`, `PEDIGREE_IDS`, a standalone `LOOKUP_TABLE name size`, and `FIELD name count`
//! with its arrays; VTK 8+'s `METADATA` blocks are skipped. Everything that is not the chosen
//! array is passed over by its declared size.
//!
//! The volume is one single-component point-data array: the one `--array NAME` names (an
//! error lists the candidates when none matches), else the first `SCALARS` (VTK's active
//! scalars), else the first single-component `FIELD` array of the point data.

use crate::io::volume::{at, byte_len, check_spacing, decode, decode_ascii, SampleType, Volume};
use crate::CliError;
use std::path::Path;

/// A parsed legacy file: the grid and where the chosen array's values are.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub ty: SampleType,
    pub binary: bool,
    /// The chosen array's name.
    pub name: String,
    /// Byte offset of its first data byte (binary) or of the text before its first value (ASCII).
    pub data_start: usize,
    /// Every point-data array seen, as `name (kind, components)`, for messages.
    pub arrays: Vec<String>,
}

/// Words of the file, with the byte position and line number for messages.
struct Words<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Words<'a> {
    /// Skips whitespace and, when `comments`, lines whose first word starts with `#`.
    fn skip_space(&mut self, comments: bool) {
        loop {
            while self.pos < self.b.len() && self.b[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if comments && self.b.get(self.pos) == Some(&b'#') {
                self.skip_line();
            } else {
                return;
            }
        }
    }

    /// Passes the rest of the current line, its newline included.
    fn skip_line(&mut self) {
        match self.b[self.pos..].iter().position(|&c| c == b'\n') {
            Some(p) => self.pos += p + 1,
            None => self.pos = self.b.len(),
        }
    }

    /// The next word (header keywords and names: comments skipped before it), if any.
    fn word(&mut self) -> Option<&'a str> {
        self.skip_space(true);
        self.raw_word()
    }

    /// The next word with only whitespace skipped (inside data).
    fn raw_word(&mut self) -> Option<&'a str> {
        self.skip_space(false);
        let start = self.pos;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start)
            .then(|| std::str::from_utf8(&self.b[start..self.pos]).ok())
            .flatten()
    }

    /// The next word, which must be there, for field `what`.
    fn need(&mut self, what: &str) -> Result<&'a str, String> {
        self.word()
            .ok_or_else(|| format!("{what}: the file ends early"))
    }

    /// The next word as a count (a whole number ≥ 0, below 2⁴⁰), for field `what`.
    fn count(&mut self, what: &str) -> Result<usize, String> {
        let w = self.need(what)?;
        w.parse::<u64>()
            .ok()
            .filter(|&n| n < 1 << 40)
            .map(|n| n as usize)
            .ok_or_else(|| format!("{what}: '{w}' is not a count"))
    }

    /// `n` numbers for field `what`.
    fn numbers(&mut self, n: usize, what: &str) -> Result<Vec<f64>, String> {
        (0..n)
            .map(|_| {
                let w = self.need(what)?;
                w.parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite())
                    .ok_or_else(|| format!("{what}: '{w}' is not a number"))
            })
            .collect()
    }

    /// Passes over `values` values of `size` bytes each (binary; the line ending the keyword
    /// first) or `values` words (ASCII); returns the position where they start.
    fn skip_values(
        &mut self,
        values: usize,
        size: usize,
        binary: bool,
        what: &str,
    ) -> Result<usize, String> {
        if binary {
            self.skip_line();
            let start = self.pos;
            let end = values
                .checked_mul(size)
                .and_then(|n| n.checked_add(start))
                .filter(|&e| e <= self.b.len())
                .ok_or_else(|| {
                    format!(
                        "{what}: binary data truncated: need {values} values of {size} bytes, \
                         the file has {} bytes left",
                        self.b.len() - start
                    )
                })?;
            self.pos = end;
            Ok(start)
        } else {
            let start = self.pos;
            for i in 0..values {
                if self.raw_word().is_none() {
                    return Err(format!(
                        "{what}: expected {values} values, found {i} (the file ends)"
                    ));
                }
            }
            Ok(start)
        }
    }

    /// VTK 8+ writes an optional `METADATA` block after an array: passes it if it is next.
    fn skip_metadata(&mut self) {
        let save = self.pos;
        if self
            .word()
            .is_some_and(|w| w.eq_ignore_ascii_case("METADATA"))
        {
            self.metadata_body();
        } else {
            self.pos = save;
        }
    }

    /// Passes a `METADATA` block's body (the keyword read): the rest of its line, then lines up
    /// to and including a blank one.
    fn metadata_body(&mut self) {
        self.skip_line();
        while self.pos < self.b.len() {
            let end = self.b[self.pos..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(self.b.len(), |p| self.pos + p);
            let blank = self.b[self.pos..end].iter().all(u8::is_ascii_whitespace);
            self.pos = (end + 1).min(self.b.len());
            if blank {
                break;
            }
        }
    }
}

/// A legacy type name's sample type, if the renderer reads it.
fn sample_type(t: &str) -> Option<SampleType> {
    Some(match t.to_ascii_lowercase().as_str() {
        "unsigned_char" | "bit" => SampleType::U8,
        "char" | "signed_char" => SampleType::I8,
        "unsigned_short" => SampleType::U16,
        "short" => SampleType::I16,
        "unsigned_int" => SampleType::U32,
        "int" => SampleType::I32,
        "float" => SampleType::F32,
        "double" => SampleType::F64,
        _ => return None,
    })
}

/// Bytes per value of a legacy type name in a binary file (what VTK's writer emits), if known.
fn type_size(t: &str) -> Option<usize> {
    Some(match t.to_ascii_lowercase().as_str() {
        "unsigned_char" | "char" | "signed_char" | "bit" => 1,
        "unsigned_short" | "short" => 2,
        "unsigned_int" | "int" | "float" | "vtkidtype" => 4,
        "unsigned_long" | "long" | "unsigned_long_long" | "long_long" | "vtktypeint64"
        | "vtktypeuint64" | "double" => 8,
        _ => return None,
    })
}

/// An array found in the data: where it is and what it holds.
struct Found {
    name: String,
    ty: String,
    components: usize,
    start: usize,
}

impl Found {
    fn new(name: String, ty: String, components: usize, start: usize) -> Self {
        Found {
            name,
            ty,
            components,
            start,
        }
    }
}

/// Parses a legacy `.vtk` file and locates the array to render: `array` by name, or the default
/// (see the module documentation).
pub fn parse(bytes: &[u8], array: Option<&str>) -> Result<Header, String> {
    let mut w = Words { b: bytes, pos: 0 };
    let mut scan = Scan {
        binary: preamble(&mut w)?,
        ..Scan::default()
    };
    while let Some(word) = w.word() {
        scan.keyword(&mut w, word)?;
    }
    scan.header(array)
}

/// Lines 1 and 2 (the version line, then the title, whatever it holds) and the `ASCII` or
/// `BINARY` word after them: whether the data are binary.
fn preamble(w: &mut Words<'_>) -> Result<bool, String> {
    let bytes = w.b;
    let first_end = bytes
        .iter()
        .position(|&c| c == b'\n')
        .unwrap_or(bytes.len());
    let first = String::from_utf8_lossy(&bytes[..first_end]);
    if !first
        .trim_start()
        .to_ascii_lowercase()
        .starts_with("# vtk datafile")
    {
        return Err("not a legacy VTK file (expected '# vtk DataFile Version')".into());
    }
    w.pos = (first_end + 1).min(bytes.len());
    w.skip_line();
    match w.word().unwrap_or("").to_ascii_uppercase().as_str() {
        "ASCII" => Ok(false),
        "BINARY" => Ok(true),
        o => Err(format!(
            "after the title: expected ASCII or BINARY, found '{o}'"
        )),
    }
}

/// What the keywords read so far declared.
#[derive(Default)]
struct Scan {
    binary: bool,
    dims: Option<[usize; 3]>,
    spacing: Option<[f32; 3]>,
    dataset: Option<String>,
    /// The point data's arrays, in file order.
    found: Vec<Found>,
    /// The current section: (point data?, tuples).
    section: Option<(bool, usize)>,
    /// The first point-data `SCALARS` (VTK's active scalars), an index into `found`.
    chosen: Option<usize>,
}

impl Scan {
    /// Reads what follows keyword `word`.
    fn keyword(&mut self, w: &mut Words<'_>, word: &str) -> Result<(), String> {
        let key = word.to_ascii_uppercase();
        match key.as_str() {
            "DATASET" => self.dataset = Some(w.need("DATASET")?.to_ascii_uppercase()),
            "DIMENSIONS" => {
                let v = w.numbers(3, "DIMENSIONS")?;
                if v.iter()
                    .any(|&x| !(x >= 1.0 && x.fract() == 0.0 && x < 1e12))
                {
                    return Err(format!("DIMENSIONS: {v:?} are not positive whole numbers"));
                }
                let d = [v[0] as usize, v[1] as usize, v[2] as usize];
                byte_len(d, SampleType::U8)?;
                self.dims = Some(d);
            }
            "SPACING" | "ASPECT_RATIO" => {
                let v = w.numbers(3, &key)?;
                self.spacing = Some([v[0] as f32, v[1] as f32, v[2] as f32]);
            }
            "ORIGIN" => {
                w.numbers(3, "ORIGIN")?;
            }
            "POINT_DATA" | "CELL_DATA" => {
                let n = w.count(&key)?;
                let point = key == "POINT_DATA";
                if point {
                    let d = self.dims.ok_or("POINT_DATA before DIMENSIONS")?;
                    let points = d[0] * d[1] * d[2];
                    if n != points {
                        return Err(format!(
                            "POINT_DATA: expected {points} (the DIMENSIONS' product), found {n}"
                        ));
                    }
                }
                self.section = Some((point, n));
            }
            "FIELD" => self.field(w)?,
            "SCALARS"
            | "COLOR_SCALARS"
            | "VECTORS"
            | "NORMALS"
            | "TEXTURE_COORDINATES"
            | "TENSORS"
            | "TENSORS6"
            | "GLOBAL_IDS"
            | "PEDIGREE_IDS"
            | "LOOKUP_TABLE" => self.attribute(w, &key)?,
            "METADATA" => w.metadata_body(),
            _ => return Err(format!("unexpected '{word}' (not a legacy VTK keyword)")),
        }
        Ok(())
    }

    /// A `FIELD name count` and its arrays (dataset field data, before any section, have
    /// their own tuple counts: only arrays of the point data's count are candidates).
    fn field(&mut self, w: &mut Words<'_>) -> Result<(), String> {
        w.need("FIELD name")?;
        let arrays = w.count("FIELD array count")?;
        for _ in 0..arrays {
            let name = w.need("FIELD array name")?.to_string();
            let comps = w.count(&format!("FIELD array {name}: components"))?;
            let tuples = w.count(&format!("FIELD array {name}: tuples"))?;
            let ty = w.need(&format!("FIELD array {name}: type"))?.to_string();
            let size = type_size(&ty)
                .ok_or_else(|| format!("FIELD array {name}: type '{ty}' is not a VTK type"))?;
            let values = comps
                .checked_mul(tuples)
                .ok_or_else(|| format!("FIELD array {name}: too many values"))?;
            let start = w.skip_values(values, size, self.binary, &name)?;
            w.skip_metadata();
            if matches!(self.section, Some((true, n)) if n == tuples) {
                self.found.push(Found::new(name, ty, comps, start));
            }
        }
        Ok(())
    }

    /// A section's attribute (`key` read): its values passed over, a point-data `SCALARS`
    /// kept as a candidate.
    fn attribute(&mut self, w: &mut Words<'_>, key: &str) -> Result<(), String> {
        let Some((point, tuples)) = self.section else {
            return Err(format!("{key} before POINT_DATA or CELL_DATA"));
        };
        let name = w.need(key)?.to_string();
        let binary = self.binary;
        let (ty, comps, size) = match key {
            "SCALARS" => match scalars_type(w, &name, tuples, binary)? {
                Some(t) => t,
                None => return Ok(()),
            },
            "COLOR_SCALARS" => {
                let c = w.count("COLOR_SCALARS components")?;
                ("unsigned_char".to_string(), c, 1)
            }
            "LOOKUP_TABLE" => {
                // A standalone table: size entries of RGBA.
                let n = w.count("LOOKUP_TABLE size")?;
                w.skip_values(n.saturating_mul(4), 1, binary, &name)?;
                return Ok(());
            }
            "TEXTURE_COORDINATES" => {
                let c = w.count("TEXTURE_COORDINATES dimension")?;
                let ty = w.need("TEXTURE_COORDINATES type")?.to_string();
                let size = type_size(&ty).ok_or_else(|| format!("{name}: type '{ty}'"))?;
                (ty, c, size)
            }
            _ => {
                let ty = w.need(&format!("{key} type"))?.to_string();
                let size = type_size(&ty)
                    .ok_or_else(|| format!("{key} {name}: type '{ty}' is not a VTK type"))?;
                let c = match key {
                    "VECTORS" | "NORMALS" => 3,
                    "TENSORS" => 9,
                    "TENSORS6" => 6,
                    _ => 1,
                };
                (ty, c, size)
            }
        };
        let values = tuples
            .checked_mul(comps)
            .ok_or_else(|| format!("{key} {name}: too many values"))?;
        let start = w.skip_values(values, size, binary, &name)?;
        w.skip_metadata();
        if point && key == "SCALARS" {
            self.chosen.get_or_insert(self.found.len());
            self.found.push(Found::new(name, ty, comps, start));
        }
        Ok(())
    }

    /// The header of the array `array` names, or of the default one.
    fn header(self, array: Option<&str>) -> Result<Header, String> {
        if self.dataset.as_deref() != Some("STRUCTURED_POINTS") {
            return Err(format!(
                "DATASET: expected STRUCTURED_POINTS, found {}",
                self.dataset.as_deref().unwrap_or("none")
            ));
        }
        let dims = self.dims.ok_or("missing DIMENSIONS")?;
        let found = &self.found;
        let list: Vec<String> = found
            .iter()
            .map(|f| format!("{} ({} × {})", f.name, f.ty, f.components))
            .collect();
        let pick = match array {
            Some(name) => found.iter().position(|f| f.name == name).ok_or_else(|| {
                format!(
                    "no point-data array '{name}' (the file has: {})",
                    if list.is_empty() {
                        "none".to_string()
                    } else {
                        list.join(", ")
                    }
                )
            })?,
            None => self
                .chosen
                .or_else(|| found.iter().position(|f| f.components == 1))
                .ok_or("missing SCALARS: no single-component point-data array")?,
        };
        let f = &found[pick];
        if f.components != 1 {
            return Err(format!(
                "array '{}' has {} components (only 1 is supported; the file has: {})",
                f.name,
                f.components,
                list.join(", ")
            ));
        }
        let ty = sample_type(&f.ty)
            .ok_or_else(|| format!("array '{}': type '{}' is not supported", f.name, f.ty))?;
        let spacing = self.spacing.unwrap_or([1.0; 3]);
        check_spacing(spacing)?;
        Ok(Header {
            dims,
            spacing,
            ty,
            binary: self.binary,
            name: f.name.clone(),
            data_start: f.start,
            arrays: list,
        })
    }
}

/// After `SCALARS name`: the type, optional components and the required `LOOKUP_TABLE name`;
/// (type, components, bytes per value), or `None` for packed bits (not renderable: passed
/// over here).
fn scalars_type(
    w: &mut Words<'_>,
    name: &str,
    tuples: usize,
    binary: bool,
) -> Result<Option<(String, usize, usize)>, String> {
    let ty = w.need("SCALARS type")?.to_string();
    let mut next = w.need("SCALARS: LOOKUP_TABLE")?;
    let mut comps = 1;
    if !next.eq_ignore_ascii_case("LOOKUP_TABLE") {
        comps = next
            .parse()
            .ok()
            .filter(|c| (1..=4).contains(c))
            .ok_or_else(|| format!("SCALARS {name}: '{next}' is not 1 to 4 components"))?;
        next = w.need("SCALARS: LOOKUP_TABLE")?;
    }
    if !next.eq_ignore_ascii_case("LOOKUP_TABLE") {
        return Err(format!(
            "SCALARS {name}: missing LOOKUP_TABLE after SCALARS, found '{next}'"
        ));
    }
    w.need("LOOKUP_TABLE name")?;
    if ty.eq_ignore_ascii_case("bit") && binary {
        // Packed eight to a byte.
        let bytes = (tuples * comps).div_ceil(8);
        w.skip_values(bytes, 1, true, name)?;
        w.skip_metadata();
        return Ok(None);
    }
    let size =
        type_size(&ty).ok_or_else(|| format!("SCALARS {name}: type '{ty}' is not a VTK type"))?;
    Ok(Some((ty, comps, size)))
}

/// Parses the header of a legacy `.vtk` file, choosing the default array.
pub fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    parse(bytes, None)
}

/// Loads a legacy `.vtk` volume: `array` by name, or the default array.
pub fn load(path: &Path, array: Option<&str>) -> Result<Volume, CliError> {
    let bytes = crate::io::read_file(path)?;
    let h = parse(&bytes, array).map_err(|e| at(path, e))?;
    let need = byte_len(h.dims, h.ty).map_err(|e| at(path, e))?;
    let data = &bytes[h.data_start..];
    let samples = if h.binary {
        decode(&data[..need], h.ty, true).map_err(|e| at(path, e))?
    } else {
        // `parse` counted the values: take exactly that many words.
        let mut w = Words { b: data, pos: 0 };
        for _ in 0..need / h.ty.size() {
            w.raw_word();
        }
        decode_ascii(&data[..w.pos], h.ty, need / h.ty.size()).map_err(|e| at(path, e))?
    };
    Ok(Volume::new(h.dims, h.spacing, samples))
}
