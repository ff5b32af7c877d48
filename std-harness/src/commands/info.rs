//! `footprint info VOLUME`: what a volume file holds, before rendering it: dimensions, spacing,
//! sample type, orientation, value range, percentiles, and the window `render` would use.

use crate::args::RenderArgs;
use crate::io::json::Json;
use crate::io::outputs::{self, Planned};
use crate::io::volume::{Samples, Volume};
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
    let raw = raw_options(&crate::args::scene(r)?)?;
    let v = crate::io::formats::load_array(path, raw.as_ref(), r.array.as_deref())?;
    let report = Report::of(&v, path.display().to_string(), r.window);
    report.print(&v);
    if let Some(j) = &r.json {
        outputs::write_one(j, report.json(&v).finish().as_bytes())?;
    }
    Ok(())
}

/// What `info` says of a volume, in the data's own units (f64), whatever the renderer's values.
struct Report {
    name: String,
    ty: &'static str,
    /// Finite range, data units ((+∞, −∞) where none is finite).
    range: (f64, f64),
    missing: usize,
    /// The percentiles' sample stride, and the percentiles ([`PERCENTILES`]), data units.
    step: usize,
    percentiles: Vec<f64>,
    /// What is not held exactly ([`held_exactly`]).
    held: Option<String>,
    /// The window render would take (renderer's values) and its rule, or why render refuses.
    window: Result<([f32; 2], String), CliError>,
}

impl Report {
    fn of(v: &Volume, name: String, given: Option<[f64; 2]>) -> Report {
        let map = v.values;
        let n = v.len();
        let (lo, hi) = v.range();
        let range = if lo <= hi {
            (map.to_data(lo), map.to_data(hi))
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        };
        // Every finite sample, or an evenly strided sample of them (the percentiles' source, and
        // the default window's, as render takes it).
        let sample = v.strided_sample();
        let at = |p: f64| match sample.is_empty() {
            true => f32::NAN,
            false => window::percentile(&sample, p),
        };
        // The window render would take, by render's own rules, or why render would refuse.
        let window = match (given, window::auto_window(&sample)) {
            (Some(w), _) => window::check_given(w, map).map(|w| (w, "--window".to_string())),
            (None, Some(w)) => Ok((w, format!("{}; --window LO,HI to change", window::RULE))),
            (None, None) => window::range_window(&name, lo, hi)
                .map(|w| (w, "the data's range; --window LO,HI to change".into())),
        };
        Report {
            ty: type_name(&v.samples),
            range,
            missing: (0..n).filter(|&i| !v.value(i).is_finite()).count(),
            step: crate::io::volume::sample_stride(n),
            percentiles: PERCENTILES.iter().map(|&p| map.to_data(at(p))).collect(),
            held: held_exactly(v),
            window,
            name,
        }
    }

    fn print(&self, v: &Volume) {
        let ([nx, ny, nz], name, ty) = (v.dims, &self.name, self.ty);
        let n = v.len();
        crate::say!(
            "{name}: {nx}x{ny}x{nz} {ty}, {n} voxels ({} bytes in memory)",
            v.bytes()
        );
        let s = v.spacing;
        let mean = if v.grid.is_some() { " (the mean)" } else { "" };
        crate::say!(
            "spacing: {} x {} x {} world units per voxel (i, j, k){mean}",
            s[0],
            s[1],
            s[2]
        );
        if let Some(g) = &v.grid {
            crate::say!("grid: {} world units between neighbours", g.describe());
        }
        let d = v.directions;
        crate::say!(
            "orientation: i -> {:?}, j -> {:?}, k -> {:?} (world directions)",
            d[0],
            d[1],
            d[2]
        );
        crate::say!(
            "values: min {}, max {}; {} not finite (NaN or infinite: transparent)",
            num(self.range.0),
            num(self.range.1),
            self.missing
        );
        if let Some(note) = &self.held {
            crate::say!("precision: {note}");
        }
        let list: Vec<String> = PERCENTILES
            .iter()
            .zip(&self.percentiles)
            .map(|(p, x)| format!("{p} %: {}", num(*x)))
            .collect();
        let stride = match self.step {
            1 => String::new(),
            step => format!(" (every {step}th sample)"),
        };
        crate::say!(
            "percentiles of the finite values{stride}: {}",
            list.join(", ")
        );
        match &self.window {
            Ok((w, rule)) => {
                let [a, b] = v.values.window_to_data(*w);
                crate::say!("window render uses: {},{} ({rule})", num(a), num(b))
            }
            Err(e) => crate::say!("window render uses: none: render refuses this volume ({e})"),
        }
    }

