//! NIfTI-1 (`.nii`, `.nii.gz`; single file, magic `n+1`): `dim`, `datatype`, `pixdim` (spacing),
//! `vox_offset`, `scl_slope` / `scl_inter` (applied when the slope is non-zero and not the identity:
//! samples become f32), orientation from the sform (if `sform_code` > 0) or the qform quaternion
//! (if `qform_code` > 0). Either byte order (detected from `sizeof_hdr`).

use super::compress;
use crate::io::volume::{
    at, byte_len, check_spacing, decode, SampleType, Samples, Volume, AXIS_ALIGNED,
};
use crate::CliError;
use std::path::Path;

/// Size of a NIfTI-1 header.
pub const HEADER_LEN: usize = 348;

/// A parsed NIfTI-1 header.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    pub vox_offset: usize,
    /// (slope, intercept) when they change the values.
    pub scale: Option<(f32, f32)>,
}

/// Parses the 348-byte header at the start of `b`.
pub fn parse_header(b: &[u8]) -> Result<Header, String> {
    if b.len() < HEADER_LEN {
        return Err(format!(
            "file is {} bytes, shorter than a NIfTI-1 header ({HEADER_LEN})",
            b.len()
        ));
    }
    let big_endian = match (
        i32::from_le_bytes(b[0..4].try_into().expect("4")),
        i32::from_be_bytes(b[0..4].try_into().expect("4")),
    ) {
        (348, _) => false,
        (_, 348) => true,
        _ => return Err("sizeof_hdr is not 348: not a NIfTI-1 file".into()),
    };
    let i16_at = |o: usize| {
        let a = [b[o], b[o + 1]];
        if big_endian {
            i16::from_be_bytes(a)
        } else {
            i16::from_le_bytes(a)
        }
    };
    let f32_at = |o: usize| {
        let a = [b[o], b[o + 1], b[o + 2], b[o + 3]];
        if big_endian {
            f32::from_be_bytes(a)
        } else {
            f32::from_le_bytes(a)
        }
    };
    let magic = &b[344..348];
    if magic != b"n+1\0" {
        return Err(format!(
            "magic {:?}: only single-file NIfTI-1 (n+1) is supported",
            String::from_utf8_lossy(magic)
        ));
    }
    let ndim = i16_at(40);
    if !(3..=7).contains(&ndim) {
        return Err(format!("dim[0] = {ndim}: expected a 3D volume"));
    }
    let mut dims = [0usize; 3];
    for (a, d) in dims.iter_mut().enumerate() {
        let v = i16_at(42 + 2 * a);
        *d = usize::try_from(v)
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("dim[{}] = {v} is not positive", a + 1))?;
    }
    for a in 3..ndim as usize {
        if i16_at(42 + 2 * a) > 1 {
            return Err(format!(
                "dim[{}] = {}: only 3D volumes are supported",
                a + 1,
                i16_at(42 + 2 * a)
            ));
        }
    }
    let datatype = i16_at(70);
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
    if i16_at(72) as usize != 8 * ty.size() {
        return Err(format!(
            "bitpix {} does not match datatype {datatype}",
            i16_at(72)
        ));
    }
    byte_len(dims, ty)?;
    let pixdim = [f32_at(80).abs(), f32_at(84).abs(), f32_at(88).abs()];
    let vox = f32_at(108);
    if !(vox >= HEADER_LEN as f32 && vox.fract() == 0.0 && vox < 1e9) {
        return Err(format!(
            "vox_offset {vox} is not a whole number ≥ {HEADER_LEN}"
        ));
    }
    let (slope, inter) = (f32_at(112), f32_at(116));
    let scale =
        (slope.is_finite() && inter.is_finite() && slope != 0.0 && (slope, inter) != (1.0, 0.0))
            .then_some((slope, inter));
    let (qform, sform) = (i16_at(252), i16_at(254));
    let (spacing, directions) = if sform > 0 {
        // srow_x, srow_y, srow_z at 280, 296, 312: column j of the 3×3 part is axis j's step.
        let m = |r: usize, c: usize| f32_at(280 + 16 * r + 4 * c);
        let mut spacing = [0.0f32; 3];
        let mut d = AXIS_ALIGNED;
        for c in 0..3 {
            let v = [m(0, c), m(1, c), m(2, c)];
            (spacing[c], d[c]) = super::axis_step(v)
                .ok_or_else(|| format!("sform column {c} is zero or not finite"))?;
        }
        (spacing, d)
    } else if qform > 0 {
        let (qb, qc, qd) = (f32_at(256), f32_at(260), f32_at(264));
        let qa = (1.0 - (qb * qb + qc * qc + qd * qd)).max(0.0).sqrt();
        let qfac = if f32_at(76) < 0.0 { -1.0 } else { 1.0 };
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
        let col = |c: usize, s: f32| [r[0][c] * s, r[1][c] * s, r[2][c] * s];
        (pixdim, [col(0, 1.0), col(1, 1.0), col(2, qfac)])
    } else {
        (pixdim, AXIS_ALIGNED)
    };
    check_spacing(spacing)?;
    Ok(Header {
        dims,
        spacing,
        directions,
        ty,
        big_endian,
        vox_offset: vox as usize,
        scale,
    })
}

