//! `render --orbit N`: an animated PNG of N frames turning the volume once around its vertical
//! axis, from one `Renderer` (the volume loaded and classified once).

use crate::args::{MethodArg, RenderArgs};
use crate::charts::colorbar;
use crate::io::image::encode_apng;
use crate::io::outputs;
use crate::pipeline::{describe, Renderer};
use crate::scene::Scene;
use crate::CliError;
use std::path::Path;
use std::time::Instant;

/// What `--orbit` cannot do, refused before the volume is loaded: another output than a PNG, the
/// f64 reference, a pipe (each frame reads the volume again).
pub fn check_orbit(args: &RenderArgs, out: &Path, depth_map: bool) -> Result<(), CliError> {
    if depth_map {
        return Err(CliError::input(
            "--depth-map is one frame's: render without --orbit",
        ));
    }
    if crate::io::outputs::extension(out).as_deref() != Some("png") {
        return Err(CliError::input(format!(
            "--orbit writes an animated PNG: {} is not a .png",
            out.display()
        )));
    }
    if args.footprint.method == MethodArg::Reference {
        return Err(CliError::input(
            "--orbit renders with the core: --method reference is one frame (render without --orbit)",
        ));
    }
    if args
        .stream
        .as_deref()
        .is_some_and(crate::io::stream::is_stdin)
    {
        return Err(CliError::input(
            "--orbit renders the volume once per frame, and standard input can be read once: \
             give the volume as a file (VOLUME, or --stream FILE)",
        ));
    }
    Ok(())
}

/// `--orbit N`: N frames a 360/N-degree turn apart, reusing the loaded volume, its level and its
/// visible-voxel lists, encoded into one animated PNG as they come.
pub fn orbit(
    mut r: Renderer,
    args: &RenderArgs,
    inputs: &Scene,
    out: &Path,
    n: usize,
    bar: bool,
) -> Result<(), CliError> {
    let start = Instant::now();
    let delay = (4000 / n).clamp(20, 1000) as u16;
    let image = encode_apng(args.size, args.png_style(), n, delay, |k| {
        if k > 0 {
            r.reframe(&inputs.turned(360.0 * k as f32 / n as f32))?;
        }
        let mut f = r.frame()?.0;
        let p = r.prepared();
        crate::say!("{}: frame {}/{n} in {:.3} s", p.name, k + 1, f.seconds);
        if bar {
            colorbar::draw(&mut f.image, args.size, &p.lut, p.data_window())?;
        }
        Ok(f.image)
    })?;
    let secs = start.elapsed().as_secs_f64();
    let (p, plan) = (r.prepared(), r.plan());
    let summary = describe(p, inputs, plan)
        .num("frames", n as f64)
        .num("frame_delay_ms", f64::from(delay))
        .num("seconds", secs)
        .str("out", &out.display().to_string())
        .finish();
    let mut files = vec![(out, image.as_slice())];
    if let Some(j) = &args.json {
        files.push((j.as_path(), summary.as_bytes()));
    }
    outputs::write_all(&files)?;
    crate::say!("wrote {} ({n} frames, {secs:.2} s)", out.display());
    Ok(())
}
