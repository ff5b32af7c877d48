//! The front door: a volume in memory (`&[T]`, x fastest) rendered with VTK's camera, a transfer
//! function and the CLI's defaults into caller buffers, in one call. It is `footprint render
//! --slicing object`'s float path for a volume in memory (object slicing, blended phase stencils:
//! the CLI's default plan measures its choice on a pilot the core does not run), and gives the
//! same image bit for bit (`tests/library.rs` renders `core/examples/in_memory.rs` both ways and
//! compares the PNG bytes).
//!
//! ```
//! use footprint::prelude::*;
//! let (dims, data) = ([16, 16, 16], vec![200u8; 16 * 16 * 16]);
//! let settings = Settings { window: [0.0, 255.0], ..Settings::new([64, 64], Preset::Grey.lut()) };
//! let n = settings.lengths(dims)?;
//! let (mut image, mut work) = (vec![[0.0; 4]; n.pixels], vec![0.0; n.work]);
//! let (mut rows, mut sheets) = (vec![RowSpan::EMPTY; n.rows], vec![0u8; n.sheets]);
//! let generic = GenericTable::<33>::build(settings.kernel);
//! let buffers = Buffers::new(&mut image, &mut work, &mut rows, &mut sheets);
//! let stats = render_volume(&data, dims, &settings, &generic, buffers)?;
//! assert_eq!(stats.sheets, 16);
//! assert!(linear8(image[32 * 64 + 32])[3] > 0);
//! # Ok::<(), footprint::Error>(())
//! ```
//!
//! Streaming (voxels from a [`SheetSource`](crate::source::SheetSource)) and the fixed-point path
//! are one level down: see [`crate::source`] and [`crate::fixed`], and the examples in the crate
//! docs.

use crate::composite::RowSpan;
use crate::frame::{FrameSetup, Order};
use crate::geometry::{FootprintOptions, Grid, View};
use crate::kernel::Kernel;
use crate::render::{FloatPath, RenderBuffers, RenderStats, SheetRenderer, SheetRing};
use crate::shade::{Sample, Shader, Shading, TransferFunction, OPACITY_TABLE_LEN};
use crate::source::render_from;
use crate::splat::BufferError;
use crate::splat::Splatter;
use crate::stencil::{self, Stencils};
use crate::table::{GenericTable, Lookup, ViewTable};
use crate::volume::MemoryVolume;
use crate::Error;

/// Everything a frame needs besides the data and the buffers. [`Settings::new`] gives
/// `footprint render`'s defaults; change fields with struct-update syntax.
#[derive(Clone, Copy, Debug)]
pub struct Settings<'a> {
    /// Image width and height, pixels (`--size`).
    pub size: [usize; 2],
    /// World units between samples along i, j, k (`--spacing`).
    pub spacing: [f32; 3],
    /// VTK's camera: azimuth, elevation, roll in degrees, applied to a camera looking down −z
    /// (`--view`; see [`View::from_vtk_camera`]).
    pub view: [f32; 3],
    /// Magnification over the fit that keeps the whole volume in the image (`--zoom`).
    pub zoom: f32,
    /// Straight RGBA lookup table over [`Settings::window`] (`--tf`; [`crate::shade::Preset::lut`]).
    pub lut: &'a [[f32; 4]],
    /// The data values mapped to the first and last entry of the table (`--window LO,HI`).
    pub window: [f32; 2],
    /// Lighting (`--shading`).
    pub shading: Shading,
    /// Compositing order, given once (`--order`).
    pub order: Order,
    /// Reconstruction kernel (`--kernel`).
    pub kernel: Kernel,
    /// Footprint geometry options (`--method robust`, `--min-radius`).
    pub options: FootprintOptions,
    /// View-table lookup (`--lookup`).
    pub lookup: Lookup,
    /// Sub-pixel phases of the footprint stencils, 0 for none (`--phases`).
    pub phases: usize,
}

impl<'a> Settings<'a> {
    /// `footprint render`'s defaults at `size` with `lut`: unit spacing, VTK camera (0, 0, 0) at
    /// zoom 1, window [0, 1], emission, back to front, the paper's Gaussian, robust map,
    /// bilinear lookup, [`stencil::DEFAULT_PHASES`] phases.
    pub fn new(size: [usize; 2], lut: &'a [[f32; 4]]) -> Self {
        Settings {
            size,
            spacing: [1.0; 3],
            view: [0.0; 3],
            zoom: 1.0,
            lut,
            window: [0.0, 1.0],
            shading: Shading::Emission,
            order: Order::BackToFront,
            kernel: Kernel::PAPER_GAUSSIAN,
            options: FootprintOptions::default(),
            lookup: Lookup::Bilinear,
            phases: stencil::DEFAULT_PHASES,
        }
    }

    /// The frame these settings give for a volume of `dims` samples.
    pub fn frame(&self, dims: [usize; 3]) -> Result<FrameSetup, Error> {
        let grid = Grid::from_spacing(self.spacing)?;
        let view = View::from_vtk_camera(self.view, self.zoom, dims, &grid, self.size)?;
        Ok(FrameSetup::new(
            dims,
            &grid,
            &view,
            &self.kernel,
            self.options,
            self.size,
        )?)
    }

