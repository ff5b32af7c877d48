//! The embedded demo scene rendered on the host: prints the same lines the firmware prints for
//! its checksums, so CI can compare them (`fixed checksum 0x…` must match bit for bit).
//!
//! ```text
//! footprint-scene-host [--threads N]     checksums: 64×64 (MPS2 boards), 48×48 (micro:bit),
//!                                        32×32 (STM32F100, compact only), and each orbit
//! footprint-scene-host compare LOG DIR   the firmware's image (from its printed LOG) against
//!                                        the host's float render: PNGs in DIR and the PSNR
//! ```
//!
//! The host renders the whole image at once (one band) and, to show that bands change nothing,
//! again in bands of 1, 2 and 5 rows: every band height must give the same checksum. `--threads N`
//! renders it on N threads at once and checks they all agree.

use footprint::composite::RowSpan;
use footprint::fixed::FixedTable;
use footprint::ViewTable;
use footprint_scene::display::{send_band, send_band_q15, CrcDisplay};
use footprint_scene::{compact_lut, compact_stencil_len, render_compact, CompactBuffers};
use footprint_scene::{render_fixed, render_float, FixedBuffers, FloatBuffers, Report};
use footprint_scene::{SIDE, SIDE_M4F_LARGE, SIDE_MICROBIT, SIDE_STM32};