    fn json(&self, v: &Volume) -> Json {
        let map = v.values;
        let mut p = Json::object();
        for (q, x) in PERCENTILES.iter().zip(&self.percentiles) {
            p = p.num(&format!("{q}"), *x);
        }
        let directions: Vec<f64> = v
            .directions
            .concat()
            .iter()
            .map(|&x| f64::from(x))
            .collect();
        let json = Json::object()
            .str("volume", &self.name)
            .arr_usize("dims", &v.dims)
            .str("type", self.ty)
            .arr_f64("spacing", &v.spacing.map(f64::from))
            .arr_f64("directions", &directions)
            .arr_f64("range", &[self.range.0, self.range.1])
            .num("not_finite", self.missing as f64)
            .obj("percentiles", p)
            .num("percentile_stride", self.step as f64)
            .bool("held_exactly", self.held.is_none())
            .arr_f64("value_map", &[map.offset, map.scale]);
        let json = match &self.held {
            Some(note) => json.str("precision", note),
            None => json,
        };
        // A rectilinear grid: its coordinates' spread (gaps per axis, world units).
        let json = match &v.grid {
            Some(g) => json.obj(
                "rectilinear",
                (0..3).fold(Json::object(), |o, a| {
                    let (lo, hi) = g.gaps()[a];
                    let c = g.axis(a);
                    o.arr_f64(["x", "y", "z"][a], &[c[0], c[c.len() - 1], lo, hi])
                }),
            ),
            None => json.null("rectilinear"),
        };
        match &self.window {
            Ok((w, rule)) => json
                .arr_f64("window", &map.window_to_data(*w))
                .str("window_rule", rule),
            Err(e) => json.null("window").str("window_refused", &e.message),
        }
    }
}

/// The sample type's name, as numpy spells it.
fn type_name(s: &Samples) -> &'static str {
    match s {
        Samples::U8(_) => "uint8",
        Samples::I8(_) => "int8",
        Samples::U16(_) => "uint16",
        Samples::I16(_) => "int16",
        Samples::U32(_) => "uint32",
        Samples::I32(_) => "int32",
        Samples::F32(_) => "float32",
        Samples::F64(_) => "float64",
        Samples::Coloured(_) => "coloured",
    }
}

/// `None` where every sample is held exactly by the renderer's f32 values; else what is lost
/// and what is done about it (wide samples: u32, i32, f64).
fn held_exactly(v: &Volume) -> Option<String> {
    let map = v.values;
    let lost = |x: f64| x.is_finite() && map.to_data(map.apply(x)) != x;
    let (ty, count) = match &v.samples {
        Samples::U32(s) => ("uint32", s.iter().filter(|&&x| lost(f64::from(x))).count()),
        Samples::I32(s) => ("int32", s.iter().filter(|&&x| lost(f64::from(x))).count()),
        Samples::F64(s) => ("float64", s.iter().filter(|&&x| lost(x)).count()),
        _ => return None,
    };
    let how = if map.is_identity() {
        "each is rounded to f32 (24 significant bits), and windows are mapped in f64".to_string()
    } else {
        format!(
            "they are rendered as (sample - {}) x {} computed in f64 and rounded to f32 once, \
             so the window keeps its arithmetic in f64 (windows stay in the data's units)",
            num(map.offset),
            num(map.scale)
        )
    };
    match (count, map.is_identity()) {
        (0, true) => None,
        (0, false) => Some(format!(
            "{ty} samples are not all f32 values as they are: {how}"
        )),
        (n, _) => Some(format!(
            "{n} {ty} samples cannot be held exactly in f32: {how}"
        )),
    }
}

/// `v` as printed: plain, or in exponent form where plain would run past 16 digits.
fn num(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-6..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}
