//! # Footprint
//!
//! A `no_std`, allocation-free implementation of Lee Westover's footprint-evaluation splatting
//! ("Footprint Evaluation for Volume Rendering", SIGGRAPH 1990).
//!
//! Every voxel is projected to the screen and its reconstruction kernel's *footprint* (the kernel
//! integrated along the view direction) is spread over the pixels it covers. The footprint is
//! precomputed once per kernel as a [`GenericTable`]; per view, the projected kernel ellipse is
//! mapped back onto the unit circle ([`Footprint`]) and the generic table resampled into a
//! [`ViewTable`], which every voxel then reuses.
//!
//! ## Where things live
//! - [`math`]: the one door to float functions (`libm` or `micromath` backend).
//! - [`kernel`]: kernels, their footprints, specs like `gaussian:spread=1.6,sigmas=2.5`.
//! - [`geometry`]: grid, view, the screen ellipse, its extent and its map to the unit circle
//!   (`ellipse.rs`), and the paper's θ decomposition (`paper.rs`).
//! - [`table`]: generic and view tables, lookup, the table byte format.
//! - [`stencil`]: a view's footprint sampled per sub-pixel phase, for fast small splats.
//! - [`splat`](mod@splat): spreading one voxel into a caller-owned image.
//! - [`frame`]: one view of one volume: placement, sheet axis and order, buffer sizes.
//! - [`shade`]: transfer functions, Phong, Levoy iso-surfaces, grid-coordinate texture.
//! - [`composite`]: Porter–Duff over/under of premultiplied RGBA.
//! - [`fixed`]: the integer-only splat, accumulator and compositing (formats, rounding, headroom).
//! - [`render`]: the sheet renderer (`mod.rs`), its float and fixed precisions (`precision.rs`),
//!   and the sheet window, ring and gradient (`sheets.rs`).
//! - [`source`]: the `SheetSource` interface for voxels streamed from outside, and its driver.
//! - [`lod`]: levels of detail, coarser levels built sheet by sheet from any `SheetSource`.
//! - [`refine`]: the paper's adaptive re-sampling: refined axes, Catmull–Rom interpolation,
//!   refinement factors (rendered by `render/refined.rs`).
//! - [`volume`]: a volume already in memory (`&[T]`, x fastest) as a `SheetSource`.
//! - [`output`]: the result as 8-bit pixels (linear, sRGB, straight alpha) or RGB565.
//! - [`quick`] and [`prelude`]: the front door, a volume in memory in one call.
//!
//! ## Conventions (kept everywhere)
//! - world = G·(i, j, k), G the grid-to-world matrix (diagonal = spacing, world units such as mm);
//! - screen = V·world + (W/2, H/2, 0), V the world-to-screen linear map, in pixels; x right,
//!   y down, z away from the viewer; pixel (x, y) has its centre at (x + 0.5, y + 0.5);
//! - a footprint weight is a density in px⁻² that integrates to one over the screen plane.
//!
//! ## Rendering a volume that is in memory
//! The front door ([`quick`], imported with [`prelude`]): a `&[T]` volume (x fastest), VTK's
//! camera as `footprint render --view` takes it, a transfer-function [`Preset`](shade::Preset),
//! into caller-owned buffers, the same image as `footprint render --slicing object` bit for bit:
//! ```
//! use footprint::prelude::*;
//! let (dims, data) = ([16, 16, 16], (0..4096u32).map(|i| (i * 37 % 256) as u8).collect::<Vec<_>>());
//! let mut s = Settings::new([64, 64], Preset::Density.lut());
//! (s.spacing, s.view, s.window) = ([1.0, 1.0, 2.0], [30.0, 20.0, 0.0], [0.0, 255.0]);
//! let n = s.lengths(dims)?;
//! let (mut image, mut work) = (vec![[0.0; 4]; n.pixels], vec![0.0; n.work]);
//! let (mut rows, mut sheets) = (vec![RowSpan::EMPTY; n.rows], vec![0u8; n.sheets]);
//! let generic = GenericTable::<33>::build(s.kernel);
//! let buffers = Buffers::new(&mut image, &mut work, &mut rows, &mut sheets);
//! let stats = render_volume(&data, dims, &s, &generic, buffers)?;
//! let pixels: Vec<[u8; 4]> = image.iter().map(|&p| linear8(p)).collect(); // or srgb8, straight8
//! assert_eq!(stats.sheets, 16);
//! assert!(pixels.iter().any(|p| p[3] > 0));
//! # Ok::<(), footprint::Error>(())
//! ```
//! `core/examples/in_memory.rs` is the same as a program that writes the CLI's PNG byte for byte.
//!
//! ## Streaming voxels from outside
//! A [`SheetSource`](source::SheetSource) hands over one sheet at a time (row-major over the
//! sheet's in-sheet axes, the lower axis fastest; see [`frame`]); the renderer keeps three in a
//! [`SheetRing`](render::SheetRing). A source that can only deliver in one order (a sensor, a
//! pipe) says so, and [`source::order_for`] picks the compositing order it implies:
//! ```
//! use footprint::{frame::*, render::*, shade::*, source::*, composite::RowSpan, prelude::Preset};
//! use footprint::{FootprintOptions, GenericTable, Grid, Kernel, Lookup, View, ViewTable};
//! /// Sheets of a ramp along z, in ascending order only.
//! struct Sensor { next: usize }
//! impl SheetSource for Sensor {
//!     type Sample = u8;
//!     type Error = RenderError;
//!     fn read_sheet(&mut self, _axis: usize, k: usize, out: &mut [u8]) -> Result<(), RenderError> {
//!         out.fill((k * 16) as u8);
//!         self.next += 1;
//!         Ok(())
//!     }
//!     fn sequential_axis(&self) -> Option<usize> { Some(2) }
//! }
//! let (dims, size) = ([16, 16, 16], [48, 48]);
//! let grid = Grid::from_spacing([1.0; 3]).unwrap();
//! let view = View::from_vtk_camera([0.0, 0.0, 0.0], 1.0, dims, &grid, size).unwrap();
//! let frame = FrameSetup::new(dims, &grid, &view, &Kernel::PAPER_GAUSSIAN, FootprintOptions::default(), size).unwrap();
//! let mut source = Sensor { next: 0 };
//! let order = order_for(&source, &frame, Order::BackToFront).unwrap();
//! let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
//! let table = ViewTable::<33>::build(&frame.footprint, &generic, Lookup::Bilinear, Lookup::Bilinear);
//! let shader = Shader { labels: None, tf: TransferFunction { lut: Preset::Grey.lut(), lo: 0.0, hi: 255.0 }, shading: Shading::Emission };
//! let (mut acc, mut image, mut rows) = (vec![[0.0; 4]; 48 * 48], vec![[0.0; 4]; 48 * 48], vec![RowSpan::EMPTY; 48]);
//! let buffers = RenderBuffers { accumulator: &mut acc, image: &mut image, rows: &mut rows };
//! let mut renderer = SheetRenderer::new(&frame, &table, shader, order, buffers, None).unwrap();
//! let mut sheets = vec![0u8; 3 * frame.sheet_shape().0];
//! let mut ring = SheetRing::for_renderer(&mut sheets, &renderer).unwrap(); // the order given once
//! render_from(&mut renderer, &mut ring, &mut source).unwrap();
//! assert_eq!((renderer.finish().sheets, source.next), (16, 16));
//! ```
//!
//! ## Fixed point
//! The same frame with integer-only splatting and compositing (Q24 colour, [`fixed`]): build a
//! [`FixedTable`](fixed::FixedTable) instead of the view table and render through a
//! [`FixedPath`](render::FixedPath); the image is `[u32; 4]` per pixel,
//! [`fixed::to_f32`] converts it exactly.
//! ```
//! use footprint::{fixed::{self, FixedTable}, frame::*, render::*, shade::*, source::*};
//! use footprint::{composite::RowSpan, prelude::Preset, volume::MemoryVolume};
//! use footprint::{FootprintOptions, GenericTable, Grid, Kernel, Lookup, View};
//! let (dims, size) = ([16, 16, 16], [48, 48]);
//! let data = vec![180u8; 16 * 16 * 16];
//! let grid = Grid::from_spacing([1.0; 3]).unwrap();
//! let view = View::from_vtk_camera([30.0, 20.0, 0.0], 1.0, dims, &grid, size).unwrap();
//! let frame = FrameSetup::new(dims, &grid, &view, &Kernel::PAPER_GAUSSIAN, FootprintOptions::default(), size).unwrap();
//! let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
//! let mut table = FixedTable::<33>::zeroed();
//! table.build_view(&frame, &generic, Lookup::Bilinear, Lookup::Bilinear).unwrap();
//! let shader = Shader { labels: None, tf: TransferFunction { lut: Preset::Grey.lut(), lo: 0.0, hi: 255.0 }, shading: Shading::Emission };
//! let (mut acc, mut image, mut rows) = (vec![[0i64; 4]; 48 * 48], vec![[0u32; 4]; 48 * 48], vec![RowSpan::EMPTY; 48]);
//! let buffers = RenderBuffers { accumulator: &mut acc, image: &mut image, rows: &mut rows };
//! let path = FixedPath::new(&frame, &table).unwrap();
//! let mut renderer = SheetRenderer::with_path(&frame, path, shader, Order::BackToFront, buffers, None).unwrap();
//! let mut sheets = vec![0u8; 3 * frame.sheet_shape().0];
//! let mut ring = SheetRing::for_renderer(&mut sheets, &renderer).unwrap();
//! render_from(&mut renderer, &mut ring, &mut MemoryVolume::new(&data, dims).unwrap()).unwrap();
//! renderer.finish();
//! let centre = fixed::to_f32(image[24 * 48 + 24]);
//! assert!(centre[3] > 0.5 && centre[3] <= 1.0);
//! ```
//!
//! ## One footprint
//! ```
//! use footprint::{geometry::*, kernel::Kernel, splat::*, table::*};
//! let kernel = Kernel::parse("gaussian:spread=1.6,sigmas=2.5").unwrap();
//! let generic = GenericTable::<33>::build(kernel);
//! let grid = Grid::from_spacing([4.0, 2.0, 2.0]).unwrap();
//! let view = View::new(glam::Mat3::IDENTITY).unwrap();
//! let fp = Footprint::new(&kernel, &view.grid_to_screen(&grid), FootprintOptions::default()).unwrap();
//! let table = ViewTable::<33>::build(&fp, &generic, Lookup::Bilinear, Lookup::Bilinear);
//! let mut pixels = [0.0f32; 32 * 32];
//! let mut image = ImageMut::new(&mut pixels, 32, 32, 32).unwrap();
//! splat(&table, [16.0, 16.0], &1.0f32, &mut image).unwrap();
//! let total: f32 = pixels.iter().sum();
//! assert!((total - 1.0).abs() < 0.01, "a splat deposits one unit, got {total}");
//! ```
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![deny(missing_docs, rustdoc::broken_intra_doc_links)]
// `!(x > 0.0)` is how this crate sends NaN down the rejecting branch; `x <= 0.0` would let it through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// `f32`/`f64` are listed in `core/clippy.toml` as disallowed types, denied only inside the
// fixed-point path's integer modules (`fixed::splat`, `fixed::composite`); everywhere else floats
// are the point.
#![allow(clippy::disallowed_types)]