/// Frames of the firmware's orbit (its `FRAMES`).
const ORBIT_FRAMES: usize = 4;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.as_slice() {
        [] => checksums(1),
        [flag, n] if flag == "--threads" => match n.parse::<usize>() {
            Ok(n) if n >= 1 => checksums(n),
            _ => Err(format!("--threads needs a whole number ≥ 1, got '{n}'")),
        },
        [cmd, log, dir] if cmd == "compare" => compare(log, dir),
        _ => Err("usage: footprint-scene-host [--threads N] | compare LOG DIR".into()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("footprint-scene-host: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The scene's promise to the renderer ([`footprint_scene::occupied`]): every non-zero sample
/// lies in its row's range, whichever axis the sheets and rows run along.
fn check_occupied() -> Result<(), String> {
    use footprint_scene::{occupied, sample, DIM};
    for i in 0..DIM {
        for j in 0..DIM {
            for k in 0..DIM {
                let nonzero = sample(i, j, k) != 0;
                let held = [
                    (i, j, k),
                    (j, k, i),
                    (k, i, j),
                    (j, i, k),
                    (i, k, j),
                    (k, j, i),
                ]
                .iter()
                .all(|&(s, v, u)| occupied(s, v).contains(&u));
                if nonzero && !held {
                    return Err(format!(
                        "sample ({i}, {j}, {k}) is outside its row's occupied range"
                    ));
                }
            }
        }
    }
    Ok(())
}

fn checksums(threads: usize) -> Result<(), String> {
    check_occupied()?;
    let fixed = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| s.spawn(|| fixed_image(SIDE, SIDE)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("render thread panicked"))
            .collect::<Result<Vec<_>, _>>()
    })?;
    let (report, _) = &fixed[0];
    if fixed.iter().any(|(r, _)| r.checksum != report.checksum) {
        return Err("threads disagree".into());
    }
    for side in [SIDE, SIDE_MICROBIT] {
        let whole = fixed_image(side, side)?.0.checksum;
        for band in [1, 2, 5] {
            let banded = fixed_image(side, band)?.0.checksum;
            if banded != whole {
                return Err(format!(
                    "{side}x{side}: bands of {band} rows give 0x{banded:08x}, the whole image 0x{whole:08x}"
                ));
            }
        }
    }
    let float = float_image(SIDE, SIDE)?.0;
    let stats = report.stats;
    println!(
        "scene: {} sheets, {} voxels splatted, {} pixel updates ({threads} thread(s) agree; bands of 1, 2, 5 rows agree)",
        stats.sheets, stats.voxels_splatted, stats.pixel_updates
    );
    println!("fixed checksum 0x{:08x}", report.checksum);
    println!(
        "microbit fixed checksum 0x{:08x}",
        fixed_image(SIDE_MICROBIT, SIDE_MICROBIT)?.0.checksum
    );
    println!("float checksum 0x{:08x} (informational)", float.checksum);
    // The compact path (what the firmware renders by default): each board's size, whole and
    // in bands, and its orbit, all through one shading table (it is view-independent).
    let lut = compact_shading()?;
    for (name, side) in [
        ("", SIDE),
        ("microbit ", SIDE_MICROBIT),
        ("stm32 ", SIDE_STM32),
        ("m4f128 ", SIDE_M4F_LARGE),
    ] {
        let (r, img) = compact_image(&lut, side, side, 0)?;
        for band in [1, 2, 5] {
            let banded = compact_image(&lut, side, band, 0)?.0.checksum;
            if banded != r.checksum {
                return Err(format!(
                    "compact {side}x{side}: bands of {band} rows give 0x{banded:08x}, the whole image 0x{:08x}",
                    r.checksum
                ));
            }
        }
        let rgb = |c: [f32; 4]| [0, 1, 2].map(|i| f64::from(c[i]));
        let float: Vec<[f64; 3]> = float_image(side, side)?.1.into_iter().map(rgb).collect();
        let q: Vec<[f64; 3]> = img
            .iter()
            .map(|&p| rgb(footprint::fixed::compact::to_f32(p)))
            .collect();
        println!(
            "{name}compact checksum 0x{:08x} ({side}x{side}, {} pixel updates, psnr_vs_float {:.2} dB)",
            r.checksum,
            r.stats.pixel_updates,
            psnr(&q, &float)
        );
        // Frame 0 is the render above; the later frames turn the view.
        let mut orbit = vec![r.checksum];
        for step in 1..ORBIT_FRAMES {
            orbit.push(compact_image(&lut, side, side, step)?.0.checksum);
        }
        let orbit: Vec<String> = orbit.iter().map(|c| format!("0x{c:08x}")).collect();
        println!("{name}orbit checksums {}", orbit.join(" "));
        let mut display = CrcDisplay::new(side);
        send_band_q15(0, side, &img, &mut vec![0; side], &mut display)
            .map_err(|e| format!("rows to the display: {e}"))?;
        let (crc, drawn) = display.finish();
        println!(
            "{name}compact rgb565 crc 0x{crc:08x} ({drawn} pixels through the embedded-graphics adaptor)"
        );
    }
    for (name, side) in [("", SIDE), ("microbit ", SIDE_MICROBIT)] {
        // The whole image as one band through the same adaptor the firmware sends its bands
        // through: bands change neither the rows nor their order.
        let image = fixed_image(side, side)?.1;
        let mut display = CrcDisplay::new(side);
        send_band(0, side, &image, &mut vec![0; side], &mut display)
            .map_err(|e| format!("rows to the display: {e}"))?;
        let (crc, drawn) = display.finish();
        println!(
            "{name}rgb565 crc 0x{crc:08x} ({drawn} pixels through the embedded-graphics adaptor)"
        );
    }
    Ok(())
}

/// The fixed render at `side`² in bands of `band` rows, with heap buffers: its report and image
/// (Q24 premultiplied RGBA, row-major).
fn fixed_image(side: usize, band: usize) -> Result<(Report, Vec<[u32; 4]>), String> {
    let band = band.min(side);
    let mut image = vec![[0u32; 4]; side * side];
    let report = render_fixed(
        side,
        FixedBuffers {
            table: &mut Box::new(FixedTable::zeroed()),
            lut: &mut Box::new([[0; 4]; 256]),
            acc: &mut vec![[0; 4]; band * side],
            image: &mut vec![[0; 4]; band * side],
            rows: &mut vec![RowSpan::EMPTY; band],
        },
        |first, px| image[first * side..first * side + px.len()].copy_from_slice(px),
    )
    .map_err(|e| format!("fixed render failed: {e}"))?;
    Ok((report, image))
}

/// The compact path's shading table ([`compact_lut`]).
fn compact_shading() -> Result<Box<[[u16; 4]; 256]>, String> {
    let mut lut = Box::new([[0u16; 4]; 256]);
    compact_lut(&mut lut).map_err(|e| format!("compact shading table: {e}"))?;
    Ok(lut)
}

/// The compact render of orbit frame `step` at `side`² in bands of `band` rows, shaded through
/// `lut`: its report and image (Q15 premultiplied RGBA, row-major).
fn compact_image(
    lut: &[[u16; 4]; 256],
    side: usize,
    band: usize,
    step: usize,
) -> Result<(Report, Vec<[u16; 4]>), String> {
    let band = band.min(side);
    let mut image = vec![[0u16; 4]; side * side];
    let report = render_compact(
        side,
        step,
        lut,
        CompactBuffers {
            stencils: &mut vec![0; compact_stencil_len(side)],
            acc: &mut vec![[0; 4]; band * side],
            image: &mut vec![[0; 4]; band * side],
            rows: &mut vec![RowSpan::EMPTY; band],
        },
        |first, px| image[first * side..first * side + px.len()].copy_from_slice(px),
    )
    .map_err(|e| format!("compact render failed: {e}"))?;
    Ok((report, image))
}

/// PSNR (dB, peak 1) of `a` against `b`, over every R, G and B value.
fn psnr(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let mse = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        / (3 * a.len()) as f64;
    if mse > 0.0 {
        10.0 * (1.0 / mse).log10()
    } else {
        f64::INFINITY
    }
}

/// The float render at `side`² in bands of `band` rows: its report and image.
fn float_image(side: usize, band: usize) -> Result<(Report, Vec<[f32; 4]>), String> {
    let band = band.min(side);
    let mut image = vec![[0f32; 4]; side * side];
    let report = render_float(
        side,
        FloatBuffers {
            table: &mut Box::new(ViewTable::zeroed(footprint::Footprint::EMPTY)),
            acc: &mut vec![[0.0; 4]; band * side],
            image: &mut vec![[0.0; 4]; band * side],
            rows: &mut vec![RowSpan::EMPTY; band],
        },
        |first, px| image[first * side..first * side + px.len()].copy_from_slice(px),
    )
    .map_err(|e| format!("float render failed: {e}"))?;
    Ok((report, image))
}

/// The image a firmware printed: `image W H`, then `row Y` followed by W pixels of four 8-digit
/// hex Q24 channels (R G B A), one line per row.
fn parse_dump(text: &str) -> Result<(usize, Vec<[u32; 4]>), String> {
    let mut lines = text.lines().map(str::trim);
    let side = lines
        .by_ref()
        .find_map(|l| l.strip_prefix("image "))
        .ok_or("no 'image W H' line")?;
    let dims: Vec<usize> = side
        .split(' ')
        .map(|v| v.parse().map_err(|_| format!("bad image size '{side}'")))
        .collect::<Result<_, _>>()?;
    let [w, h] = dims[..] else {
        return Err(format!("bad image size '{side}'"));
    };
    if w != h || w == 0 || w > 1024 {
        return Err(format!("unexpected image size {w}x{h}"));
    }
    let mut image = vec![[0u32; 4]; w * h];
    let mut seen = vec![false; h];
    for l in lines {
        let Some(rest) = l.strip_prefix("row ") else {
            continue;
        };
        let (y, hex) = rest.split_once(' ').ok_or("a row without pixels")?;
        let y: usize = y.parse().map_err(|_| format!("bad row number '{y}'"))?;
        if y >= h || hex.len() != 32 * w {
            return Err(format!(
                "row {y}: {} hex digits, expected {}",
                hex.len(),
                32 * w
            ));
        }
        for (x, px) in image[y * w..(y + 1) * w].iter_mut().enumerate() {
            for (c, v) in px.iter_mut().enumerate() {
                let at = 32 * x + 8 * c;
                *v = u32::from_str_radix(&hex[at..at + 8], 16)
                    .map_err(|_| format!("row {y}: bad hex"))?;
            }
        }
        seen[y] = true;
    }
    if let Some(y) = seen.iter().position(|s| !s) {
        return Err(format!("row {y} missing"));
    }
    Ok((w, image))
}

/// 8-bit RGB PNG of premultiplied colour over black, linear, clamped (as `footprint render`).
fn write_png(path: &std::path::Path, side: usize, rgb: &[[f64; 3]]) -> Result<(), String> {
    let bytes: Vec<u8> = rgb
        .iter()
        .flatten()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), side as u32, side as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let err = |e: png::EncodingError| format!("{}: {e}", path.display());
    let mut w = enc.write_header().map_err(err)?;
    w.write_image_data(&bytes).map_err(err)?;
    w.finish().map_err(err)
}

