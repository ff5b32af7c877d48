//! Single-channel float images: PFM (float32, exact) and PNG (8-bit view).

use crate::CliError;
use std::path::Path;

/// A single-channel f32 image, rows top to bottom (screen y down).
#[derive(Clone, Debug, PartialEq)]
pub struct GreyImage {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `width × height` values, row-major, top row first.
    pub data: Vec<f32>,
}

impl GreyImage {
    /// Largest value (0 for an empty or all-negative image).
    pub fn peak(&self) -> f32 {
        self.data.iter().copied().fold(0.0, f32::max)
    }
}

/// Encodes a PFM: `Pf`, `W H`, scale −1 (little-endian), then rows **bottom to top** as PFM
/// requires.
pub fn encode_pfm(img: &GreyImage) -> Vec<u8> {
    let mut out = format!("Pf\n{} {}\n-1.0\n", img.width, img.height).into_bytes();
    out.reserve(img.data.len() * 4);
    for row in img.data.chunks(img.width.max(1)).rev() {
        for v in row {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// `data` as NumPy's `.npy` format, version 1.0: little-endian f32, C order, shape (rows, cols).
pub fn encode_npy(data: &[f32], rows: usize, cols: usize) -> Vec<u8> {
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    // Magic (6), version (2), header length (2), then the dictionary padded with spaces and
    // ended by a newline to a multiple of 64 bytes.
    let unpadded = 10 + dict.len() + 1;
    let header_len = dict.len() + 1 + (64 - unpadded % 64) % 64;
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header_len as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.resize(10 + header_len - 1, b' ');
    out.push(b'\n');
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Decodes a single-channel PFM (either endianness).
pub fn decode_pfm(bytes: &[u8], name: &str) -> Result<GreyImage, CliError> {
    decode_pfm_as(bytes, name, false).map(|(img, _)| img)
}

/// Decodes a greyscale (`Pf`) or colour (`PF`, what `render --out x.pfm` writes) PFM, either
/// endianness: the values as a [`GreyImage`] whose rows hold each pixel's channels in turn
/// (`width` is pixels × channels), and the number of channels (1 or 3).
pub fn decode_pfm_any(bytes: &[u8], name: &str) -> Result<(GreyImage, usize), CliError> {
    decode_pfm_as(bytes, name, true)
}

fn decode_pfm_as(bytes: &[u8], name: &str, colour: bool) -> Result<(GreyImage, usize), CliError> {
    let kind = if colour { "PFM" } else { "greyscale PFM" };
    let bad = |what: &str| CliError::input(format!("{name}: not a {kind}: {what}"));
    // Header: three whitespace-separated lines.
    let mut fields = Vec::new();
    let mut at = 0;
    while fields.len() < 4 {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if start == at {
            return Err(bad("header ends early"));
        }
        fields.push(std::str::from_utf8(&bytes[start..at]).map_err(|_| bad("header is not text"))?);
    }
    at += 1; // the single whitespace byte after the scale
    let channels = match fields[0] {
        "Pf" => 1,
        "PF" if colour => 3,
        "PF" => return Err(bad("magic is not Pf (colour PFM is not supported)")),
        _ if colour => return Err(bad("magic is neither Pf nor PF")),
        _ => return Err(bad("magic is not Pf (colour PFM is not supported)")),
    };
    let parse = |s: &str, what: &str| s.parse::<usize>().map_err(|_| bad(what));
    let pixels = parse(fields[1], "bad width")?;
    let height = parse(fields[2], "bad height")?;
    let scale: f32 = fields[3].parse().map_err(|_| bad("bad scale"))?;
    let width = pixels
        .checked_mul(channels)
        .ok_or_else(|| bad("size overflows"))?;
    let n = width
        .checked_mul(height)
        .ok_or_else(|| bad("size overflows"))?;
    let need = n
        .checked_mul(4)
        .and_then(|b| b.checked_add(at))
        .ok_or_else(|| bad("size overflows"))?;
    if bytes.len() != need {
        return Err(bad(&format!(
            "expected {need} bytes for {pixels}x{height}, got {}",
            bytes.len()
        )));
    }
    let little = scale < 0.0;
    let mut data = vec![0.0f32; n];
    for (i, chunk) in bytes[at..].chunks_exact(4).enumerate() {
        let b = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let v = if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        // File row r (from the bottom) is image row height−1−r.
        let (r, c) = (i / width, i % width);
        data[(height - 1 - r) * width + c] = v;
    }
    Ok((
        GreyImage {
            width,
            height,
            data,
        },
        channels,
    ))
}

/// Encodes an 8-bit greyscale PNG, mapping [0, `white`] linearly to [0, 255] (clamped).
pub fn encode_png_grey(img: &GreyImage, white: f32) -> Result<Vec<u8>, CliError> {
    let scale = if white > 0.0 { 255.0 / white } else { 0.0 };
    let pixels: Vec<u8> = img
        .data
        .iter()
        .map(|v| (v * scale).round().clamp(0.0, 255.0) as u8)
        .collect();
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, img.width as u32, img.height as u32);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc
        .write_header()
        .map_err(|e| CliError::input(format!("PNG encoder: {e}")))?;
    writer
        .write_image_data(&pixels)
        .map_err(|e| CliError::input(format!("PNG encoder: {e}")))?;
    writer
        .finish()
        .map_err(|e| CliError::input(format!("PNG encoder: {e}")))?;
    Ok(out)
}

/// Writes `img` to `path` as PFM (`.pfm`) or as an 8-bit PNG normalised to its peak (`.png`).
pub fn save_grey(img: &GreyImage, path: &Path) -> Result<(), CliError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match ext.as_deref() {
        Some("pfm") => encode_pfm(img),
        Some("png") => encode_png_grey(img, img.peak())?,
        _ => {
            return Err(CliError::input(format!(
                "{}: unknown output type (use .pfm or .png)",
                path.display()
            )))
        }
    };
    super::write_atomic(path, &bytes)
}

/// What the volume is composited over (`--background`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Background {
    /// Black, opaque: the PNG is RGB, the premultiplied colour as it is (the default).
    Black,
    /// Nothing: the PNG is RGBA with straight alpha, the render's coverage.
    Transparent,
    /// A PNG of the output size, composited behind the volume (its alpha respected).
    Image(std::path::PathBuf),
}

impl Background {
    /// The image file, if it names one.
    pub fn file(&self) -> Option<&Path> {
        match self {
            Background::Image(p) => Some(p),
            _ => None,
        }
    }
}

/// How colour values become PNG samples: the transfer curve applied to the colour channels (alpha
/// is always linear, as PNG defines it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Gamma {
    /// Values written as computed, no curve. This is what VTK and ParaView do by default
    /// (`vtkRenderWindow::UseSRGBColorSpace` is off): their transfer-function colours are display
    /// values, blended and stored unchanged, and viewers read the file as sRGB. A preset renders
    /// here with the colours it shows in ParaView.
    #[default]
    Linear,
    /// Values treated as linear light and encoded with the sRGB curve (IEC 61966-2-1), and the
    /// file tagged with an `sRGB` chunk: physically meaningful emission (X-ray, density) looks
    /// right on a display, at the cost of lighter images than ParaView's for the same colours.
    Srgb,
}

