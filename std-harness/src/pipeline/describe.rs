//! The JSON fields every render and verify summary share ([`describe`]): what was rendered and
//! how, from a [`Prepared`] render, its inputs and its plan.

use super::stages::prepare::Prepared;
use crate::io::json::Json;
use crate::plan::{End, Footprints, Plan, Precision};
use crate::scene::Scene;

/// The JSON fields every render and verify summary share.
pub fn describe(p: &Prepared, args: &Scene, plan: &Plan) -> Json {
    let f = &p.frame;
    let method = match (plan.end, plan.table.footprints) {
        (End::Reference, _) => "reference".to_string(),
        (_, Footprints::Direct) => "direct".to_string(),
        _ => match args.kernel.options.mapping {
            footprint::geometry::Mapping::Paper { .. } => "paper".to_string(),
            _ => "robust".to_string(),
        },
    };
    Json::object()
        .str("volume", &p.name)
        .arr_usize("dims", &p.frame.dims)
        .arr_f64("spacing", &p.frame.spacing.map(f64::from))
        .arr_usize("size", &[args.size.0, args.size.1])
        .str("kernel", &p.kernel.to_string())
        .num("table", plan.table.size as f64)
        .str("lookup", &format!("{:?}", plan.table.lookup).to_lowercase())
        .str("method", &method)
        .str("order", &format!("{:?}", p.order).to_lowercase())
        .str(
            "accum",
            match plan.precision() {
                Precision::Float => "float",
                Precision::Fixed => "fixed",
            },
        )
        .bool("streamed", p.volume().is_none())
        .str("shading", &args.shading.to_string())
        .str("tf", &p.tf_name)
        .arr_f64("window", &p.data_window())
        // `--labels`: how many labels classify the samples (null: the transfer function does).
        .num(
            "labels",
            p.labels.as_ref().map_or(f64::NAN, |l| l.len() as f64),
        )
        .arr_usize(
            "crop",
            &args
                .crop
                .map_or(Vec::new(), |c| c.0.iter().flatten().copied().collect()),
        )
        .arr_obj(
            "clip",
            p.clip
                .iter()
                .map(|c| {
                    Json::object()
                        .arr_f64("normal", &c.normal)
                        .num("offset", c.offset)
                })
                .collect(),
        )
        .str("sheet_axis", ["i", "j", "k"][f.sheet_axis])
        .str("slicing", plan.slicing())
        .str("classification", plan.classification())
        .str("reconstruction", plan.reconstruction().name())
        .num(
            "slab",
            match plan.end {
                End::Slabs { thickness } | End::Post { thickness, .. } => f64::from(thickness),
                _ => f64::NAN,
            },
        )
        .num(
            "value_subsample",
            match plan.end {
                End::Post {
                    thickness,
                    values,
                    reconstruction,
                    ..
                } => {
                    crate::pipeline::ends::post::value_scale(p, (thickness, values, reconstruction))
                        .map_or(f64::NAN, |s| s as f64)
                }
                _ => f64::NAN,
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
        .num("subsample", p.subsample_factor(plan).unwrap_or(1) as f64)
        .num("lod", f64::from(p.level))
        .arr_usize("lod_dims", &p.frame.dims)
        .str(
            "background",
            &match &args.background {
                crate::io::image::Background::Black => "black".to_string(),
                crate::io::image::Background::Transparent => "transparent".to_string(),
                crate::io::image::Background::Image(path) => path.display().to_string(),
            },
        )
        .str("gamma", &format!("{:?}", args.gamma).to_lowercase())
        .num("depth", f64::from(args.depth))
        .num("cull", plan.cull.map_or(f64::NAN, f64::from))
        .obj("plan", plan_json(p, plan))
}

/// What drew the frame, resolved (defaults and `auto`s decided): `end` (`sheets`, `slabs`,
/// `post`, `refined` or `reference`), `precision`, `slab` (voxel spacings; null but for slabs),
/// `depth_phases` (slabs: 0 cuts each kernel per pixel, N snaps depths to N phases per slab and
/// splats section stencils; null but for slabs), `blend` (`composite`, `mip`, `minip`, `average`),
/// `reconstruction` (`kernel`, or `trilinear` for post-classified slabs), `subsample` and `supersample` (factors), `lod` (level), `cull` (ε; null when off), `order`,
/// `phase_lookup` (`blend` or `nearest`: how sheets, float or fixed, read the phase stencils).
pub fn plan_json(p: &Prepared, plan: &Plan) -> Json {
    let (end, slab) = match plan.end {
        End::Sheets(_) => ("sheets", f64::NAN),
        End::Slabs { thickness } => ("slabs", f64::from(thickness)),
        End::Post { thickness, .. } => ("post", f64::from(thickness)),
        End::Refined { .. } => ("refined", f64::NAN),
        End::Reference => ("reference", f64::NAN),
    };
    Json::object()
        .str("end", end)
        .str(
            "precision",
            match plan.precision() {
                Precision::Float => "float",
                Precision::Fixed => "fixed",
            },
        )
        .num("slab", slab)
        .num(
            "depth_phases",
            match plan.end {
                End::Slabs { .. } => plan.depth_phases as f64,
                _ => f64::NAN,
            },
        )
        .str(
            "blend",
            match plan.end {
                End::Post { blend, .. } => blend.name(),
                _ => "composite",
            },
        )
        .str("reconstruction", plan.reconstruction().name())
        .num("subsample", p.subsample_factor(plan).unwrap_or(1) as f64)
        .num("supersample", p.supersample as f64)
        .num("lod", f64::from(p.level))
        .num("cull", plan.cull.map_or(f64::NAN, f64::from))
        .str("order", &format!("{:?}", p.order).to_lowercase())
        .str(
            "phase_lookup",
            crate::plan::phase_lookup_name(plan.phase_lookup.unwrap_or_default()),
        )
}
