//! NIfTI-1 and NIfTI-2, single file (`.nii`, `.nii.gz`; magic `n+1` / `n+2`) or pair (`.hdr` +
//! `.img` or `.img.gz`; magic `ni1` / `ni2`, and Analyze 7.5 headers, which have no magic and no
//! orientation): `dim`, `datatype`, `pixdim` (spacing), `vox_offset`, `scl_slope` / `scl_inter`
//! (applied when the slope is non-zero and not the identity: samples become f32), orientation
//! from the sform (if `sform_code` > 0) or the qform quaternion (if `qform_code` > 0). Either
//! byte order (detected from `sizeof_hdr`: 348 for NIfTI-1, 540 for NIfTI-2).
//!
//! The two versions hold the same fields at different offsets and widths (NIfTI-2: 64-bit
//! integers and doubles); `Layout` names them once for each.

use super::compress;
use crate::io::volume::{
    at, byte_len, check_spacing, decode, SampleType, Samples, Volume, AXIS_ALIGNED,
};
use crate::CliError;
use std::path::{Path, PathBuf};

/// Size of a NIfTI-1 header.
pub const HEADER_LEN: usize = 348;
/// Size of a NIfTI-2 header.
pub const HEADER2_LEN: usize = 540;

/// Where one version keeps its fields (byte offsets) and how wide its numbers are.
struct Layout {
    /// Integers (`dim`, `vox_offset` in NIfTI-2, form codes) are 8 bytes wide, reals 8 (f64).
    wide: bool,
    datatype: usize,
    bitpix: usize,
    dim: usize,
    pixdim: usize,
    vox_offset: usize,
    slope: usize,
    inter: usize,
    qform: usize,
    sform: usize,
    quatern: usize,
    srow: usize,
    magic: usize,
}

const NIFTI1: Layout = Layout {
    wide: false,
    datatype: 70,
    bitpix: 72,
    dim: 40,
    pixdim: 76,
    vox_offset: 108,
    slope: 112,
    inter: 116,
    qform: 252,
    sform: 254,
    quatern: 256,
    srow: 280,
    magic: 344,
};

const NIFTI2: Layout = Layout {
    wide: true,
    datatype: 12,
    bitpix: 14,
    dim: 16,
    pixdim: 104,
    vox_offset: 168,
    slope: 176,
    inter: 184,
    qform: 344,
    sform: 348,
    quatern: 352,
    srow: 400,
    magic: 4,
};

/// A parsed NIfTI-1 or NIfTI-2 header.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// 1 or 2; 0 for an Analyze 7.5 header (a pair without NIfTI magic).
    pub version: u8,
    /// The samples are in a separate `.img` file (magic `ni1`/`ni2`, or Analyze).
    pub pair: bool,
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    /// Where the samples start: in the `.nii`, or in the `.img` of a pair.
    pub vox_offset: usize,
    /// (slope, intercept) when they change the values.
    pub scale: Option<(f32, f32)>,
}

/// The header length that the first four bytes (`sizeof_hdr`) announce, if either version's, and
/// the byte order that makes it so.
pub fn sizeof_hdr(b: &[u8]) -> Option<(usize, bool)> {
    let w: [u8; 4] = b.get(0..4)?.try_into().ok()?;
    match (i32::from_le_bytes(w), i32::from_be_bytes(w)) {
        (348, _) => Some((HEADER_LEN, false)),
        (_, 348) => Some((HEADER_LEN, true)),
        (540, _) => Some((HEADER2_LEN, false)),
        (_, 540) => Some((HEADER2_LEN, true)),
        _ => None,
    }
}

