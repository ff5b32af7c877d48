//! `footprint verify`: render with the core and with the f64 reference (no tables), and measure
//! how far apart they are.
//!
//! Colour space: the renderers' output, linear premultiplied RGBA in [0, 1], composited over the
//! background (transparent black if none), exactly what `render` writes to its PNG before 8-bit
//! quantisation. Per channel c over the N pixels:
//! MSE_c = Σ (core − ref)² / N, RMSE_c = √MSE_c, PSNR_c = 10·log₁₀(1 / MSE_c) dB (peak 1), max abs
//! = max |core − ref|. *Overall* is the same over the R, G and B channels together (MSE averaged
//! over 3N values): the colour a person sees. PSNR is reported as infinite (JSON null) when the
//! images are identical.

use super::render::{
    apply_quality, describe, prepare, quality_json, render_core, render_core_with, render_ref,
    RenderArgs,
};
use crate::cli::{AccumArg, MethodArg};
use crate::io::{self, image::encode_png_rgb, json::Json};
use crate::CliError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// Exit with code 1 if the overall PSNR is below this, dB.
    #[arg(long)]
    pub min_psnr: Option<f64>,
    /// Also write the reference render (PNG) here.
    #[arg(long)]
    pub reference_out: Option<PathBuf>,
}

/// Error statistics of one channel or of RGB together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    pub mse: f64,
    pub rmse: f64,
    pub psnr_db: f64,
    pub max_abs: f64,
}

impl ErrorStats {
    fn from_sums(sum_sq: f64, count: usize, max_abs: f64) -> Self {
        let mse = sum_sq / count as f64;
        let psnr_db = if mse > 0.0 {
            10.0 * (1.0 / mse).log10()
        } else {
            f64::INFINITY
        };
        ErrorStats {
            mse,
            rmse: mse.sqrt(),
            psnr_db,
            max_abs,
        }
    }
    fn json(&self) -> Json {
        Json::object()
            .num("psnr_db", self.psnr_db)
            .num("rmse", self.rmse)
            .num("max_abs", self.max_abs)
            .num("mse", self.mse)
    }
}

/// Per-channel (R, G, B, A) and overall (RGB) errors of `core` against `reference`.
pub fn compare(core: &[[f32; 4]], reference: &[[f64; 4]]) -> ([ErrorStats; 4], ErrorStats) {
    let mut sq = [0.0f64; 4];
    let mut mx = [0.0f64; 4];
    for (c, r) in core.iter().zip(reference) {
        for ch in 0..4 {
            let d = (f64::from(c[ch]) - r[ch]).abs();
            sq[ch] += d * d;
            mx[ch] = mx[ch].max(d);
        }
    }
    let n = core.len().max(1);
    let per = [0, 1, 2, 3].map(|ch| ErrorStats::from_sums(sq[ch], n, mx[ch]));
    let overall = ErrorStats::from_sums(sq[0] + sq[1] + sq[2], 3 * n, mx[0].max(mx[1]).max(mx[2]));
    (per, overall)
}

pub fn run(args: &VerifyArgs) -> Result<(), CliError> {
    let r = &args.render;
    if r.footprint.method == MethodArg::Reference {
        return Err(CliError::input(
            "verify compares a table method with the reference: choose robust, paper or direct",
        ));
    }
    let p = prepare(r)?;
    let (chosen, choice) = apply_quality(&p, r)?;
    let r = &chosen;
    let (core, stats, core_s) = render_core(&p, r)?;
    let (reference, ref_s) = render_ref(&p)?;
    let (per, overall) = compare(&core, &reference);
    crate::say!(
        "{}: {}x{}, core {:.3} s, reference {:.3} s",
        p.name,
        r.size.0,
        r.size.1,
        core_s,
        ref_s
    );
    crate::say!("channel   PSNR dB      RMSE   max abs");
    for (name, e) in ["R", "G", "B", "A"].iter().zip(&per) {
        crate::say!(
            "{name:<7} {:>9.2} {:>9.2e} {:>9.2e}",
            e.psnr_db,
            e.rmse,
            e.max_abs
        );
    }
    crate::say!(
        "overall {:>9.2} {:>9.2e} {:>9.2e}   (RGB, linear premultiplied)",
        overall.psnr_db,
        overall.rmse,
        overall.max_abs
    );
    // The fixed path is also measured against the float path of the same table and method.
    let fixed_vs_float = if r.accum == AccumArg::Fixed {
        let (float, _, _) = render_core_with(&p, r, AccumArg::Float)?;
        let float: Vec<[f64; 4]> = float.iter().map(|c| c.map(f64::from)).collect();
        let (_, e) = compare(&core, &float);
        crate::say!(
            "fixed vs float {:>9.2} {:>9.2e} {:>9.2e}   (RGB, same table and method)",
            e.psnr_db,
            e.rmse,
            e.max_abs
        );
        Some(e)
    } else {
        None
    };
    if let Some(out) = &r.out {
        io::write_atomic(out, &encode_png_rgb(&core, r.size.0, r.size.1)?)?;
    }
    if let Some(out) = &args.reference_out {
        let img: Vec<[f32; 4]> = reference.iter().map(|c| c.map(|x| x as f32)).collect();
        io::write_atomic(out, &encode_png_rgb(&img, r.size.0, r.size.1)?)?;
    }
    let pass = args.min_psnr.is_none_or(|m| overall.psnr_db >= m);
    if let Some(j) = &r.json {
        let channels = Json::object()
            .obj("r", per[0].json())
            .obj("g", per[1].json())
            .obj("b", per[2].json())
            .obj("a", per[3].json());
        let mut summary = describe(&p, r).str("command", "verify");
        if let Some(e) = fixed_vs_float {
            summary = summary.obj("fixed_vs_float", e.json());
        }
        if let Some(c) = &choice {
            summary = summary.obj("quality", quality_json(c));
        }
        let summary = summary
            .num("core_seconds", core_s)
            .num("reference_seconds", ref_s)
            .num("voxels_splatted", stats.voxels_splatted as f64)
            .obj("overall", overall.json())
            .obj("channels", channels)
            .num("min_psnr_db", args.min_psnr.unwrap_or(f64::NAN))
            .bool("pass", pass);
        io::write_atomic(j, summary.finish().as_bytes())?;
    }
    if pass {
        Ok(())
    } else {
        Err(CliError::check(format!(
            "PSNR {:.2} dB is below --min-psnr {}",
            overall.psnr_db,
            args.min_psnr.unwrap_or(f64::NAN)
        )))
    }
}