    /// The buffer lengths [`render_volume`] needs for a volume of `dims` samples.
    pub fn lengths(&self, dims: [usize; 3]) -> Result<Lengths, Error> {
        let frame = self.frame(dims)?;
        Ok(Lengths {
            pixels: frame.image_len(),
            rows: frame.size[1],
            sheets: 3 * frame.sheet_shape().0,
            work: self.work_len(&frame),
        })
    }

    /// The `work` buffer's layout: the accumulator (4 per pixel), the opacity table, the
    /// stencils.
    fn work_len(&self, frame: &FrameSetup) -> usize {
        4 * frame.image_len() + OPACITY_TABLE_LEN + self.stencil_len(frame)
    }

    fn stencil_len(&self, frame: &FrameSetup) -> usize {
        if self.phases == 0 {
            return 0;
        }
        stencil::len_for(&frame.footprint, self.phases).unwrap_or(0)
    }
}

/// Buffer lengths for [`Buffers`] (elements, not bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lengths {
    /// `image` and `accumulator`: width × height.
    pub pixels: usize,
    /// `rows`: the image height.
    pub rows: usize,
    /// `sheets`: three sheets of samples.
    pub sheets: usize,
    /// `work`: the sheet accumulator (4 per pixel), the opacity-correction table and the
    /// footprint stencils.
    pub work: usize,
}

/// The caller's buffers ([`Settings::lengths`] gives their lengths; longer is fine).
#[derive(Debug)]
pub struct Buffers<'a, T> {
    /// The result: premultiplied linear RGBA, row-major, top row first, composited over black
    /// (see [`crate::output`] for 8-bit pixels).
    pub image: &'a mut [[f32; 4]],
    /// The sheet accumulator and tables built per frame (any contents: they are cleared).
    pub work: &'a mut [f32],
    /// Per-row extents of what a sheet touched.
    pub rows: &'a mut [RowSpan],
    /// Three sheets of samples (the ring the volume is read through).
    pub sheets: &'a mut [T],
}

impl<'a, T> Buffers<'a, T> {
    /// The buffers, in the order of their fields.
    pub fn new(
        image: &'a mut [[f32; 4]],
        work: &'a mut [f32],
        rows: &'a mut [RowSpan],
        sheets: &'a mut [T],
    ) -> Self {
        Buffers {
            image,
            work,
            rows,
            sheets,
        }
    }
}

/// Renders `data` (`dims` samples, x fastest, then y, then z) with `settings` and the generic
/// table `generic` (N × N; the CLI's `--table` default is 129) into `buffers.image`.
///
/// This is `footprint render`'s float path for a volume in memory with `--lod 0` (or a view in
/// which `--lod auto` keeps level 0 and nothing is supersampled, which is every view of at least
/// about one pixel per sample): the same image, bit for bit, for any `--threads`.
pub fn render_volume<T: Sample, const N: usize>(
    data: &[T],
    dims: [usize; 3],
    settings: &Settings<'_>,
    generic: &GenericTable<N>,
    buffers: Buffers<'_, T>,
) -> Result<RenderStats, Error> {
    let mut volume = MemoryVolume::new(data, dims)?;
    let frame = settings.frame(dims)?;
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: settings.lut,
            lo: settings.window[0],
            hi: settings.window[1],
        },
        shading: settings.shading,
    };
    let table = ViewTable::<N>::build(&frame.footprint, generic, settings.lookup, settings.lookup);
    let (stencil_len, pixels) = (settings.stencil_len(&frame), frame.image_len());
    let needed = settings.work_len(&frame);
    if buffers.work.len() < needed {
        return Err(BufferError::TooSmall {
            needed,
            got: buffers.work.len(),
        }
        .into());
    }
    let (accumulator, rest) = buffers.work.split_at_mut(4 * pixels);
    let accumulator = accumulator.as_chunks_mut::<4>().0;
    accumulator.fill([0.0; 4]);
    let (opacity, rest) = rest.split_at_mut(OPACITY_TABLE_LEN);
    let render = RenderBuffers {
        accumulator,
        image: buffers.image,
        rows: buffers.rows,
    };
    let (order, sheets) = (settings.order, buffers.sheets);
    // Footprints up to 128 px across through the phase stencils (as the CLI), wider ones through
    // the view table; each its own monomorphised sheet loop.
    if stencil_len > 0 {
        let stencils = Stencils::build(&table, settings.phases, &mut rest[..stencil_len])?;
        run(
            &frame,
            &stencils,
            (shader, order),
            render,
            opacity,
            sheets,
            &mut volume,
        )
    } else {
        run(
            &frame,
            &table,
            (shader, order),
            render,
            opacity,
            sheets,
            &mut volume,
        )
    }
}

/// The sheets of `volume` through `sampler`'s float path into `render`.
fn run<S: Splatter + ?Sized, T: Sample>(
    frame: &FrameSetup,
    sampler: &S,
    (shader, order): (Shader<'_>, Order),
    render: RenderBuffers<'_>,
    opacity: &mut [f32],
    sheets: &mut [T],
    volume: &mut MemoryVolume<'_, T>,
) -> Result<RenderStats, Error> {
    let path = FloatPath::new(sampler);
    let mut renderer = SheetRenderer::with_path(frame, path, shader, order, render, None)?
        .with_opacity_table(opacity)?;
    let mut ring = SheetRing::for_renderer(sheets, &renderer)?;
    render_from(&mut renderer, &mut ring, volume)?;
    Ok(renderer.finish())
}