/// Parses the 348-byte (NIfTI-1) or 540-byte (NIfTI-2) header at the start of `b`.
pub fn parse_header(b: &[u8]) -> Result<Header, String> {
    let Some((len, big_endian)) = sizeof_hdr(b) else {
        if b.len() < HEADER_LEN {
            return Err(format!(
                "file is {} bytes, shorter than a NIfTI-1 header ({HEADER_LEN})",
                b.len()
            ));
        }
        return Err("sizeof_hdr is not 348 or 540: not a NIfTI-1 or NIfTI-2 file".into());
    };
    if b.len() < len {
        return Err(format!(
            "file is {} bytes, shorter than a NIfTI-{} header ({len})",
            b.len(),
            if len == HEADER_LEN { 1 } else { 2 }
        ));
    }
    let f = Fields {
        b,
        big_endian,
        l: if len == HEADER_LEN { &NIFTI1 } else { &NIFTI2 },
    };
    let (version, pair) = f.version()?;
    let dims = f.dims()?;
    let ty = f.sample_type()?;
    byte_len(dims, ty)?;
    let l = f.l;
    let vox = if l.wide {
        f.i64_at(l.vox_offset) as f64
    } else {
        f.real(l.vox_offset, 0)
    };
    // A single file's samples follow the header; a pair's `.img` holds only samples (offset 0
    // in practice, any whole number allowed).
    let min = if pair { 0 } else { len };
    if !(vox >= min as f64 && vox.fract() == 0.0 && vox < 1e9) {
        return Err(format!("vox_offset {vox} is not a whole number ≥ {min}"));
    }
    let (slope, inter) = (f.real(l.slope, 0) as f32, f.real(l.inter, 0) as f32);
    let scale =
        (slope.is_finite() && inter.is_finite() && slope != 0.0 && (slope, inter) != (1.0, 0.0))
            .then_some((slope, inter));
    // Analyze headers keep other fields where NIfTI has its form codes: orientation is ignored.
    let (spacing, directions) = if version == 0 {
        (f.pixdim(), AXIS_ALIGNED)
    } else {
        f.orientation()?
    };
    check_spacing(spacing)?;
    Ok(Header {
        version,
        pair,
        dims,
        spacing,
        directions,
        ty,
        big_endian,
        vox_offset: vox as usize,
        scale,
    })
}

/// A header's fields, read in its byte order at its version's offsets and widths.
struct Fields<'a> {
    b: &'a [u8],
    big_endian: bool,
    l: &'static Layout,
}