/// Loads a `.nii` or `.nii.gz` volume (gzip is recognised by its magic bytes, whatever the name).
///
/// Read as a stream, compressed or not: the 348-byte header first, then the bytes up to
/// `vox_offset` (extensions, skipped), then exactly the samples the header declares, into memory
/// that grows as they arrive. Anything after the samples is ignored and, in a `.nii.gz`, never
/// inflated: a valid volume followed by gigabytes of trailing data costs what the volume costs.
pub fn load(path: &Path) -> Result<Volume, CliError> {
    use std::io::Read;
    crate::io::regular_file_len(path)?;
    let cannot = |e: std::io::Error| at(path, format!("cannot read: {e}"));
    let mut file = std::io::BufReader::new(std::fs::File::open(path).map_err(cannot)?);
    let gz = std::io::BufRead::fill_buf(&mut file)
        .map_err(cannot)?
        .starts_with(&[0x1f, 0x8b]);
    let mut stream: Box<dyn Read> = if gz {
        Box::new(flate2::bufread::MultiGzDecoder::new(file))
    } else {
        Box::new(file)
    };
    let what = if gz { "gzip" } else { "NIfTI" };
    let read_error = |e| at(path, compress::read_error(e, what));
    let head = crate::io::read_growing(&mut stream, HEADER_LEN as u64, "the header")
        .map_err(read_error)?;
    let h = parse_header(&head).map_err(|e| at(path, e))?;
    let need = byte_len(h.dims, h.ty).map_err(|e| at(path, e))?;
    let gap = (h.vox_offset - HEADER_LEN) as u64;
    let skipped =
        std::io::copy(&mut (&mut stream).take(gap), &mut std::io::sink()).map_err(read_error)?;
    let body =
        crate::io::read_growing(&mut stream, need as u64, "the samples").map_err(read_error)?;
    if skipped < gap || body.len() < need {
        return Err(at(
            path,
            format!(
                "data truncated: need {need} bytes after vox_offset {}, found {}",
                h.vox_offset,
                body.len()
            ),
        ));
    }
    let mut samples = decode(&body, h.ty, h.big_endian).map_err(|e| at(path, e))?;
    drop(body);
    if let Some((slope, inter)) = h.scale {
        let v = Volume::new(h.dims, h.spacing, samples);
        let mut scaled =
            crate::io::try_vec(v.len(), "the scaled samples").map_err(|e| at(path, e))?;
        scaled.extend((0..v.len()).map(|n| v.value(n) * slope + inter));
        samples = Samples::F32(scaled);
    }
    Ok(Volume {
        dims: h.dims,
        spacing: h.spacing,
        directions: h.directions,
        samples,
    })
}
