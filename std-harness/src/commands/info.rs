//! `footprint info VOLUME`: what a volume file holds, before rendering it: dimensions, spacing,
//! sample type, orientation, value range, percentiles, and the window `render` would use.

use crate::args::RenderArgs;
use crate::io::json::Json;
use crate::io::outputs::{self, Planned};
use crate::io::volume::Samples;
use crate::pipeline::stages::load::raw_options;
use crate::pipeline::stages::window;
use crate::CliError;
use clap::Args;

#[derive(Args, Debug, Clone)]
pub struct InfoArgs {
    /// The volume (as `render` takes it: --dims, --type, --spacing and --array apply).
    #[command(flatten)]
    pub render: RenderArgs,
}

/// The percentiles printed, in percent.
const PERCENTILES: [f64; 7] = [1.0, 5.0, 25.0, 50.0, 75.0, 95.0, 99.0];

pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let r = &args.render;
    let path = r.volume.as_deref().ok_or_else(|| {
        CliError::input("info needs a VOLUME (the built-in scene is described in the README)")
    })?;
    r.note_inputs();
    if let Some(j) = &r.json {
        outputs::check(&[Planned {
            flag: "--json",
            path: j,
            extensions: &[],
        }])?;
    }
    let raw = raw_options(&crate::plan::Inputs::from(r))?;
    let v = crate::io::formats::load_array(path, raw.as_ref(), r.array.as_deref())?;
    let ty = match &v.samples {
        Samples::U8(_) => "uint8",
        Samples::I8(_) => "int8",
        Samples::U16(_) => "uint16",
        Samples::I16(_) => "int16",
        Samples::U32(_) => "uint32",
        Samples::I32(_) => "int32",
        Samples::F32(_) => "float32",
        Samples::F64(_) => "float64",
        Samples::Coloured(_) => "coloured",
    };
    let n = v.len();
    let (lo, hi) = v.range();
    // Every finite sample, or an evenly strided sample of them (the percentiles' source, and
    // the default window's, as render takes it).
    let step = crate::io::volume::sample_stride(n);
    let sample = v.strided_sample();
    let missing = (0..n).filter(|&i| !v.value(i).is_finite()).count();
    let at = |p: f64| {
        if sample.is_empty() {
            f32::NAN
        } else {
            window::percentile(&sample, p)
        }
    };
    let pcts: Vec<f64> = PERCENTILES.iter().map(|&p| f64::from(at(p))).collect();
    let window = match (r.window, window::auto_window(&sample)) {
        (Some(w), _) => (w, "--window".to_string()),
        (None, Some(w)) => (w, format!("{}; --window LO,HI to change", window::RULE)),
        (None, None) => (
            [lo, hi],
            "the data's range; --window LO,HI to change".into(),
        ),
    };
    let [nx, ny, nz] = v.dims;
    let name = path.display();
    crate::say!(
        "{name}: {nx}x{ny}x{nz} {ty}, {n} voxels ({} bytes in memory)",
        v.bytes()
    );
    crate::say!(
        "spacing: {} x {} x {} world units per voxel (i, j, k)",
        v.spacing[0],
        v.spacing[1],
        v.spacing[2]
    );
    let d = v.directions;
    crate::say!(
        "orientation: i -> {:?}, j -> {:?}, k -> {:?} (world directions)",
        d[0],
        d[1],
        d[2]
    );
    crate::say!("values: min {lo}, max {hi}; {missing} not finite (NaN or infinite: transparent)");
    let list: Vec<String> = PERCENTILES
        .iter()
        .zip(&pcts)
        .map(|(p, x)| format!("{p} %: {x}"))
        .collect();
    crate::say!(
        "percentiles of the finite values{}: {}",
        if step > 1 {
            format!(" (every {step}th sample)")
        } else {
            String::new()
        },
        list.join(", ")
    );
    crate::say!(
        "window render uses: {},{} ({})",
        window.0[0],
        window.0[1],
        window.1
    );
    if let Some(j) = &r.json {
        let mut p = Json::object();
        for (q, x) in PERCENTILES.iter().zip(&pcts) {
            p = p.num(&format!("{q}"), *x);
        }
        let json = Json::object()
            .str("volume", &name.to_string())
            .arr_usize("dims", &v.dims)
            .str("type", ty)
            .arr_f64("spacing", &v.spacing.map(f64::from))
            .arr_f64(
                "directions",
                &d.concat().iter().map(|&x| f64::from(x)).collect::<Vec<_>>(),
            )
            .arr_f64("range", &[f64::from(lo), f64::from(hi)])
            .num("not_finite", missing as f64)
            .obj("percentiles", p)
            .num("percentile_stride", step as f64)
            .arr_f64("window", &window.0.map(f64::from))
            .str("window_rule", &window.1)
            .finish();
        outputs::write_one(j, json.as_bytes())?;
    }
    Ok(())
}