impl Gamma {
    /// A linear value in [0, 1] as stored in the file, in [0, 1].
    pub fn encode(self, v: f32) -> f32 {
        match self {
            Gamma::Linear => v,
            Gamma::Srgb => {
                // Clamped: the curve's rounding must not carry 1 past 1.
                if v <= 0.003_130_8 {
                    v * 12.92
                } else {
                    (1.055 * v.powf(1.0 / 2.4) - 0.055).min(1.0)
                }
            }
        }
    }
    /// A stored value in [0, 1] as linear, the inverse of [`Gamma::encode`].
    pub fn decode(self, v: f32) -> f32 {
        match self {
            Gamma::Linear => v,
            Gamma::Srgb => {
                if v <= 0.040_45 {
                    v / 12.92
                } else {
                    ((v + 0.055) / 1.055).powf(2.4).min(1.0)
                }
            }
        }
    }
}

/// How a colour PNG is written. The default (opaque 8-bit RGB, [`Gamma::Linear`]) is what
/// `render` writes without `--background transparent`, `--gamma` or `--depth`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PngStyle {
    /// RGBA with straight (not premultiplied) alpha, as PNG requires: the render's coverage over
    /// a transparent background. Otherwise RGB: the premultiplied colour, i.e. composited over
    /// the working image's background (black unless one was given).
    pub alpha: bool,
    /// Transfer curve of the colour channels.
    pub gamma: Gamma,
    /// 16 bits per sample instead of 8.
    pub sixteen: bool,
}

