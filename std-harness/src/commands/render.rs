//! `footprint render`: a volume (or the built-in scene) rendered by the core, sheet by sheet, to a
//! PNG (see [`crate::pipeline::prepare`](mod@crate::pipeline::prepare) for the view conventions).

use crate::args::{MethodArg, RenderArgs};
use crate::io::image::{check_style, encode_rgb_for, RGB_EXTENSIONS};
use crate::io::outputs::{self, Planned};
use crate::pipeline::visible::FrameCache;
use crate::pipeline::{choose::apply_quality, quality::quality_json};
use crate::pipeline::{describe, prepare, render_frame, render_ref};
use crate::CliError;
use std::path::PathBuf;

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
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
    args.note_inputs();
    outputs::check(&planned)?;
    check_style(&out, args.png_style())?;
    let (p, args, choice) = apply_quality(prepare(args)?, args)?;
    let args = &args;
    let (rgb, summary) = if args.footprint.method == MethodArg::Reference {
        let (img, secs) = render_ref(&p)?;
        let rgb: Vec<[f32; 4]> = img.iter().map(|c| c.map(|x| x as f32)).collect();
        crate::say!("{}: f64 reference render in {:.3} s", p.name, secs);
        (rgb, describe(&p, args).num("seconds", secs))
    } else {
        let frame = render_frame(&p, args, args.accum, &mut FrameCache::default())?;
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
            match (p.supersample, p.subsample_factor(args)?) {
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
        let j = describe(&p, args)
            .num("seconds", secs)
            .num("sheets", stats.sheets as f64)
            .num("voxels", stats.voxels as f64)
            .num("voxels_splatted", stats.voxels_splatted as f64)
            .num("bands", frame.threads as f64)
            .num("pixel_updates", stats.pixel_updates as f64)
            .num("pixels_composited", stats.pixels_composited as f64);
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
    let image = encode_rgb_for(&out, &rgb, args.size.0, args.size.1, args.png_style())?;
    let summary = summary.str("out", &out.display().to_string()).finish();
    let mut files = vec![(out.as_path(), image.as_slice())];
    if let Some(j) = &args.json {
        files.push((j.as_path(), summary.as_bytes()));
    }
    outputs::write_all(&files)?;
    crate::say!("wrote {}", out.display());
    Ok(())
}
