//! What `verify` prints and writes: the table of figures on the terminal, the images and the
//! JSON summary (keys as documented in the README).

use super::{Measured, VerifyArgs};
use crate::args::{ReferenceArg, RenderArgs};
use crate::io::image::encode_rgb_for;
use crate::io::json::Json;
use crate::pipeline::describe;
use crate::pipeline::ends::continuous::{models_json, others, PIXEL_FILTER};
use crate::pipeline::quality::model::quality_json;
use crate::plan::End;
use crate::reference::continuous::Reconstruction;
use crate::CliError;
use std::path::Path;

impl Measured {
    /// The figures, one line each.
    pub(super) fn print(&self, args: &VerifyArgs, r: &RenderArgs) {
        let p = &self.p;
        crate::say!(
            "{}: {}x{}, core {:.3} s, reference {:.3} s",
            p.name,
            r.size.0,
            r.size.1,
            self.core_s,
            self.ref_s
        );
        crate::say!("channel   PSNR dB      RMSE   max abs");
        for (name, e) in ["R", "G", "B", "A"].iter().zip(&self.per) {
            crate::say!(
                "{name:<7} {:>9.2} {:>9.2e} {:>9.2e}",
                e.psnr_db,
                e.rmse,
                e.max_abs
            );
        }
        let o = &self.overall;
        crate::say!(
            "overall {:>9.2} {:>9.2e} {:>9.2e}   (RGB, linear premultiplied)",
            o.psnr_db,
            o.rmse,
            o.max_abs
        );
        if let Some(e) = &self.full_resolution {
            crate::say!(
                "full res {:>8.2} {:>9.2e} {:>9.2e}   (RGB, against the f64 reference of level \
                 0: level {}'s own error included)",
                e.psnr_db,
                e.rmse,
                e.max_abs,
                p.level
            );
        }
        if matches!(self.plan.end, End::Refined { .. }) {
            crate::say!(
                "(--refine: the sheet reference renders the grid as given, so `overall` above is \
                 what refinement changed; the field line below measures it against the finer \
                 sampling)"
            );
        }
        if self.p.volume().is_some_and(|v| v.grid.is_some()) {
            crate::say!(
                "(a rectilinear grid: the sheet reference renders its values on the uniform grid \
                 of its mean spacing, so `overall` above is what the uneven spacing changes; the \
                 continuous line below measures the grid)"
            );
        }
        if matches!(self.plan.end, End::Slabs { .. }) {
            crate::say!(
                "(--slicing image: the sheet reference renders the paper's object-aligned sheets, \
                 so `overall` above is the difference between the two slicings; --reference \
                 continuous measures image slicing against the truth)"
            );
        }
        if let Some(c) = &self.continuous {
            let (e, i) = (&c.error, &c.integral);
            crate::say!(
                "{} {:>9.2} {:>9.2e} {:>9.2e}   (RGB, against the continuous integral{}, {} \
                 reconstruction, {} model{}; step {:.4} world units after {} passes, last change \
                 {:.1} dB{}; {:.1} s)",
                args.reference.name(),
                e.psnr_db,
                e.rmse,
                e.max_abs,
                match args.reference {
                    ReferenceArg::Field => format!(" of the field sampled {}^3", r.field_size),
                    _ => String::new(),
                },
                Reconstruction::from(args.render.reconstruction).name(),
                c.models[0].0.name(),
                others(&c.models),
                i.step,
                i.passes,
                i.change_db,
                if i.converged { "" } else { ", NOT converged" },
                c.seconds
            );
        }
        if let Some(e) = &self.fixed_vs_float {
            crate::say!(
                "fixed vs float {:>9.2} {:>9.2e} {:>9.2e}   (RGB, same table and method)",
                e.psnr_db,
                e.rmse,
                e.max_abs
            );
        }
    }

    /// The files asked for: `--out` (the core's image), `--reference-out` (the reference
    /// `--reference` chose) and `--json` (the summary, with `pass`).
    pub(super) fn files<'a>(
        &self,
        args: &'a VerifyArgs,
        r: &'a RenderArgs,
        pass: bool,
    ) -> Result<Vec<(&'a Path, Vec<u8>)>, CliError> {
        let (w, h) = r.size;
        let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
        if let Some(out) = &r.out {
            files.push((out, encode_rgb_for(out, &self.core, w, h, r.png_style())?));
        }
        if let Some(out) = &args.reference_out {
            let chosen = self
                .continuous
                .as_ref()
                .map_or(&self.reference, |c| &c.integral.image);
            let img: Vec<[f32; 4]> = chosen.iter().map(|c| c.map(|x| x as f32)).collect();
            files.push((out, encode_rgb_for(out, &img, w, h, r.png_style())?));
        }
        if let Some(j) = &r.json {
            files.push((j, self.json(args, r, pass).finish().into_bytes()));
        }
        Ok(files)
    }

    /// The JSON summary: the plan as `describe` states it, then every figure.
    fn json(&self, args: &VerifyArgs, r: &RenderArgs, pass: bool) -> Json {
        let per = &self.per;
        let channels = Json::object()
            .obj("r", per[0].json())
            .obj("g", per[1].json())
            .obj("b", per[2].json())
            .obj("a", per[3].json());
        let mut summary = describe(&self.p, &self.inputs, &self.plan).str("command", "verify");
        if let Some(e) = &self.fixed_vs_float {
            summary = summary.obj("fixed_vs_float", e.json());
        }
        if let Some(c) = &self.choice {
            summary = summary.obj("quality", quality_json(c));
        }
        if let Some(e) = &self.full_resolution {
            summary = summary.obj("full_resolution", e.json());
        }
        summary = summary.str("reference", args.reference.name());
        if let Some(c) = &self.continuous {
            let e = match args.reference {
                ReferenceArg::Field => c.error.json().num("field_size", r.field_size as f64),
                _ => c.error.json(),
            };
            let i = &c.integral;
            summary = summary.obj(
                "continuous",
                e.str(
                    "reconstruction",
                    Reconstruction::from(args.render.reconstruction).name(),
                )
                .str("absorption", c.models[0].0.name())
                .obj("models", models_json(&c.models))
                .str("pixel_filter", PIXEL_FILTER)
                .num("step_world", i.step)
                .num("passes", i.passes as f64)
                .num("change_db", i.change_db)
                .bool("converged", i.converged)
                .num("seconds", c.seconds),
            );
        }
        summary
            .num("core_seconds", self.core_s)
            .num("reference_seconds", self.ref_s)
            .num("voxels_splatted", self.stats.voxels_splatted as f64)
            .obj("overall", self.overall.json())
            .obj("channels", channels)
            .num("min_psnr_db", args.min_psnr.unwrap_or(f64::NAN))
            .bool("pass", pass)
    }
}
