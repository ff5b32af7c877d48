//! `footprint render`: a volume (or the built-in scene) rendered by the core, sheet by sheet, to a
//! PNG (see [`crate::pipeline::prepare`](mod@crate::pipeline::stages::prepare) for the view conventions).

mod orbit;
use crate::args::{plan, RenderArgs};
use crate::charts::colorbar;
use crate::io::image::{check_style, encode_rgb_for, RGB_EXTENSIONS};
use crate::io::outputs::{self, Planned};
use crate::pipeline::depth::DEPTH_EXTENSIONS;
use crate::pipeline::quality::model::quality_json;
use crate::pipeline::{describe, Prepared, Renderer};
use crate::plan::{End, Plan};
use crate::scene::Scene;
use crate::CliError;
use orbit::{check_orbit, orbit};
use std::path::{Path, PathBuf};

/// `footprint render`: the render flags every rendering command shares, and what only a picture
/// for people needs.
#[derive(clap::Args, Debug, Clone)]
pub struct RenderCommandArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// An animated PNG (APNG) of N frames (2 to 360) turning the volume once around its vertical
    /// axis, as ParaView's orbit does: frame k at --view's azimuth + 360·k/N degrees, a full turn
    /// in about 4 s, looping. The volume is loaded and classified once. --out must be a .png.
    #[arg(help_heading = "Picture", long, value_name = "N", value_parser = clap::value_parser!(u16).range(2..=360))]
    pub orbit: Option<u16>,
    /// Draw the transfer function's legend into the image (every frame of an --orbit): its
    /// colours, its opacity as a white line, and the window's values, in a panel at the right.
    #[arg(help_heading = "Picture", long)]
    pub colorbar: bool,
    /// Split the volume into X×Y×Z bricks rendered on their own and composited front to back
    /// (sort-last). Under `mpirun -np N` (a build with the `mpi` feature) rank n renders brick n
    /// and X·Y·Z must be N (default with N > 1: a balanced k-d split into N); in one process the
    /// bricks render in turn. The JSON gains `ranks`, `bricks`, `order` and `per_rank`. See
    /// docs/scale-out.md.
    #[arg(help_heading = "Scale-out", long, value_name = "X,Y,Z", value_parser = crate::args::parse_bricks)]
    pub bricks: Option<[usize; 3]>,
    /// Also write the depth map: per pixel, the screen z where the accumulated opacity first
    /// reaches 0.5, in world units (0 on the plane through the volume's centre, growing away from
    /// the viewer; NaN where it never does), from the frame's continuous model at full
    /// resolution (`.pfm`, single channel, or `.npy`, float32 (height, width), top row first).
    /// See `footprint probe` and docs/depth.md.
    #[arg(help_heading = "Picture", long, value_name = "FILE")]
    pub depth_map: Option<PathBuf>,
}

pub fn run(command: &RenderCommandArgs) -> Result<(), CliError> {
    let args = &command.render;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("footprint.png"));
    let mut planned = vec![Planned {
        flag: "--out",
        path: &out,
        extensions: &RGB_EXTENSIONS,
    }];
    if let Some(j) = &args.json {
        planned.push(Planned {
            flag: "--json",
            path: j,
            extensions: &[],
        });
    }
    if let Some(d) = &command.depth_map {
        planned.push(Planned {
            flag: "--depth-map",
            path: d,
            extensions: &DEPTH_EXTENSIONS,
        });
    }
    args.note_inputs();
    outputs::check(&planned)?;
    check_style(&out, args.png_style())?;
    if command.orbit.is_some() {
        check_orbit(args, &out, command.depth_map.is_some())?;
    }
    if command.depth_map.is_some() && args.blend != crate::args::BlendArg::Composite {
        return Err(CliError::input(
            "--depth-map with --blend: a projection has no depth (no opacity accumulates)",
        ));
    }
    if command.depth_map.is_some() && args.stream.is_some() {
        return Err(CliError::input(
            "--depth-map marches the volume in memory: drop --stream (the volume is loaded)",
        ));
    }
    // Every rule the flags decide, before anything is loaded.
    let asked = Plan {
        bricks: command.bricks,
        ..plan(args)?
    };
    let inputs = crate::args::scene(args)?;
    if let Some(split) = crate::distributed::render_split(&inputs, &asked)? {
        if command.orbit.is_some() || command.colorbar || command.depth_map.is_some() {
            return Err(CliError::input(
                "--orbit, --colorbar and --depth-map render one process's frame: drop --bricks \
                 (or mpirun)",
            ));
        }
        let Some((rgb, summary)) = split else {
            return Ok(());
        };
        return write(args, &out, &rgb, summary);
    }
    if let Some(n) = command.orbit {
        let renderer = Renderer::open(&inputs, &asked)?;
        return orbit(
            renderer,
            args,
            &inputs,
            &out,
            usize::from(n),
            command.colorbar,
        );
    }
    let (mut rgb, summary, p) = single(args, &inputs, &asked)?;
    if command.colorbar {
        colorbar::draw(&mut rgb, args.size, &p.lut, p.data_window())?;
    }
    drop(p);
    let depth = match &command.depth_map {
        Some(d) => vec![(
            d.as_path(),
            crate::pipeline::depth::depth_map(&inputs, &asked, d)?,
        )],
        None => vec![],
    };
    write_files_with(args, Some(&out), &rgb, summary, &depth)
}

