//! `footprint probe VOLUME --at X,Y` and `render --depth-map FILE` (issue 77): where each pixel's
//! ray reaches an accumulated opacity of one half, in the continuous model of the frame
//! (`pipeline::ends::continuous::probes`: the f64 march, kernel reconstruction, the frame's
//! absorption model or post-classification), at full resolution (level 0) and at the output
//! size whatever the frame's own plan chose for its picture.
//!
//! The march halves its step until the image of the rays marched converges
//! (`reference::continuous`), so a probe, which marches one ray, may stop at another step than
//! the depth map at the same pixel: the two agree within that convergence (0.007 world units on
//! the slab of `python/tests`), not bit for bit.
//!
//! Units and conventions: depth is the screen z of the crossing in world units, 0 on the plane
//! through the volume's centre, growing away from the viewer; the world point has the volume's
//! centre at the origin (grid axes times their spacing); the value is the data's, trilinear
//! between the samples. Pixels are (x, y), (0, 0) the top-left one, x right, y down.

use crate::args::RenderArgs;
use crate::io::json::Json;
use crate::io::outputs;
use crate::pipeline::depth::{probes, Probe};
use crate::CliError;
use clap::Args;

#[derive(Args, Debug, Clone)]
pub struct ProbeArgs {
    /// The scene and every render flag (`--json` writes the probe).
    #[command(flatten)]
    pub render: RenderArgs,
    /// The pixel whose ray is probed: X,Y ((0, 0) the top-left pixel, x right, y down).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    pub at: [usize; 2],
}

fn parse_pixel(s: &str) -> Result<[usize; 2], String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("'{s}' is not X,Y"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{v}' is not a pixel index (a whole number ≥ 0)"))
    };
    Ok([n(x)?, n(y)?])
}

pub fn run(args: &ProbeArgs) -> Result<(), CliError> {
    let r = &args.render;
    // Inputs first, so that a --json naming one of them is refused before any work.
    r.note_inputs();
    outputs::check_image_and_json(None, r.json.as_deref())?;
    let [x, y] = args.at;
    let (found, secs) = probe_frame(r, Some(&[args.at]))?;
    let p = found[0];
    if p.depth.is_nan() {
        crate::say!("probe ({x}, {y}): the accumulated opacity never reaches 0.5 on this ray");
    } else {
        let [wx, wy, wz] = p.world;
        crate::say!(
            "probe ({x}, {y}): depth {:.4} world units; world point ({wx:.4}, {wy:.4}, {wz:.4}); \
             value {} (the continuous model's crossing of opacity 0.5, {secs:.3} s)",
            p.depth,
            p.value
        );
    }
    if let Some(j) = &r.json {
        let json = Json::object()
            .arr_usize("pixel", &args.at)
            .num("depth", p.depth)
            .arr_f64("world", &p.world)
            .num("value", p.value)
            .num("seconds", secs);
        outputs::write_one(j, json.finish().as_bytes())?;
    }
    Ok(())
}

/// The [`Probe`]s of `args`' frame at the listed pixels (every pixel, row-major, for None), and
/// their seconds ([`crate::pipeline::depth::probes`] of the resolved request).
pub fn probe_frame(
    args: &RenderArgs,
    pixels: Option<&[[usize; 2]]>,
) -> Result<(Vec<Probe>, f64), CliError> {
    probes(
        &crate::args::scene(args)?,
        &crate::args::plan(args)?,
        pixels,
    )
}