/// `compare LOG DIR`: the firmware's printed image against the host's float render of the same
/// scene. Checks the image's CRC is the host's fixed checksum, writes `DIR/microbit.png` and
/// `DIR/host-float.png`, and prints `psnr_vs_float N dB` (RGB, values in [0, 1], peak 1).
fn compare(log: &str, dir: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(log).map_err(|e| format!("{log}: {e}"))?;
    let (side, target) = parse_dump(&text)?;
    // A compact firmware printed Q15 widened to Q24: its CRC is over the Q15 image.
    let compact = text.lines().any(|l| l.starts_with("compact checksum"));
    let (crc, host) = if compact {
        let q15 = target
            .iter()
            .map(|p| {
                let q = p.map(|c| (c >> 9) as u16);
                (footprint::fixed::compact::to_q24(q) == *p)
                    .then_some(q)
                    .ok_or("a compact image pixel that is not Q15")
            })
            .collect::<Result<Vec<_>, _>>()?;
        let crc = footprint::fixed::compact::checksum(&q15);
        (
            crc,
            compact_image(&*compact_shading()?, side, side, 0)?
                .0
                .checksum,
        )
    } else {
        (
            footprint::fixed::checksum(&target),
            fixed_image(side, side)?.0.checksum,
        )
    };
    if crc != host {
        return Err(format!(
            "the printed image's CRC 0x{crc:08x} is not the host's checksum 0x{host:08x}"
        ));
    }
    let (_, float) = float_image(side, side)?;
    let to_rgb = |c: [f32; 4]| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])];
    let target_rgb: Vec<[f64; 3]> = target
        .iter()
        .map(|&c| to_rgb(footprint::fixed::to_f32(c)))
        .collect();
    let float_rgb: Vec<[f64; 3]> = float.iter().map(|&c| to_rgb(c)).collect();
    let psnr = psnr(&target_rgb, &float_rgb);
    let dir = std::path::Path::new(dir);
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    write_png(&dir.join("microbit.png"), side, &target_rgb)?;
    write_png(&dir.join("host-float.png"), side, &float_rgb)?;
    let path = if compact { "compact" } else { "fixed" };
    println!("image {side}x{side}, crc 0x{crc:08x} (= host {path}), psnr_vs_float {psnr:.2} dB");
    Ok(())
}