impl Fields<'_> {
    /// `n` ≤ 8 bytes at `o`, little-endian first.
    fn bytes(&self, o: usize, n: usize) -> [u8; 8] {
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(&self.b[o..o + n]);
        if self.big_endian {
            a[..n].reverse();
        }
        a
    }

    fn i16_at(&self, o: usize) -> i16 {
        let [a, b, ..] = self.bytes(o, 2);
        i16::from_le_bytes([a, b])
    }

    fn i32_at(&self, o: usize) -> i32 {
        let [a, b, c, d, ..] = self.bytes(o, 4);
        i32::from_le_bytes([a, b, c, d])
    }

    fn i64_at(&self, o: usize) -> i64 {
        i64::from_le_bytes(self.bytes(o, 8))
    }

    /// `dim[i]`: i16 in NIfTI-1, i64 in NIfTI-2.
    fn dim(&self, i: usize) -> i64 {
        if self.l.wide {
            self.i64_at(self.l.dim + 8 * i)
        } else {
            i64::from(self.i16_at(self.l.dim + 2 * i))
        }
    }

    /// A form code: i16 in NIfTI-1, i32 in NIfTI-2.
    fn code(&self, o: usize) -> i64 {
        if self.l.wide {
            i64::from(self.i32_at(o))
        } else {
            i64::from(self.i16_at(o))
        }
    }

    /// Real `i` of the array at `o`, kept in f64 (NIfTI-2's width), narrowed where the renderer
    /// needs f32.
    fn real(&self, o: usize, i: usize) -> f64 {
        if self.l.wide {
            f64::from_le_bytes(self.bytes(o + 8 * i, 8))
        } else {
            let [a, b, c, d, ..] = self.bytes(o + 4 * i, 4);
            f64::from(f32::from_le_bytes([a, b, c, d]))
        }
    }

    /// (version, pair) from the magic: 1 or 2, or 0 for Analyze 7.5 (no magic, always a pair).
    fn version(&self) -> Result<(u8, bool), String> {
        let (l, b) = (self.l, self.b);
        let magic = &b[l.magic..l.magic + 4];
        Ok(match magic {
            b"n+1\0" if !l.wide => (1, false),
            b"ni1\0" if !l.wide => (1, true),
            b"n+2\0" if l.wide => (2, false),
            b"ni2\0" if l.wide => (2, true),
            [0, 0, 0, 0] if !l.wide => (0, true),
            _ => {
                return Err(format!(
                    "magic {:?} is not {} (single file) or {} (pair)",
                    String::from_utf8_lossy(magic).trim_end_matches('\0'),
                    if l.wide { "n+2" } else { "n+1" },
                    if l.wide { "ni2" } else { "ni1" },
                ))
            }
        })
    }

    /// The three dimensions (a 3D volume: any further ones 1).
    fn dims(&self) -> Result<[usize; 3], String> {
        let ndim = self.dim(0);
        if !(3..=7).contains(&ndim) {
            return Err(format!("dim[0] = {ndim}: expected a 3D volume"));
        }
        let mut dims = [0usize; 3];
        for (a, d) in dims.iter_mut().enumerate() {
            let v = self.dim(a + 1);
            *d = usize::try_from(v)
                .ok()
                .filter(|&v| v > 0)
                .ok_or_else(|| format!("dim[{}] = {v} is not positive", a + 1))?;
        }
        for a in 4..=ndim as usize {
            if self.dim(a) > 1 {
                return Err(format!(
                    "dim[{a}] = {}: only 3D volumes are supported",
                    self.dim(a)
                ));
            }
        }
        Ok(dims)
    }

    /// The sample type `datatype` names, checked against `bitpix`.
    fn sample_type(&self) -> Result<SampleType, String> {
        let datatype = self.i16_at(self.l.datatype);
        let ty = match datatype {
            2 => SampleType::U8,
            4 => SampleType::I16,
            8 => SampleType::I32,
            16 => SampleType::F32,
            64 => SampleType::F64,
            256 => SampleType::I8,
            512 => SampleType::U16,
            768 => SampleType::U32,
            o => return Err(format!("datatype {o} is not supported")),
        };
        let bitpix = self.i16_at(self.l.bitpix);
        if bitpix as usize != 8 * ty.size() {
            return Err(format!(
                "bitpix {bitpix} does not match datatype {datatype}"
            ));
        }
        Ok(ty)
    }

    /// `pixdim[1..=3]`, as magnitudes.
    fn pixdim(&self) -> [f32; 3] {
        [1, 2, 3].map(|i| self.real(self.l.pixdim, i).abs() as f32)
    }

    /// Spacing and axis directions: from the sform if `sform_code` > 0, else the qform if
    /// `qform_code` > 0, else `pixdim` along the axes.
    fn orientation(&self) -> Result<([f32; 3], [[f32; 3]; 3]), String> {
        let l = self.l;
        if self.code(l.sform) > 0 {
            // srow_x, srow_y, srow_z: four reals each; column j of the 3×3 part is axis j's step.
            let m = |r: usize, c: usize| self.real(l.srow, 4 * r + c) as f32;
            let mut spacing = [0.0f32; 3];
            let mut d = AXIS_ALIGNED;
            for c in 0..3 {
                let v = [m(0, c), m(1, c), m(2, c)];
                (spacing[c], d[c]) = super::axis_step(v)
                    .ok_or_else(|| format!("sform column {c} is zero or not finite"))?;
            }
            Ok((spacing, d))
        } else if self.code(l.qform) > 0 {
            Ok((self.pixdim(), self.quaternion()?))
        } else {
            Ok((self.pixdim(), AXIS_ALIGNED))
        }
    }

    /// The qform's axis directions. As nifti1_io's nifti_quatern_to_mat44 (in f64): a = √(1 −
    /// b² − c² − d²), except where that is below 10⁻⁷, when (b, c, d) is normalised and a = 0 (a
    /// 180° rotation), so a quaternion written a little past unit length still gives a rotation.
    fn quaternion(&self) -> Result<[[f32; 3]; 3], String> {
        let [mut qb, mut qc, mut qd] = [0, 1, 2].map(|k| self.real(self.l.quatern, k));
        let norm2 = qb * qb + qc * qc + qd * qd;
        if !norm2.is_finite() {
            return Err("qform quaternion (quatern_b, c, d) is not finite".into());
        }
        let qa = if 1.0 - norm2 < 1e-7 {
            let k = 1.0 / norm2.sqrt();
            (qb, qc, qd) = (qb * k, qc * k, qd * k);
            0.0
        } else {
            (1.0 - norm2).sqrt()
        };
        let qfac = if self.real(self.l.pixdim, 0) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let r = [
            [
                qa * qa + qb * qb - qc * qc - qd * qd,
                2.0 * (qb * qc - qa * qd),
                2.0 * (qb * qd + qa * qc),
            ],
            [
                2.0 * (qb * qc + qa * qd),
                qa * qa + qc * qc - qb * qb - qd * qd,
                2.0 * (qc * qd - qa * qb),
            ],
            [
                2.0 * (qb * qd - qa * qc),
                2.0 * (qc * qd + qa * qb),
                qa * qa + qd * qd - qc * qc - qb * qb,
            ],
        ];
        let col = |c: usize, s: f64| [0, 1, 2].map(|i| (r[i][c] * s) as f32);
        Ok([col(0, 1.0), col(1, 1.0), col(2, qfac)])
    }
}