/// One frame of `args` (with `inputs` and the plan `asked` resolved from them) as `footprint
/// render` draws it without `--orbit`, `--colorbar` or a split: the premultiplied RGBA image at
/// the output size, its JSON summary (without `out`) and what was prepared. What the Python
/// package's `render` calls too.
pub fn single(
    args: &RenderArgs,
    inputs: &Scene,
    asked: &Plan,
) -> Result<(Vec<[f32; 4]>, crate::io::json::Json, Prepared), CliError> {
    let (frame, renderer) = crate::pipeline::render(inputs, asked)?;
    let (p, plan, choice) = renderer.into_parts();
    let (rgb, summary) = if plan.end == End::Reference {
        crate::say!("{}: f64 reference render in {:.3} s", p.name, frame.seconds);
        (
            frame.image,
            describe(&p, inputs, &plan).num("seconds", frame.seconds),
        )
    } else {
        let (img, stats, secs) = (frame.image, frame.stats, frame.seconds);
        if let Some(r) = &frame.refine {
            crate::say!(
                "{}: refined at {}: {} samples from {} (intervals at factors 1/2/4 along i {:?}, j {:?}, k {:?})",
                p.name,
                r.threshold,
                r.samples,
                r.coarse_samples,
                r.counts()[0],
                r.counts()[1],
                r.counts()[2]
            );
        }
        crate::say!(
            "{}: {}x{}{} in {:.3} s; {} sheets along {}, {} voxels ({} splatted{}), {} pixel updates, {} composites",
            p.name,
            args.size.0,
            args.size.1,
            match (p.supersample, p.subsample_factor(&plan)?) {
                (1, 1) => String::new(),
                (1, s) => format!(" (subsampled: rendered at 1/{s} and resampled)"),
                (k, _) => format!(" (supersampled {k}x: voxels project closer than --min-radius)"),
            },
            secs,
            stats.sheets,
            ["i", "j", "k"][p.frame.sheet_axis],
            stats.voxels,
            stats.voxels_splatted,
            if frame.threads > 1 {
                format!(
                    ", counted in each of the {} bands of rows a voxel reaches",
                    frame.threads
                )
            } else {
                String::new()
            },
            stats.pixel_updates,
            stats.pixels_composited
        );
        let j = describe(&p, inputs, &plan)
            .num("seconds", secs)
            .num("sheets", stats.sheets as f64)
            .num("voxels", stats.voxels as f64)
            .num("voxels_splatted", stats.voxels_splatted as f64)
            .num("bands", frame.threads as f64)
            .num("pixel_updates", stats.pixel_updates as f64)
            .num("pixels_composited", stats.pixels_composited as f64)
            .num("culled_voxels", stats.culled_voxels as f64);
        let j = match &frame.refine {
            Some(r) => j.obj("refine", r.json()),
            None => j,
        };
        (img, j)
    };
    let summary = match &choice {
        Some(c) => summary.obj("quality", quality_json(c)),
        None => summary,
    };
    let summary = match crate::distributed::peak_memory_bytes() {
        Some(m) => summary.num("peak_memory_bytes", m as f64),
        None => summary,
    };
    Ok((rgb, summary, p))
}

/// Writes the image and the JSON summary (all or nothing).
fn write(
    args: &RenderArgs,
    out: &Path,
    rgb: &[[f32; 4]],
    summary: crate::io::json::Json,
) -> Result<(), CliError> {
    write_files(args, Some(out), rgb, summary)
}

/// [`write_files`] and more files with them (`--depth-map`), all or nothing.
fn write_files_with(
    args: &RenderArgs,
    out: Option<&Path>,
    rgb: &[[f32; 4]],
    summary: crate::io::json::Json,
    more: &[(&Path, Vec<u8>)],
) -> Result<(), CliError> {
    let image = match out {
        Some(o) => Some(encode_rgb_for(
            o,
            rgb,
            args.size.0,
            args.size.1,
            args.png_style(),
        )?),
        None => None,
    };
    let summary = match out {
        Some(o) => summary.str("out", &o.display().to_string()),
        None => summary,
    }
    .finish();
    let mut files: Vec<(&Path, &[u8])> = Vec::new();
    if let (Some(o), Some(image)) = (out, &image) {
        files.push((o, image.as_slice()));
    }
    if let Some(j) = &args.json {
        files.push((j.as_path(), summary.as_bytes()));
    }
    files.extend(more.iter().map(|(p, b)| (*p, b.as_slice())));
    outputs::write_all(&files)?;
    for (path, _) in files
        .iter()
        .filter(|(p, _)| Some(*p) != args.json.as_deref())
    {
        crate::say!("wrote {}", path.display());
    }
    Ok(())
}

/// Writes the image to `out` (if any) and the JSON summary to `--json` (if given), all or
/// nothing: what `render` writes, for a program that renders with [`single`] (Python's
/// `render(out=..., json=...)`). Check the paths with [`crate::io::outputs::check_image_and_json`]
/// before rendering.
pub fn write_files(
    args: &RenderArgs,
    out: Option<&Path>,
    rgb: &[[f32; 4]],
    summary: crate::io::json::Json,
) -> Result<(), CliError> {
    write_files_with(args, out, rgb, summary, &[])
}