impl PngStyle {
    /// Whether this is the plain style a `.pfm` (linear float RGB, no alpha) can also stand for.
    pub fn is_plain(&self) -> bool {
        *self == PngStyle::default()
    }
}

/// Encodes premultiplied RGBA (linear, row-major, top row first) as a PNG in `style`: values are
/// clamped to [0, 1] (colour to [0, alpha]), un-premultiplied for an RGBA file, passed through
/// the transfer curve and rounded to the nearest 8- or 16-bit level.
pub fn encode_png(
    rgba: &[[f32; 4]],
    width: usize,
    height: usize,
    style: PngStyle,
) -> Result<Vec<u8>, CliError> {
    let bytes = png_samples(rgba, width, height, style)?;
    let mut out = Vec::new();
    let enc = png_encoder(&mut out, width, height, style);
    let mut writer = enc.write_header().map_err(png_err)?;
    writer.write_image_data(&bytes).map_err(png_err)?;
    writer.finish().map_err(png_err)?;
    Ok(out)
}

/// An animated PNG (APNG) of `count` frames in `style`, each shown `delay_ms` milliseconds and
/// looping forever; `frame(k)` renders frame k (premultiplied RGBA as [`encode_png`] takes),
/// which is encoded before the next is asked for, so memory holds one frame and the compressed
/// file. Viewers without APNG show the first frame.
pub fn encode_apng(
    (width, height): (usize, usize),
    style: PngStyle,
    count: usize,
    delay_ms: u16,
    mut frame: impl FnMut(usize) -> Result<Vec<[f32; 4]>, CliError>,
) -> Result<Vec<u8>, CliError> {
    let mut out = Vec::new();
    let mut enc = png_encoder(&mut out, width, height, style);
    let frames = u32::try_from(count)
        .map_err(|_| CliError::input(format!("{count} frames: too many for a PNG")))?;
    enc.set_animated(frames, 0).map_err(png_err)?;
    enc.set_frame_delay(delay_ms, 1000).map_err(png_err)?;
    let mut writer = enc.write_header().map_err(png_err)?;
    for k in 0..count {
        let rgba = frame(k)?;
        let bytes = png_samples(&rgba, width, height, style)?;
        writer.write_image_data(&bytes).map_err(png_err)?;
    }
    writer.finish().map_err(png_err)?;
    Ok(out)
}

fn png_err(e: png::EncodingError) -> CliError {
    CliError::input(format!("PNG encoder: {e}"))
}

/// The PNG encoder for `style` (colour type, depth, the sRGB chunk) writing into `out`.
fn png_encoder(
    out: &mut Vec<u8>,
    width: usize,
    height: usize,
    style: PngStyle,
) -> png::Encoder<'static, &mut Vec<u8>> {
    let mut enc = png::Encoder::new(out, width as u32, height as u32);
    enc.set_color(if style.alpha {
        png::ColorType::Rgba
    } else {
        png::ColorType::Rgb
    });
    enc.set_depth(if style.sixteen {
        png::BitDepth::Sixteen
    } else {
        png::BitDepth::Eight
    });
    if style.gamma == Gamma::Srgb {
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    enc
}