/// The header and the image of a pair named by either (`.hdr`, `.hdr.gz`, `.img`, `.img.gz`, in
/// either case): the other half is the same stem with the other extension, plain or gzipped
/// (nibabel gzips both halves when asked for `.img.gz`), the first that exists; `None` if `path`
/// has none of these extensions.
pub fn pair_paths(path: &Path) -> Option<(PathBuf, PathBuf)> {
    let name = path.file_name()?.to_str()?;
    let lower = name.to_ascii_lowercase();
    let dir = path.parent().unwrap_or(Path::new(""));
    let (stem, is_header) = [
        (".hdr", true),
        (".hdr.gz", true),
        (".img", false),
        (".img.gz", false),
    ]
    .iter()
    .find(|(ext, _)| lower.ends_with(ext))
    .map(|(ext, h)| (&name[..name.len() - ext.len()], *h))?;
    let upper = name.ends_with(|c: char| c.is_ascii_uppercase());
    let ext = |e: &str| {
        if upper {
            e.to_ascii_uppercase()
        } else {
            e.to_string()
        }
    };
    let other = if is_header { ".img" } else { ".hdr" };
    let plain = dir.join(format!("{stem}{}", ext(other)));
    let gzipped = dir.join(format!("{stem}{}{}", ext(other), ext(".gz")));
    let other = if !plain.exists() && gzipped.exists() {
        gzipped
    } else {
        plain
    };
    Some(if is_header {
        (path.to_path_buf(), other)
    } else {
        (other, path.to_path_buf())
    })
}

/// A stream of `reader`'s bytes, inflated if they start with gzip's magic bytes (whatever the
/// file is called).
fn maybe_gunzip(
    mut reader: std::io::BufReader<std::fs::File>,
) -> std::io::Result<(Box<dyn std::io::Read>, bool)> {
    let gz = std::io::BufRead::fill_buf(&mut reader)?.starts_with(&[0x1f, 0x8b]);
    Ok(if gz {
        (Box::new(flate2::bufread::MultiGzDecoder::new(reader)), true)
    } else {
        (Box::new(reader), false)
    })
}