pub mod composite;
pub mod fixed;
pub mod frame;
pub mod geometry;
pub mod kernel;
pub mod lod;
pub mod math;
pub mod output;
pub mod prelude;
pub mod quick;
pub mod refine;
pub mod render;
pub mod shade;
pub mod source;
pub mod splat;
pub mod stencil;
pub mod table;
pub mod volume;

/// The `glam` the core's API speaks (`Mat3`, `Vec3`), re-exported so callers use the same version.
pub use glam;

pub use geometry::{Footprint, FootprintOptions, GeometryError, Grid, Mapping, View};
pub use kernel::{Kernel, KernelSpecError};
pub use splat::{splat, BufferError, ImageMut, Sampler};
pub use table::{GenericTable, Lookup, TableError, ViewLayout, ViewTable};

use core::fmt;

/// Any error the core can return, for callers that want one type.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A bad kernel spec.
    Kernel(KernelSpecError),
    /// Bad grid or view geometry.
    Geometry(GeometryError),
    /// A table that cannot be loaded or saved.
    Table(TableError),
    /// A caller buffer of the wrong size, or a bad splat position.
    Buffer(BufferError),
    /// A frame that cannot be set up.
    Frame(frame::FrameError),
    /// A sheet the renderer refused.
    Render(render::RenderError),
    /// A view outside the fixed-point path's range.
    Fixed(fixed::FixedError),
    /// A slice that is not a volume of the dimensions given.
    Volume(volume::VolumeError),
    /// A sequential source whose sheets run along another axis than the frame's.
    Order(source::OrderMismatch),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Kernel(e) => e.fmt(f),
            Error::Geometry(e) => e.fmt(f),
            Error::Table(e) => e.fmt(f),
            Error::Buffer(e) => e.fmt(f),
            Error::Frame(e) => e.fmt(f),
            Error::Render(e) => e.fmt(f),
            Error::Fixed(e) => e.fmt(f),
            Error::Volume(e) => e.fmt(f),
            Error::Order(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for Error {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Error::Kernel(e) => Some(e),
            Error::Geometry(e) => Some(e),
            Error::Table(e) => Some(e),
            Error::Buffer(e) => Some(e),
            Error::Frame(e) => Some(e),
            Error::Render(e) => Some(e),
            Error::Fixed(e) => Some(e),
            Error::Volume(e) => Some(e),
            Error::Order(e) => Some(e),
        }
    }
}

macro_rules! from_error {
    ($($variant:ident($ty:ty)),*) => {$(
        impl From<$ty> for Error {
            fn from(e: $ty) -> Self {
                Error::$variant(e)
            }
        }
    )*};
}
from_error!(
    Kernel(KernelSpecError),
    Geometry(GeometryError),
    Table(TableError),
    Buffer(BufferError),
    Frame(frame::FrameError),
    Render(render::RenderError),
    Fixed(fixed::FixedError),
    Volume(volume::VolumeError),
    Order(source::OrderMismatch)
);
