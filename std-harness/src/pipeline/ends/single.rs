//! One voxel of value 1 rendered on its own: its raw footprint weights as an image, by a table
//! method or by the f64 reference (what `footprint splat` writes and the stability charts measure).
//!
//! Conventions: world = G·(i, j, k) with G = diag(--spacing) (or --grid-matrix); screen =
//! V·world + (W/2, H/2, 0), V = Rz·Ry·Rx·(--view-matrix), pixels, x right, y down, z away; the
//! voxel sits at the screen origin (W/2, H/2) unless --center moves it. Weights are px⁻² and
//! integrate to one over the screen plane.

use crate::io::image::GreyImage;
use crate::plan::Method;
use crate::reference::ReferenceFootprint;
use crate::scene::KernelModel;
use crate::CliError;
use footprint::geometry::{Footprint, FootprintOptions, Mapping};
use footprint::splat::{splat, Direct, ImageMut, Sampler};
use footprint::{Grid, Lookup, View, ViewTable};
use glam::Mat3;
use std::path::PathBuf;
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

/// One voxel's render, resolved (what `footprint splat`'s flags ask for).
#[derive(Clone, Debug)]
pub struct Single {
    /// The kernel and its footprint's shape.
    pub kernel: KernelModel,
    /// How the footprint is evaluated.
    pub method: Method,
    /// Generic and view table side N, and their lookup.
    pub table: usize,
    pub lookup: Lookup,
    /// A generic table loaded from this file instead of built.
    pub table_file: Option<PathBuf>,
    /// G: world = G·(i, j, k) (`--spacing` as its diagonal, or `--grid-matrix`).
    pub grid: Grid,
    /// V: screen = V·world (`Rz·Ry·Rx·--view-matrix`, [`compose_view`]).
    pub view: View,
    /// Image size, pixels (width, height).
    pub size: (usize, usize),
    /// Where the voxel lands, pixels; `None`: the image's centre.
    pub center: Option<[f32; 2]>,
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
pub fn splat_image(args: &Single) -> Result<(GreyImage, SplatReport), CliError> {
    let kernel = args.kernel.kernel;
    let min_radius = args.kernel.options.min_radius_px;
    let g2s = args.view.grid_to_screen(&args.grid);
    let (w, h) = args.size;
    let center = args.center.unwrap_or([w as f32 / 2.0, h as f32 / 2.0]);
    let lookup = args.lookup;
    let start = Instant::now();
    if args.method == Method::Reference {
        let reference = ReferenceFootprint::new(&kernel, &g2s.as_dmat3(), f64::from(min_radius))?;
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
                min_radius_px: min_radius,
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
    let fp = Footprint::new(&kernel, &g2s, args.kernel.options)?;
    let mut pixels = vec![0.0f32; w * h];
    /// One splat of `fp` at `center` into `pixels` (w × h) through tables of side N.
    struct One<'a> {
        args: &'a Single,
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
            let generic =
                crate::io::table::generic_for::<N>(self.args.table_file.as_deref(), &self.kernel)?;
            let mut image = ImageMut::new(self.pixels, self.size.0, self.size.1, self.size.0)?;
            let sampler: Box<dyn Sampler + '_> = match self.args.method {
                Method::Direct => Box::new(Direct {
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
        args,
        kernel,
        fp,
        lookup,
        center,
        pixels: &mut pixels,
        size: (w, h),
    };
    crate::dispatch::with_size(args.table, one)?;
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
        layout: (args.method != Method::Direct).then(|| footprint::ViewLayout::for_footprint(&fp)),
        sum: img.data.iter().map(|&v| f64::from(v)).sum(),
        peak: img.peak(),
        seconds,
    };
    Ok((img, report))
}
