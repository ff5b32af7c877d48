//! The stability sweeps: one voxel of the paper Gaussian against the exact footprint, over
//! rotation, anisotropy and footprint size.

use crate::args::{FootprintArgs, LookupArg, MethodArg, SplatArgs};
use crate::metrics::max_rel_diff;
use crate::pipeline::ends::single::splat_image;
use std::path::PathBuf;

/// One stability curve: (x, error) points, `None` where the method failed.
pub struct Curve {
    pub name: &'static str,
    pub points: Vec<(f64, Option<f64>)>,
}

fn splat_error(args: &SplatArgs) -> Option<f64> {
    let core = splat_image(&crate::args::single(args).ok()?).ok()?.0;
    let mut r = args.clone();
    r.footprint.method = MethodArg::Reference;
    let reference = splat_image(&crate::args::single(&r).ok()?).ok()?.0;
    let e = max_rel_diff(&core, &reference).ok()?;
    e.is_finite().then_some(e)
}

fn base_splat(method: MethodArg, lookup: LookupArg) -> SplatArgs {
    SplatArgs {
        footprint: FootprintArgs {
            kernel: "gaussian:spread=1.6,sigmas=2.5".into(),
            table: 65,
            table_file: None,
            lookup,
            method,
            min_radius: footprint::geometry::DEFAULT_MIN_RADIUS_PX,
            paper_cheat: 0.01,
        },
        spacing: [2.0, 1.0, 1.0],
        grid_matrix: None,
        view_matrix: None,
        rotate_x: 0.0,
        rotate_y: 0.0,
        rotate_z: 0.0,
        size: (128, 128),
        center: None,
        out: PathBuf::from("unused.pfm"),
    }
}

/// The three stability sweeps.
pub fn stability() -> [Vec<Curve>; 3] {
    // (a) rotation about the view axis, a 2:1 grid about 40 px across.
    let mut angles: Vec<f64> = (0..=90).map(f64::from).collect();
    angles.extend((0..=100).map(|i| 44.5 + 0.01 * f64::from(i)));
    angles.extend([45.0 - 1e-4, 45.0 + 8e-5, 45.0 + 1e-4]);
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let rotation = [
        (MethodArg::Robust, 0.01, "robust (Cholesky)"),
        (MethodArg::Paper, 0.01, "paper (θ, 0.01° cheat)"),
        (MethodArg::Paper, 0.0, "paper (θ, no cheat)"),
    ]
    .map(|(m, cheat, name)| Curve {
        name,
        points: angles
            .iter()
            .map(|&a| {
                let mut s = base_splat(m, LookupArg::Bilinear);
                s.footprint.paper_cheat = cheat;
                s.spacing = [12.0, 6.0, 6.0];
                s.rotate_z = a as f32;
                (a, splat_error(&s))
            })
            .collect(),
    })
    .into();
    // (b) anisotropy r:1:1, seen at 30° about y and 20° about x, long axis ~100 px.
    let ratios: Vec<f64> = (0..=30).map(|i| 10f64.powf(f64::from(i) / 10.0)).collect();
    let aniso = [
        (MethodArg::Robust, "robust (Cholesky)"),
        (MethodArg::Paper, "paper (θ, 0.01° cheat)"),
    ]
    .map(|(m, name)| Curve {
        name,
        points: ratios
            .iter()
            .map(|&r| {
                let mut s = base_splat(m, LookupArg::Bilinear);
                let unit = 100.0 / (3.2 * r as f32);
                s.spacing = [unit * r as f32, unit, unit];
                s.rotate_y = 30.0;
                s.rotate_x = 20.0;
                s.rotate_z = 10.0;
                (r, splat_error(&s))
            })
            .collect(),
    })
    .into();
    // (c) footprint size, isotropic, 0.1 to 1000 px across on a 128x128 image.
    let sizes: Vec<f64> = (-10..=30)
        .map(|i| 10f64.powf(f64::from(i) / 10.0))
        .collect();
    let size = [
        (LookupArg::Bilinear, "bilinear"),
        (LookupArg::Nearest, "nearest"),
    ]
    .map(|(l, name)| Curve {
        name,
        points: sizes
            .iter()
            .map(|&d| {
                let mut s = base_splat(MethodArg::Robust, l);
                let spacing = d as f32 / 3.2;
                s.spacing = [spacing; 3];
                s.rotate_z = 10.0;
                s.center = Some([64.3, 64.2]);
                (d, splat_error(&s))
            })
            .collect(),
    })
    .into();
    [rotation, aniso, size]
}

/// The stability curves as CSV: panel, curve, x, error (empty where it failed).
pub fn stability_csv(curves: &[Vec<Curve>; 3]) -> String {
    let mut s = String::from("panel,curve,x,max_rel_error\n");
    for (panel, set) in ["rotation_deg", "anisotropy", "footprint_px"]
        .iter()
        .zip(curves)
    {
        for c in set {
            for &(x, e) in &c.points {
                let e = e.map_or(String::new(), |e| format!("{e:.4e}"));
                s.push_str(&format!("{panel},\"{}\",{x},{e}\n", c.name));
            }
        }
    }
    s
}
