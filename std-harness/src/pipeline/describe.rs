//! The JSON fields every render and verify summary share ([`describe`]): what was rendered and
//! how, from a [`Prepared`] render and its arguments.

use super::prepare::Prepared;
use crate::args::RenderArgs;
use crate::io::json::Json;

/// The JSON fields every render and verify summary share.
pub fn describe(p: &Prepared, args: &RenderArgs) -> Json {
    let f = &p.frame;
    Json::object()
        .str("volume", &p.name)
        .arr_usize("dims", &p.frame.dims)
        .arr_f64("spacing", &p.frame.spacing.map(f64::from))
        .arr_usize("size", &[args.size.0, args.size.1])
        .str("kernel", &p.kernel.to_string())
        .num("table", args.footprint.table as f64)
        .str(
            "lookup",
            &format!("{:?}", args.footprint.lookup).to_lowercase(),
        )
        .str(
            "method",
            &format!("{:?}", args.footprint.method).to_lowercase(),
        )
        .str("order", &format!("{:?}", p.order).to_lowercase())
        .str("accum", &format!("{:?}", args.accum).to_lowercase())
        .bool("streamed", p.volume().is_none())
        .str("shading", &args.shading)
        .str("tf", &p.tf_name)
        .arr_f64("window", &p.window.map(f64::from))
        .str("sheet_axis", ["i", "j", "k"][f.sheet_axis])
        .str("slicing", args.slicing.name())
        .num(
            "slab",
            match args.slicing {
                crate::args::SlicingArg::Image => f64::from(args.slab),
                crate::args::SlicingArg::Object => f64::NAN,
            },
        )
        .str(
            "projection",
            if f.camera().is_some() {
                "perspective"
            } else {
                "orthographic"
            },
        )
        .num("fovy_deg", args.perspective.map_or(f64::NAN, f64::from))
        .num(
            "eye_distance",
            f.camera().map_or(f64::NAN, |c| f64::from(c.eye_distance)),
        )
        .arr_f64(
            "footprint_half_extent_px",
            &f.footprint
                .half_extent
                .map(|e| f64::from(e) / p.supersample as f64),
        )
        .num("supersample", p.supersample as f64)
        .num(
            "subsample",
            crate::plan::plan(args)
                .and_then(|plan| p.subsample_factor(&plan))
                .unwrap_or(1) as f64,
        )
        .num("lod", f64::from(p.level))
        .arr_usize("lod_dims", &p.frame.dims)
        .str(
            "background",
            &match &args.background {
                crate::args::Background::Black => "black".to_string(),
                crate::args::Background::Transparent => "transparent".to_string(),
                crate::args::Background::Image(path) => path.display().to_string(),
            },
        )
        .str("gamma", &format!("{:?}", args.gamma).to_lowercase())
        .num("depth", f64::from(args.depth))
}
