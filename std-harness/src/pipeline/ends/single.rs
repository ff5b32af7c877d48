//! One voxel of value 1 rendered on its own: its raw footprint weights as an image, by a table
//! method or by the f64 reference (what `footprint splat` writes and the stability charts measure).
//!
//! Conventions: world = G·(i, j, k) with G = diag(--spacing) (or --grid-matrix); screen =
//! V·world + (W/2, H/2, 0), V = Rz·Ry·Rx·(--view-matrix), pixels, x right, y down, z away; the
//! voxel sits at the screen origin (W/2, H/2) unless --center moves it. Weights are px⁻² and
//! integrate to one over the screen plane.

use crate::args::{MethodArg, SplatArgs};
use crate::io::image::GreyImage;
use crate::reference::ReferenceFootprint;
use crate::CliError;
use footprint::geometry::{Footprint, FootprintOptions, Mapping};
use footprint::splat::{splat, Direct, ImageMut, Sampler};
use footprint::{Grid, Lookup, View, ViewTable};
use glam::Mat3;
use std::time::Instant;

/// What one single-sample render did.
#[derive(Clone, Debug)]
pub struct SplatReport {
    /// Footprint half-extents, pixels.
    pub half_extent: [f32; 2],
    /// Sheet axis (0 = i, 1 = j, 2 = k).
    pub sheet_axis: usize,
    /// A semi-axis was widened to --min-radius.
    pub clamped: bool,
    /// The paper method needed its cheat.
    pub cheated: bool,
    /// Where the view table's nodes lay (`None` for the direct and reference methods).
    pub layout: Option<footprint::ViewLayout>,
    /// Σ of all pixel weights (≈ 1 when the footprint is on screen).
    pub sum: f64,
    /// Largest weight, px⁻².
    pub peak: f32,
    /// Time for table build + splat (not file I/O), seconds.
    pub seconds: f64,
}

/// `Rz(z)·Ry(y)·Rx(x)·V`, angles in degrees.
pub fn compose_view(view_rows: Option<[f32; 9]>, rx: f32, ry: f32, rz: f32) -> Mat3 {
    let v = view_rows.map_or(Mat3::IDENTITY, |m| Mat3::from_cols_array(&m).transpose());
    Mat3::from_rotation_z(rz.to_radians())
        * Mat3::from_rotation_y(ry.to_radians())
        * Mat3::from_rotation_x(rx.to_radians())
        * v
}

/// Renders the single sample described by `args` (no file is written).
pub fn splat_image(args: &SplatArgs) -> Result<(GreyImage, SplatReport), CliError> {
    let fa = &args.footprint;
    let kernel = fa.kernel()?;
    let grid = match args.grid_matrix {
        Some(m) => Grid::from_matrix(Mat3::from_cols_array(&m).transpose()),
        None => Grid::from_spacing(args.spacing),
    }
    .map_err(|e| CliError::input(format!("grid: {e}")))?;
    let view = View::new(compose_view(
        args.view_matrix,
        args.rotate_x,
        args.rotate_y,
        args.rotate_z,
    ))
    .map_err(|e| CliError::input(format!("view: {e}")))?;
    let g2s = view.grid_to_screen(&grid);
    let (w, h) = args.size;
    let center = args.center.unwrap_or([w as f32 / 2.0, h as f32 / 2.0]);
    let lookup = Lookup::from(fa.lookup);
    let start = Instant::now();
    if fa.method == MethodArg::Reference {
        let reference =
            ReferenceFootprint::new(&kernel, &g2s.as_dmat3(), f64::from(fa.min_radius))?;
        let mut out = vec![0.0f64; w * h];
        reference.splat([f64::from(center[0]), f64::from(center[1])], w, h, &mut out);
        let seconds = start.elapsed().as_secs_f64();
        let img = GreyImage {
            width: w,
            height: h,
            data: out.iter().map(|&v| v as f32).collect(),
        };
        let fp = Footprint::new(
            &kernel,
            &g2s,
            FootprintOptions {
                mapping: Mapping::Robust,
                min_radius_px: fa.min_radius,
            },
        )?;
        let report = SplatReport {
            half_extent: [
                reference.half_extent[0] as f32,
                reference.half_extent[1] as f32,
            ],
            sheet_axis: fp.sheet_axis,
            clamped: reference.clamped,
            cheated: false,
            layout: None,
            sum: out.iter().sum(),
            peak: img.peak(),
            seconds,
        };
        return Ok((img, report));
    }
    let mapping = fa.mapping()?;
    let fp = Footprint::new(
        &kernel,
        &g2s,
        FootprintOptions {
            mapping,
            min_radius_px: fa.min_radius,
        },
    )?;
    let mut pixels = vec![0.0f32; w * h];
    /// One splat of `fp` at `center` into `pixels` (w × h) through tables of side N.
    struct One<'a> {
        fa: &'a crate::args::FootprintArgs,
        kernel: footprint::Kernel,
        fp: Footprint,
        lookup: footprint::Lookup,
        center: [f32; 2],
        pixels: &'a mut [f32],
        size: (usize, usize),
    }
    impl crate::dispatch::TableSize for One<'_> {
        type Output = ();
        fn run<const N: usize>(self) -> Result<(), CliError> {
            let (fp, lookup) = (self.fp, self.lookup);
            let generic = self.fa.generic_table::<N>(&self.kernel)?;
            let mut image = ImageMut::new(self.pixels, self.size.0, self.size.1, self.size.0)?;
            let sampler: Box<dyn Sampler + '_> = match self.fa.method {
                MethodArg::Direct => Box::new(Direct {
                    footprint: fp,
                    table: &*generic,
                    lookup,
                }),
                _ => Box::new(ViewTable::<N>::build(&fp, &generic, lookup, lookup)),
            };
            splat(&*sampler, self.center, &1.0f32, &mut image)?;
            Ok(())
        }
    }
    let one = One {
        fa,
        kernel,
        fp,
        lookup,
        center,
        pixels: &mut pixels,
        size: (w, h),
    };
    crate::dispatch::with_size(fa.table, one)?;
    let seconds = start.elapsed().as_secs_f64();
    let img = GreyImage {
        width: w,
        height: h,
        data: pixels,
    };
    let report = SplatReport {
        half_extent: fp.half_extent,
        sheet_axis: fp.sheet_axis,
        clamped: fp.clamped,
        cheated: fp.cheated,
        layout: (fa.method != MethodArg::Direct).then(|| footprint::ViewLayout::for_footprint(&fp)),
        sum: img.data.iter().map(|&v| f64::from(v)).sum(),
        peak: img.peak(),
        seconds,
    };
    Ok((img, report))
}