/// The samples of one PNG image in `style` (see [`encode_png`]), row-major, big-endian at 16 bits.
fn png_samples(
    rgba: &[[f32; 4]],
    width: usize,
    height: usize,
    style: PngStyle,
) -> Result<Vec<u8>, CliError> {
    let channels = if style.alpha { 4 } else { 3 };
    let (top, bytes_per) = if style.sixteen {
        (65535.0, 2)
    } else {
        (255.0, 1)
    };
    let mut bytes: Vec<u8> = Vec::new();
    bytes
        .try_reserve_exact(rgba.len().saturating_mul(channels * bytes_per))
        .map_err(|_| CliError::input(format!("{width}x{height} image: out of memory")))?;
    // A sample in [0, 1] as the nearest level, big-endian at 16 bits as PNG stores it.
    let mut put = |v: f32| {
        let level = (v * top).round() as u16;
        if style.sixteen {
            bytes.extend_from_slice(&level.to_be_bytes());
        } else {
            bytes.push(level as u8);
        }
    };
    for p in rgba {
        let a = if p[3] > 0.0 { p[3].min(1.0) } else { 0.0 };
        let colour = |c: f32| -> f32 {
            let c = c.clamp(0.0, 1.0);
            if !style.alpha {
                c
            } else if a > 0.0 {
                (c / a).min(1.0)
            } else {
                0.0
            }
        };
        for &c in &p[..3] {
            put(style.gamma.encode(colour(c)));
        }
        if style.alpha {
            put(a);
        }
    }
    Ok(bytes)
}

/// Encodes premultiplied RGBA (composited over black, i.e. the colour channels as they are) as an
/// 8-bit RGB PNG. Values are linear and written without a gamma curve, clamped to [0, 1]
/// ([`encode_png`] in the default [`PngStyle`]).
pub fn encode_png_rgb(rgba: &[[f32; 4]], width: usize, height: usize) -> Result<Vec<u8>, CliError> {
    encode_png(rgba, width, height, PngStyle::default())
}

/// Extensions a colour image output may have (`.png`, 8-bit, [`encode_png_rgb`]; `.pfm`, float,
/// [`encode_pfm_rgb`]) and a single-channel one ([`save_grey`]); the lists live with the output
/// checks ([`super::outputs`]).
pub use super::outputs::{GREY_EXTENSIONS, RGB_EXTENSIONS};

/// Encodes a colour PFM (`PF`, scale −1: little-endian float32 RGB, rows bottom to top): the
/// premultiplied colour channels as they are (linear, not clamped), for measuring.
pub fn encode_pfm_rgb(rgba: &[[f32; 4]], width: usize, height: usize) -> Vec<u8> {
    let mut out = format!("PF\n{width} {height}\n-1.0\n").into_bytes();
    out.reserve(rgba.len() * 12);
    for row in rgba.chunks(width.max(1)).rev() {
        for p in row {
            for v in &p[..3] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    out
}

/// `rgba` encoded as the colour image type `path`'s extension names (see [`RGB_EXTENSIONS`];
/// commands check the extension and [`check_style`] before rendering).
pub fn encode_rgb_for(
    path: &Path,
    rgba: &[[f32; 4]],
    width: usize,
    height: usize,
    style: PngStyle,
) -> Result<Vec<u8>, CliError> {
    check_style(path, style)?;
    match super::outputs::extension(path).as_deref() {
        Some("pfm") => Ok(encode_pfm_rgb(rgba, width, height)),
        Some("png") => encode_png(rgba, width, height, style),
        _ => Err(CliError::input(format!(
            "{}: cannot write this image type (use .png or .pfm)",
            path.display()
        ))),
    }
}

/// Refuses a PNG style that `path`'s type cannot hold: a `.pfm` is linear float RGB, so
/// `--background transparent`, `--gamma srgb` and `--depth 16` apply to `.png` only.
pub fn check_style(path: &Path, style: PngStyle) -> Result<(), CliError> {
    if super::outputs::extension(path).as_deref() == Some("pfm") && !style.is_plain() {
        let what = if style.alpha {
            "--background transparent (PFM has no alpha channel)"
        } else if style.gamma != Gamma::Linear {
            "--gamma srgb (PFM holds linear values)"
        } else {
            "--depth 16 (PFM is float32)"
        };
        return Err(CliError::input(format!(
            "{}: {what} applies to .png output only",
            path.display()
        )));
    }
    Ok(())
}

/// Decodes a grey, grey+alpha, RGB or RGBA PNG (8 or 16 bits; palettes and fewer bits are
/// expanded) into premultiplied RGBA f32, values as stored (no transfer curve undone). Returns
/// (width, height, pixels).
pub fn decode_png_rgba(
    bytes: &[u8],
    name: &str,
) -> Result<(usize, usize, Vec<[f32; 4]>), CliError> {
    decode_png_checked(open_png(bytes, name)?, name, Gamma::Linear)
}

/// A PNG reader past the header (size and colour type known, nothing decoded yet).
fn open_png<'a>(
    bytes: &'a [u8],
    name: &str,
) -> Result<png::Reader<std::io::Cursor<&'a [u8]>>, CliError> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    decoder
        .read_info()
        .map_err(|e| CliError::input(format!("{name}: not a readable PNG: {e}")))
}

