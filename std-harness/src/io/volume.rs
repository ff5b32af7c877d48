//! Volumes in memory and the loaders of this stage: NRRD (attached `.nrrd` or detached `.nhdr`,
//! raw encoding, either endianness, 8–64-bit integer and float samples) and headerless raw.
//!
//! Data are x-fastest: sample (i, j, k) is at `i + dims[0]·(j + dims[1]·k)`.

use crate::CliError;
use std::path::{Path, PathBuf};

/// Sample storage, by type.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    U32(Vec<u32>),
    I32(Vec<i32>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// A sample type name as written on the command line and in NRRD headers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl SampleType {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::F64 => 8,
        }
    }

    /// Parses NRRD's type names (all spellings of the NRRD spec) and short names (`u8`, `f32`, …).
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s.trim() {
            "uchar" | "unsigned char" | "uint8" | "uint8_t" | "u8" => SampleType::U8,
            "signed char" | "int8" | "int8_t" | "i8" => SampleType::I8,
            "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" | "u16" => {
                SampleType::U16
            }
            "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t"
            | "i16" => SampleType::I16,
            "uint" | "unsigned int" | "uint32" | "uint32_t" | "u32" => SampleType::U32,
            "int" | "signed int" | "int32" | "int32_t" | "i32" => SampleType::I32,
            "float" | "float32" | "f32" => SampleType::F32,
            "double" | "float64" | "f64" => SampleType::F64,
            _ => return None,
        })
    }
}

/// A volume: dimensions, spacing (world units per voxel along i, j, k) and samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// World units per voxel along i, j, k.
    pub spacing: [f32; 3],
    /// The samples.
    pub samples: Samples,
}

impl Volume {
    /// Sample at linear index `n` as f32.
    #[inline]
    pub fn value(&self, n: usize) -> f32 {
        match &self.samples {
            Samples::U8(v) => f32::from(v[n]),
            Samples::I8(v) => f32::from(v[n]),
            Samples::U16(v) => f32::from(v[n]),
            Samples::I16(v) => f32::from(v[n]),
            Samples::U32(v) => v[n] as f32,
            Samples::I32(v) => v[n] as f32,
            Samples::F32(v) => v[n],
            Samples::F64(v) => v[n] as f32,
        }
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Whether the volume has no voxel (never true for a loaded volume).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Smallest and largest finite sample.
    pub fn range(&self) -> (f32, f32) {
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for n in 0..self.len() {
            let v = self.value(n);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo, hi)
    }

    /// Copies sheet `s` of `axis` (row-major over the other two axes, lower axis fastest) into `out`
    /// as f32.
    pub fn sheet_into(&self, axis: usize, s: usize, out: &mut [f32]) {
        let (a, b) = footprint::geometry::in_sheet_axes(axis);
        let stride = [1, self.dims[0], self.dims[0] * self.dims[1]];
        let (na, nb) = (self.dims[a], self.dims[b]);
        for v in 0..nb {
            for u in 0..na {
                out[v * na + u] = self.value(s * stride[axis] + u * stride[a] + v * stride[b]);
            }
        }
    }
}

fn decode(bytes: &[u8], ty: SampleType, big_endian: bool) -> Samples {
    macro_rules! conv {
        ($t:ty, $variant:ident) => {{
            const N: usize = std::mem::size_of::<$t>();
            Samples::$variant(
                bytes
                    .chunks_exact(N)
                    .map(|c| {
                        let a: [u8; N] = c.try_into().expect("chunk of N bytes");
                        if big_endian {
                            <$t>::from_be_bytes(a)
                        } else {
                            <$t>::from_le_bytes(a)
                        }
                    })
                    .collect(),
            )
        }};
    }
    match ty {
        SampleType::U8 => Samples::U8(bytes.to_vec()),
        SampleType::I8 => Samples::I8(bytes.iter().map(|&b| b as i8).collect()),
        SampleType::U16 => conv!(u16, U16),
        SampleType::I16 => conv!(i16, I16),
        SampleType::U32 => conv!(u32, U32),
        SampleType::I32 => conv!(i32, I32),
        SampleType::F32 => conv!(f32, F32),
        SampleType::F64 => conv!(f64, F64),
    }
}

/// Largest volume accepted, voxels (4 Gi): beyond it the byte size overflows typical limits.
pub const MAX_VOXELS: usize = 1 << 32;

fn checked_len(path: &Path, dims: [usize; 3], ty: SampleType) -> Result<usize, CliError> {
    let bad = |why: &str| CliError::input(format!("{}: dims {dims:?}: {why}", path.display()));
    if dims.contains(&0) {
        return Err(bad("a dimension is zero"));
    }
    let n = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| bad("too many voxels"))?;
    if n > MAX_VOXELS {
        return Err(bad("too many voxels"));
    }
    n.checked_mul(ty.size())
        .ok_or_else(|| bad("too many bytes"))
}