/// Loads a NIfTI volume: a `.nii` or `.nii.gz` file, or a pair named by its `.hdr`, `.img` or
/// `.img.gz` (gzip is recognised by its magic bytes, whatever the name).
///
/// Read as a stream, compressed or not: the 348- or 540-byte header first, then the bytes up to
/// `vox_offset` (extensions, skipped), then exactly the samples the header declares, into memory
/// that grows as they arrive. Anything after the samples is ignored and, in a `.gz`, never
/// inflated: a valid volume followed by gigabytes of trailing data costs what the volume costs.
pub fn load(path: &Path) -> Result<Volume, CliError> {
    use std::io::Read;
    let (hdr_path, img_path) = match pair_paths(path) {
        Some((hdr, img)) => (hdr, Some(img)),
        None => (path.to_path_buf(), None),
    };
    crate::io::regular_file_len(&hdr_path)?;
    let cannot = |p: &Path, e: std::io::Error| at(p, format!("cannot read: {e}"));
    let file = std::fs::File::open(&hdr_path).map_err(|e| cannot(&hdr_path, e))?;
    let (mut stream, gz) =
        maybe_gunzip(std::io::BufReader::new(file)).map_err(|e| cannot(&hdr_path, e))?;
    let what = if gz { "gzip" } else { "NIfTI" };
    let read_error = |p: &Path, e| at(p, compress::read_error(e, what));
    let mut head = crate::io::read_growing(&mut stream, HEADER_LEN as u64, "the header")
        .map_err(|e| read_error(&hdr_path, e))?;
    if let Some((HEADER2_LEN, _)) = sizeof_hdr(&head) {
        let more =
            crate::io::read_growing(&mut stream, (HEADER2_LEN - HEADER_LEN) as u64, "the header")
                .map_err(|e| read_error(&hdr_path, e))?;
        head.extend(more);
    }
    let h = parse_header(&head).map_err(|e| at(&hdr_path, e))?;
    let header_len = if h.version == 2 {
        HEADER2_LEN
    } else {
        HEADER_LEN
    };
    let need = byte_len(h.dims, h.ty).map_err(|e| at(&hdr_path, e))?;
    // Where the samples are: after the header in this stream, or at the start of the pair's image.
    let (source, mut body_stream, gap): (PathBuf, Box<dyn Read>, u64) = if h.pair {
        let img = img_path.ok_or_else(|| {
            at(
                &hdr_path,
                "the header is a pair's (magic ni1/ni2, or Analyze): its samples are in a .img \
                 file, found by opening the .hdr or .img (this file has neither extension)",
            )
        })?;
        let d = crate::io::open_data(&img)?;
        let (s, _) = maybe_gunzip(d.reader).map_err(|e| cannot(&img, e))?;
        (img, s, h.vox_offset as u64)
    } else {
        if hdr_path != path {
            return Err(at(
                &hdr_path,
                "magic n+1/n+2 says the samples follow the header in this file, but it was \
                 opened as one half of a .hdr/.img pair; rename it .nii",
            ));
        }
        (hdr_path.clone(), stream, (h.vox_offset - header_len) as u64)
    };
    let skipped = std::io::copy(&mut (&mut body_stream).take(gap), &mut std::io::sink())
        .map_err(|e| read_error(&source, e))?;
    let body = crate::io::read_growing(&mut body_stream, need as u64, "the samples")
        .map_err(|e| read_error(&source, e))?;
    if skipped < gap || body.len() < need {
        return Err(at(
            &source,
            format!(
                "data truncated: need {need} bytes after vox_offset {}, found {}",
                h.vox_offset,
                body.len()
            ),
        ));
    }
    let mut samples = decode(&body, h.ty, h.big_endian).map_err(|e| at(&source, e))?;
    drop(body);
    if let Some((slope, inter)) = h.scale {
        let v = Volume::new(h.dims, h.spacing, samples);
        let mut scaled =
            crate::io::try_vec(v.len(), "the scaled samples").map_err(|e| at(&source, e))?;
        scaled.extend((0..v.len()).map(|n| v.value(n) * slope + inter));
        samples = Samples::F32(scaled.into());
    }
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