/// [`decode_png_rgba`] of a PNG that must be `width × height`, its colour channels decoded from
/// `gamma`'s curve to linear (a background under `--gamma srgb` is read as sRGB, so a pixel the
/// volume does not cover is written back unchanged). The size in its header is checked before
/// anything is decoded, so a small file declaring a huge image costs nothing.
pub fn decode_png_rgba_sized(
    bytes: &[u8],
    name: &str,
    (width, height): (usize, usize),
    gamma: Gamma,
) -> Result<(usize, usize, Vec<[f32; 4]>), CliError> {
    let bad = |e: String| CliError::input(format!("{name}: {e}"));
    let reader = open_png(bytes, name)?;
    let info = reader.info();
    if (info.width as usize, info.height as usize) != (width, height) {
        return Err(bad(format!(
            "background is {}x{}, the image is {width}x{height}",
            info.width, info.height
        )));
    }
    decode_png_checked(reader, name, gamma)
}

fn decode_png_checked(
    mut reader: png::Reader<std::io::Cursor<&[u8]>>,
    name: &str,
    gamma: Gamma,
) -> Result<(usize, usize, Vec<[f32; 4]>), CliError> {
    let bad = |e: String| CliError::input(format!("{name}: {e}"));
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| bad("PNG too large".into()))?;
    let mut buf = Vec::new();
    buf.try_reserve_exact(size)
        .map_err(|_| bad("PNG too large".into()))?;
    buf.resize(size, 0u8);
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| bad(format!("corrupt PNG: {e}")))?;
    let (w, h) = (info.width as usize, info.height as usize);
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => return Err(bad(format!("unsupported PNG colour type {other:?}"))),
    };
    let wide = info.bit_depth == png::BitDepth::Sixteen;
    let bytes_per = if wide { 2 } else { 1 };
    let sample = |b: &[u8]| -> f32 {
        if wide {
            f32::from(u16::from_be_bytes([b[0], b[1]])) / 65535.0
        } else {
            f32::from(b[0]) / 255.0
        }
    };
    let stride = channels * bytes_per;
    let px = buf[..w * h * stride]
        .chunks_exact(stride)
        .map(|c| {
            let mut s = [0.0f32; 4];
            for (v, b) in s.iter_mut().zip(c.chunks_exact(bytes_per)) {
                *v = sample(b);
            }
            let (r, g, b, a) = match channels {
                1 => (s[0], s[0], s[0], 1.0),
                2 => (s[0], s[0], s[0], s[1]),
                3 => (s[0], s[1], s[2], 1.0),
                _ => (s[0], s[1], s[2], s[3]),
            };
            let lin = |v: f32| gamma.decode(v) * a;
            [lin(r), lin(g), lin(b), a]
        })
        .collect();
    Ok((w, h, px))
}