/// Reads a headerless raw volume.
pub fn load_raw(
    path: &Path,
    dims: [usize; 3],
    ty: SampleType,
    big_endian: bool,
    spacing: [f32; 3],
) -> Result<Volume, CliError> {
    let need = checked_len(path, dims, ty)?;
    let bytes = super::read_file(path)?;
    if bytes.len() != need {
        return Err(CliError::input(format!(
            "{}: expected {need} bytes for {}x{}x{} {:?}, found {}",
            path.display(),
            dims[0],
            dims[1],
            dims[2],
            ty,
            bytes.len()
        )));
    }
    check_spacing(path, spacing)?;
    Ok(Volume {
        dims,
        spacing,
        samples: decode(&bytes, ty, big_endian),
    })
}

fn check_spacing(path: &Path, spacing: [f32; 3]) -> Result<(), CliError> {
    if spacing.iter().all(|s| s.is_finite() && *s > 0.0) {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "{}: spacing {spacing:?} must be finite and positive",
            path.display()
        )))
    }
}

/// Reads an NRRD volume (`.nrrd` with attached data or `.nhdr` with a `data file`).
pub fn load_nrrd(path: &Path) -> Result<Volume, CliError> {
    let bytes = super::read_file(path)?;
    let err = |what: String| CliError::input(format!("{}: {what}", path.display()));
    if !bytes.starts_with(b"NRRD000") {
        return Err(err("not an NRRD file (missing NRRD000x magic)".into()));
    }
    // The header ends at the first empty line (or at end of file for a detached header).
    let mut at = 0;
    let mut fields: Vec<(String, String)> = Vec::new();
    let mut first = true;
    loop {
        let end = bytes[at..].iter().position(|&b| b == b'\n').map(|p| at + p);
        let line_bytes = &bytes[at..end.unwrap_or(bytes.len())];
        at = end.map_or(bytes.len(), |e| e + 1);
        let line = std::str::from_utf8(line_bytes).map_err(|_| err("header is not text".into()))?;
        let line = line.trim_end_matches('\r');
        if first {
            first = false;
        } else if line.is_empty() {
            break;
        } else if !line.starts_with('#') {
            // "key: value" fields; "key:=value" key/value pairs are metadata and ignored.
            if let Some((k, v)) = line.split_once(": ") {
                fields.push((k.trim().to_ascii_lowercase(), v.trim().to_string()));
            } else if !line.contains(":=") {
                return Err(err(format!("malformed header line '{line}'")));
            }
        }
        if end.is_none() {
            break;
        }
    }
    let get = |k: &str| {
        fields
            .iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.as_str())
    };
    let need = |k: &str| get(k).ok_or_else(|| err(format!("missing header field '{k}'")));
    let ty = SampleType::parse(need("type")?)
        .ok_or_else(|| err(format!("unsupported type '{}'", get("type").unwrap_or(""))))?;
    let dimension: usize = need("dimension")?
        .parse()
        .map_err(|_| err("dimension is not a number".into()))?;
    if dimension != 3 {
        return Err(err(format!(
            "dimension {dimension}: only 3D volumes are supported"
        )));
    }
    let sizes: Vec<usize> = need("sizes")?
        .split_whitespace()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            err(format!(
                "sizes '{}' are not whole numbers",
                get("sizes").unwrap_or("")
            ))
        })?;
    if sizes.len() != 3 {
        return Err(err(format!(
            "sizes has {} entries, expected 3",
            sizes.len()
        )));
    }
    let dims = [sizes[0], sizes[1], sizes[2]];
    let spacing = match get("spacings") {
        Some(s) => {
            let v: Vec<f32> = s
                .split_whitespace()
                .map(|x| x.parse())
                .collect::<Result<_, _>>()
                .map_err(|_| err(format!("spacings '{s}' are not numbers")))?;
            if v.len() != 3 {
                return Err(err(format!("spacings has {} entries, expected 3", v.len())));
            }
            [v[0], v[1], v[2]]
        }
        None => [1.0; 3],
    };
    check_spacing(path, spacing)?;
    let encoding = need("encoding")?;
    if encoding != "raw" {
        return Err(err(format!(
            "encoding '{encoding}' is not supported yet (raw only)"
        )));
    }
    let big_endian = match get("endian") {
        Some("big") => true,
        Some("little") | None => false,
        Some(other) => return Err(err(format!("endian '{other}' is not little or big"))),
    };
    if ty.size() > 1 && get("endian").is_none() {
        return Err(err(
            "missing header field 'endian' (required for multi-byte types)".into(),
        ));
    }
    let len = checked_len(path, dims, ty)?;
    let skip: usize = get("byte skip")
        .map_or(Ok(0), |s| s.parse())
        .map_err(|_| err("byte skip is not a whole number".into()))?;
    let (data, source): (Vec<u8>, PathBuf) = match get("data file").or(get("datafile")) {
        Some(name) => {
            let p = path.parent().unwrap_or(Path::new(".")).join(name);
            (super::read_file(&p)?, p)
        }
        None => (bytes[at..].to_vec(), path.to_path_buf()),
    };
    let body = data.get(skip..).unwrap_or(&[]);
    if body.len() != len {
        return Err(CliError::input(format!(
            "{}: header says {}x{}x{} {:?} = {len} bytes, data has {}",
            source.display(),
            dims[0],
            dims[1],
            dims[2],
            ty,
            body.len()
        )));
    }
    Ok(Volume {
        dims,
        spacing,
        samples: decode(body, ty, big_endian),
    })
}
