//! Argument structs and value parsers that several commands share. This module imports no command
//! and nothing above the pipeline: commands flatten these structs into their own, and the pipeline
//! reads them.
//!
//! Value formats: lists are comma-separated (`60,30,30`), sizes `WxH`, angles in degrees, matrices
//! nine numbers in row-major order.

use crate::CliError;
use clap::{Args, ValueEnum};
use footprint::frame::Order;
use std::path::PathBuf;

pub mod keywords;
mod model;
mod parse;
mod phase;
pub mod resolve;
pub use crate::io::image::Background;
pub use keywords::{Keywords, Value};
pub use model::*;
pub use parse::*;
pub use phase::*;
pub use resolve::{plan, scene, single};

/// Table lookup, as on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ValueEnum)]
pub enum LookupArg {
    Nearest,
    Bilinear,
}

impl From<LookupArg> for footprint::Lookup {
    fn from(l: LookupArg) -> Self {
        match l {
            LookupArg::Nearest => footprint::Lookup::Nearest,
            LookupArg::Bilinear => footprint::Lookup::Bilinear,
        }
    }
}

/// How the footprint is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ValueEnum)]
pub enum MethodArg {
    /// View table built through the Cholesky (or sheet-parallelogram) map: no singular angle.
    Robust,
    /// View table built through the paper's θ/Sx/Sy decomposition with its 0.01° cheat.
    Paper,
    /// No view table: each pixel is mapped straight into the generic table.
    Direct,
    /// f64, no tables: the exact line integral (the float reference).
    Reference,
}

/// How the sheet accumulator, the working image and compositing count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AccumArg {
    /// f32 throughout.
    Float,
    /// Integers only in the splat and compositing (see the core's `fixed` module): an integer
    /// table, an i64 accumulator, a Q24 image. Bit-exact on every target.
    Fixed,
}

/// How the volume is cut into layers that are composited one after another (`--slicing`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SlicingArg {
    /// The paper's sheets: one per voxel plane along the grid axis most parallel to the image,
    /// each voxel's whole footprint in its sheet.
    Object,
    /// Slabs parallel to the image plane (Mueller and Crawfis 1998): each voxel's kernel cut by
    /// the slabs it overlaps, each section from the pre-integrated section table.
    Image,
    /// The default: object slicing where a pilot measures it within the default target of the
    /// continuous model (`plan::DEFAULT_TARGET_DB`), the thickest slabs that reach it otherwise.
    Auto,
}

/// What `--quality DB` aims at (`--quality-reference`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QualityReferenceArg {
    /// The f64 renderer with the same sheets (`verify`'s `--reference sheets`): the table
    /// configuration's error, predicted from one footprint in milliseconds.
    Sheets,
    /// The continuous volume-rendering integral (`verify`'s `--reference continuous`): the error
    /// a user sees, measured on a pilot of sampled rays; chooses the slicing and slab too.
    Continuous,
    /// The built-in scene only: the continuous integral of its analytic field sampled
    /// `--field-size` N³ over the same box (`verify`'s `--reference field`), the finer field a
    /// coarse grid stands for; measured on a pilot like `continuous`, and chooses refinement
    /// (`--refine 0`) too.
    Field,
}

/// `verify --reference`: what the core's image is measured against.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceArg {
    Sheets,
    Continuous,
    /// The built-in scene only: the continuous integral of its field sampled `--field-size` N³
    /// (the finer field the grid stands for; the one reference `--refine` can approach).
    Field,
}

impl ReferenceArg {
    /// The name the command line and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            ReferenceArg::Sheets => "sheets",
            ReferenceArg::Continuous => "continuous",
            ReferenceArg::Field => "field",
        }
    }
}

impl SlicingArg {
    /// The name the command line and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            SlicingArg::Object => "object",
            SlicingArg::Image => "image",
            SlicingArg::Auto => "auto",
        }
    }
}

fn parse_background(s: &str) -> Result<Background, String> {
    Ok(match s {
        "black" => Background::Black,
        "transparent" => Background::Transparent,
        "" => return Err("expected black, transparent or a PNG file".into()),
        path => Background::Image(PathBuf::from(path)),
    })
}

/// The transfer curve of PNG colour values (see [`crate::io::image::Gamma`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GammaArg {
    /// Values as computed, no curve (VTK and ParaView's default).
    Linear,
    /// The sRGB curve, and an `sRGB` chunk.
    Srgb,
}

fn parse_depth(s: &str) -> Result<u8, String> {
    match s {
        "8" => Ok(8),
        "16" => Ok(16),
        _ => Err(format!("'{s}' is not a PNG bit depth (expected 8 or 16)")),
    }
}

/// The footprint flags `splat`, `render` and `verify` share.
#[derive(clap::Args, Debug, Clone)]
pub struct FootprintArgs {
    /// Kernel spec, e.g. gaussian:spread=1.6,sigmas=2.5 (also cone, sinc, bilinear).
    #[arg(long, default_value = crate::scene::DEFAULT_KERNEL)]
    pub kernel: String,
    /// Generic and view table size N (N×N). The default, 129, is on the Pareto frontier of
    /// `footprint chart` for both charted scenes (docs/accuracy.md, "Speed against accuracy").
    #[arg(long, default_value_t = 129)]
    pub table: usize,
    /// Load the generic table from a file written by `footprint tables` (its N must equal --table).
    #[arg(long)]
    pub table_file: Option<std::path::PathBuf>,
    /// Lookup, both when building the view table and when sampling it (or the generic table).
    #[arg(long, value_enum, default_value_t = LookupArg::Bilinear)]
    pub lookup: LookupArg,
    /// Footprint method.
    #[arg(long, value_enum, default_value_t = MethodArg::Robust)]
    pub method: MethodArg,
    /// Smallest footprint semi-axis, pixels (sub-pixel footprints are widened to it).
    #[arg(long, default_value_t = footprint::geometry::DEFAULT_MIN_RADIUS_PX, value_parser = parse_min_radius)]
    pub min_radius: f32,
    /// `--method paper` only: how close to 45° (degrees) the paper's rotation cheat nudges θ;
    /// 0 disables it, and the singular angle becomes a typed error.
    #[arg(long, default_value_t = 0.01, value_parser = parse_finite_f32)]
    pub paper_cheat: f32,
}

impl FootprintArgs {
    /// The ellipse-to-circle map `--method` and `--paper-cheat` ask for.
    pub fn mapping(&self) -> Result<footprint::geometry::Mapping, CliError> {
        if self.method != MethodArg::Paper {
            return Ok(footprint::geometry::Mapping::Robust);
        }
        if !(self.paper_cheat >= 0.0 && self.paper_cheat < 45.0) {
            return Err(CliError::input(format!(
                "--paper-cheat {}: expected degrees in [0, 45)",
                self.paper_cheat
            )));
        }
        Ok(footprint::geometry::Mapping::Paper {
            cheat_deg: self.paper_cheat,
        })
    }
}

impl FootprintArgs {
    /// The parsed `--kernel`.
    pub fn kernel(&self) -> Result<footprint::Kernel, CliError> {
        footprint::Kernel::parse(&self.kernel)
            .map_err(|e| CliError::input(format!("--kernel '{}': {e}", self.kernel)))
    }

    /// The generic table: loaded from `--table-file` (which must be for `kernel` and of size N), or
    /// built.
    pub fn generic_table<const N: usize>(
        &self,
        kernel: &footprint::Kernel,
    ) -> Result<Box<footprint::GenericTable<N>>, CliError> {
        crate::io::table::generic_for::<N>(self.table_file.as_deref(), kernel)
    }
}

/// Compositing direction on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OrderArg {
    /// Farthest sheet first, composited over (the paper's order).
    BackToFront,
    /// Nearest sheet first, composited under.
    FrontToBack,
}

impl From<OrderArg> for Order {
    fn from(o: OrderArg) -> Self {
        match o {
            OrderArg::BackToFront => Order::BackToFront,
            OrderArg::FrontToBack => Order::FrontToBack,
        }
    }
}

/// Every flag of `render` (and of `verify`, which takes them all).
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// A volume already in memory, rendered instead of VOLUME or the built-in scene (set by a
    /// program, such as the Python package; not a flag).
    #[arg(skip)]
    pub memory: Option<crate::io::stream::InMemory>,
    /// What `--stream -` reads instead of standard input (set by a program; not a flag).
    #[arg(skip)]
    pub stdin: Option<crate::io::stream::Pipe>,
    /// Volume: .nrrd/.nhdr, .vti, .vtk, .mhd/.mha, .nii/.nii.gz, a NIfTI or Analyze pair
    /// (.hdr + .img, either may be .gz), or headerless raw with --dims and --type. Omitted: the
    /// built-in electron-density scene.
    pub volume: Option<PathBuf>,
    /// Image size, WxH pixels.
    #[arg(help_heading = "Camera", short, long, default_value = "512x512", value_parser = parse_size)]
    pub size: (usize, usize),
    /// VTK/ParaView camera AZ,EL,ROLL in degrees: from ParaView's default (on +z looking toward
    /// −z, +y up), Azimuth(AZ), Elevation(EL), Roll(ROLL); or a view-direction button of
    /// ParaView's: +x, -x, +y, -y (+z up), +z, -z (+y up). See docs/cli.md, "Camera".
    #[arg(help_heading = "Camera", long, default_value = "0,0,0", value_parser = parse_view, allow_hyphen_values = true)]
    pub view: [f32; 3],
    /// Multiplies the zoom that fits the volume's bounding sphere into the image (VTK's
    /// ResetCamera).
    #[arg(help_heading = "Camera", long, default_value_t = 1.0, value_parser = parse_positive)]
    pub zoom: f32,
    /// Explicit world-to-screen matrix, nine numbers row-major, pixels per world unit (overrides
    /// --view and --zoom). With --perspective only its rotation counts: it must be a rotation
    /// times one scale, and the scale is ignored (the field of view and --zoom set it).
    #[arg(help_heading = "Camera", long, value_parser = parse_list::<9>, allow_hyphen_values = true)]
    pub view_matrix: Option<[f32; 9]>,
    /// Perspective projection with this vertical field of view, degrees (0 < FOVY < 180): a
    /// pinhole on the view axis, the volume's centre at the image centre, focal length
    /// (H/2) / tan(FOVY/2) × --zoom pixels. Float accumulation only; every voxel gets its own
    /// footprint (the generic table is sampled directly, whatever --method says).
    #[arg(help_heading = "Camera", long, value_name = "FOVY", value_parser = parse_fov)]
    pub perspective: Option<f32>,
    /// With --perspective: the eye's distance from the volume's centre, world units. Default
    /// VTK's ResetCamera: R / sin(FOVY/2), R half the diagonal of the voxel-centre box. An eye
    /// inside the volume (or within a kernel radius of it, or among its sheets) is refused.
    #[arg(help_heading = "Camera", long, value_name = "D", value_parser = parse_positive)]
    pub eye_distance: Option<f32>,
    /// Transfer function: a preset (grey, ct-bone-skin, density; ParaView's Grayscale, Cool to
    /// Warm, Viridis, X Ray), a ParaView preset file (`.json`, `FILE.json#NAME` for one of
    /// several) or a file of `t r g b a` lines. Default: density (built-in scene), ct-bone-skin
    /// (a volume). Repeatable: one per component of a multi-component volume (docs/components.md).
    #[arg(help_heading = "Picture", long, action = clap::ArgAction::Append)]
    pub tf: Vec<String>,
    /// Value window LO,HI mapped onto the transfer function. Default for a volume: Otsu's
    /// threshold between background and foreground to the 99.5th percentile, from at most 2^20
    /// strided samples (`footprint info` prints it); the built-in scene: the data's range. Data units, f64.
    #[arg(help_heading = "Picture", long, value_parser = parse_list_f64::<2>, allow_hyphen_values = true)]
    pub window: Option<[f64; 2]>,
    /// Render only the voxels of this box: inclusive voxel-index ranges along i, j, k (e.g.
    /// 0:127,0:255,40:112). The rest are missing samples, in the picture and in the continuous
    /// model; the voxels keep their places, the window and the transfer function. See docs/cut.md.
    #[arg(help_heading = "Picture", long, value_name = "X0:X1,Y0:Y1,Z0:Z1", value_parser = parse_crop)]
    pub crop: Option<crate::scene::Crop>,
    /// Keep the world points x with NX·x + NY·y + NZ·z ≤ D (world units, the volume's centre at
    /// the origin); repeatable, every plane kept. Kernels a plane crosses are cut where it
    /// crosses each ray; renders with image-aligned slabs. See docs/cut.md.
    #[arg(help_heading = "Picture", long, value_name = "NX,NY,NZ,D", value_parser = parse_clip, allow_hyphen_values = true, action = clap::ArgAction::Append)]
    pub clip: Vec<crate::scene::ClipPlane>,
    /// A label volume's colours: JSON `{"1": [r, g, b, a], …}` (a file, or the text) or ITK-SNAP's
    /// label file; unlisted labels are transparent (docs/labels.md).
    #[arg(help_heading = "Picture", long, value_name = "FILE|JSON")]
    pub labels: Option<String>,
    /// Shading: emission, phong, iso:VALUE (Levoy iso-surface at VALUE, data units), texture.
    #[arg(help_heading = "Picture", long, default_value = "emission")]
    pub shading: String,
    /// What the volume is composited over: `black` (an RGB PNG), `transparent` (an RGBA PNG
    /// with straight alpha, the render's coverage; PNG output only) or a PNG file of the output
    /// size (read with --gamma's curve; a file named `black` or `transparent` needs a `./`).
    #[arg(help_heading = "Picture", long, default_value = "black", value_parser = parse_background)]
    pub background: Background,
    /// PNG colour values: `linear` writes them as computed, with no curve (VTK and ParaView's
    /// default, so presets show the colours they show there; PSNR is measured on these values);
    /// `srgb` treats them as linear light and applies the sRGB curve. PNG output only.
    #[arg(help_heading = "Picture", long, value_enum, default_value_t = GammaArg::Linear)]
    pub gamma: GammaArg,
    /// PNG bits per sample: 8 or 16. PNG output only.
    #[arg(help_heading = "Picture", long, default_value = "8", value_parser = parse_depth)]
    pub depth: u8,
    /// Write a JSON summary here.
    #[arg(help_heading = "Picture", long)]
    pub json: Option<PathBuf>,
    /// Output image: `.png` (RGB, the premultiplied colour over the background, clamped; RGBA
    /// with --background transparent; see --gamma and --depth) or `.pfm` (float32 RGB, linear
    /// values unclamped, over black or the background image); other extensions are refused. `render`
    /// defaults to footprint.png; `verify` writes one only if asked. Every output is checked
    /// before rendering, and none is written unless all are.
    #[arg(help_heading = "Picture", short, long)]
    pub out: Option<PathBuf>,
    /// VTK files (.vtk, .vti) with several point-data arrays: the one to render, by name (default:
    /// the active scalars). A name the file lacks is an error that lists the file's arrays.
    #[arg(help_heading = "Input", long, value_name = "NAME")]
    pub array: Option<String>,
    /// The built-in scene only: its analytic field sampled N×N×N over the same box (64 by
    /// default; 16 and 128 are what the refinement chart compares).
    #[arg(help_heading = "Input", long, value_name = "N", default_value_t = crate::builtin::SIDE, value_parser = parse_scene_size)]
    pub scene_size: usize,
    /// The built-in scene only: the finer sampling, N×N×N over the same box, whose continuous
    /// integral `--quality-reference field` and `verify --reference field` measure against (it
    /// must exceed --scene-size).
    #[arg(help_heading = "Input", long, value_name = "N", default_value_t = 128, value_parser = parse_scene_size)]
    pub field_size: usize,
    /// Stream the volume a few sheets at a time: raw (with --dims and --type), NRRD with raw
    /// encoding, uncompressed MetaImage; `-`: raw z-slices on standard input (needs --dims, --type).
    /// Held whole where a pilot needs it and it fits, for the file's picture (docs/cli.md).
    #[arg(help_heading = "Input", long)]
    pub stream: Option<PathBuf>,
    /// Raw volumes: dimensions X,Y,Z.
    #[arg(help_heading = "Input", long, value_parser = parse_dims, allow_hyphen_values = true)]
    pub dims: Option<[usize; 3]>,
    /// Raw volumes: sample type (u8, i8, u16, i16, u32, i32, f32, f64).
    #[arg(help_heading = "Input", long = "type", value_parser = parse_sample_type)]
    pub sample_type: Option<crate::io::volume::SampleType>,
    /// Raw volumes: byte order.
    #[arg(help_heading = "Input", long, value_enum, default_value_t = EndianArg::Little)]
    pub endian: EndianArg,
    /// Raw volumes: spacing X,Y,Z in world units.
    #[arg(help_heading = "Input", long, default_value = "1,1,1", value_parser = parse_spacing, allow_hyphen_values = true)]
    pub spacing: [f32; 3],
    /// Kernel, tables, lookup, method (`reference` renders with the f64 reference) and minimum
    /// footprint radius.
    #[command(flatten, next_help_heading = "Method")]
    pub footprint: FootprintArgs,
    /// Accumulation: float, or fixed (integer splat, accumulator and compositing; bit-exact).
    #[arg(help_heading = "Method", long, value_enum, default_value_t = AccumArg::Float)]
    pub accum: AccumArg,
    /// Slicing: `object`, the paper's sheets along the grid axis most parallel to the image (pops
    /// where that axis switches), `image`, slabs parallel to the image (Mueller and Crawfis 1998;
    /// no popping), or `auto`: object slicing where a pilot of sampled rays measures it at 44 dB
    /// against the continuous model, else the thickest slabs that reach it (docs/modes.md). Image
    /// slicing needs a gaussian kernel, float, an orthographic view and the volume in memory;
    /// else (or with --accum fixed, --refine, --quality) `auto` is object slicing. [default: auto]
    #[arg(help_heading = "Method", long, value_enum)]
    pub slicing: Option<SlicingArg>,
    /// With --slicing image: slab thickness along the view ray, in smallest voxel spacings.
    #[arg(help_heading = "Method", long, value_name = "T", default_value_t = 1.0, value_parser = parse_positive)]
    pub slab: f32,
    /// The model both slicings render and `verify --reference continuous` integrates: `opacity`
    /// (opacity and colour reconstructed, no cap: the paper's sheets) or `extinction` (opaque
    /// voxels capped at 1 − 10⁻⁶ per world unit). See docs/accuracy.md, "The model".
    #[arg(help_heading = "Method", long, value_enum, default_value_t = AbsorptionArg::Opacity)]
    pub absorption: AbsorptionArg,
    /// `pre` (the paper's: voxels shaded, then reconstructed) or `post` (values and gradients
    /// reconstructed into image-aligned slabs of --slab-post spacings, then classified and shaded
    /// per pixel, as ray casters do; float, orthographic, the volume in memory).
    #[arg(help_heading = "Method", long, value_enum, default_value_t = ClassificationArg::Pre)]
    pub classification: ClassificationArg,
    /// `composite` (the emission-absorption integral), or project the reconstructed value along
    /// each ray and classify the projection: `mip` (maximum), `minip` (minimum), `average`.
    /// Projections render post-classified slabs (docs/blend.md has the model).
    #[arg(help_heading = "Method", long, value_enum, default_value_t = BlendArg::Composite)]
    pub blend: BlendArg,
    /// With --classification post: reconstruct values and gradients with the kernel (gaussian) or
    /// `trilinear`ly, as VTK's ray casters do. `verify`: also the continuous model's.
    #[arg(help_heading = "Method", long, value_enum, default_value_t = ReconstructionArg::Kernel)]
    pub reconstruction: ReconstructionArg,
    /// With --classification post: slab thickness along the view ray, in voxel spacings (the
    /// smallest of the grid's three spacings): the step of the post-classified integral.
    /// [default: 0.7 for emission, 0.4 lit; trilinear 0.5 and 0.3 (docs/post-classification.md)]
    #[arg(help_heading = "Method", long, value_name = "T", value_parser = parse_positive)]
    pub slab_post: Option<f32>,
    /// With --classification post: splat values and gradients at 1/S of the image size, then
    /// interpolate them bilinearly per pixel before classifying; `auto`: the largest S keeping
    /// the kernel's shorter semi-axis ≥ 3 value pixels (docs/post-classification.md).
    #[arg(help_heading = "Method", long, value_name = "S", default_value = "auto", value_parser = parse_supersample)]
    pub value_subsample: Supersample,
    /// Sub-pixel phases per pixel (at most; wide footprints use fewer) of the stencils that splat
    /// footprints up to 128 px across (slab sections: at most 8); 0 walks the table per pixel.
    #[arg(help_heading = "Method", long, default_value_t = footprint::stencil::DEFAULT_PHASES)]
    pub phases: usize,
    /// --slicing image: voxel depths snapped to N phases per slab (T/(2N) at most), sections
    /// splatted by stencils built per view (docs/performance.md); 0: each kernel cut per pixel.
    #[arg(help_heading = "Method", long, value_name = "N", default_value_t = 0, value_parser = parse_depth_phases)]
    pub depth_phases: usize,
    /// Stencils (float or fixed) read at the nearest phase (up to 1/(2P) px off) or blended from
    /// four; `auto`: nearest where the default plan's pilot measures it at target, else blended.
    #[arg(help_heading = "Method", long, value_enum, default_value = "auto")]
    pub phase_lookup: PhaseLookupArg,
    /// Compositing direction (default back-to-front; a pipe's views impose theirs).
    #[arg(help_heading = "Method", long, value_enum)]
    pub order: Option<OrderArg>,
    /// Supersampling: `auto` renders at k× the size and averages k×k blocks when voxels project
    /// too close for the smallest footprint (removes the brightness bias of minified renders; see
    /// the harness's `pipeline::stages::supersample`); a number fixes k (1 = off).
    #[arg(help_heading = "Resolution", long, default_value = "auto", value_parser = parse_supersample)]
    pub supersample: Supersample,
    /// Image-space level of detail for magnified volumes: a number s ≥ 2 renders the frame at
    /// 1/s of the size (plus a 2-pixel margin) and resamples it to the size with Catmull-Rom
    /// cubic interpolation (the harness's `pipeline::stages::subsample`); `auto` picks the largest s that
    /// keeps the footprints' shorter semi-axis at least 2 px at the lower resolution (Gaussian
    /// kernels, orthographic views only; otherwise 1); 1 is off. Unset: 1, or `auto` where the
    /// default plan's pilot measures it to reach its target (docs/modes.md, "Subsampling").
    #[arg(help_heading = "Resolution", long, value_parser = parse_supersample)]
    pub subsample: Option<Supersample>,
    /// Level of detail: a number N splats level N (each level averages 2x2x2 samples of the one
    /// above into one, the spacing doubled, carrying the block's colour; 0 = full resolution);
    /// `auto`, the default, the deepest level L with 4^L x (level 0's projected spacing) <= 3 px
    /// (docs/modes.md, "Levels of detail") that a pilot of image rows also measures within 40 dB
    /// of level 0 (a volume or a file stream; a pipe too large to hold keeps the spacing rule alone). Orthographic views only (`auto` keeps a perspective view, and
    /// --refine, at level 0). The f64 reference `verify` compares with renders the same level
    /// (and, for a level >= 1, also level 0: `full res`); the continuous reference integrates
    /// full resolution (`auto` then means level 0). With --quality, `auto` means the level the
    /// quality pilot measures to hold the target against full resolution.
    #[arg(help_heading = "Resolution", long, default_value = "auto", value_parser = parse_lod)]
    pub lod: Lod,
    /// The paper's adaptive re-sampling for magnified volumes: along each grid axis, intervals
    /// whose neighbouring samples' classified colours (premultiplied RGBA, 0..1) differ by more
    /// than THRESHOLD get 2 or 4 steps of Catmull-Rom-interpolated samples, splatted with
    /// footprints for their local spacing (one-sided at region borders); steps stay ≥ 2 px apart
    /// on screen. Float, object slicing, orthographic, the volume in memory. See docs/modes.md,
    /// "Adaptive refinement".
    #[arg(help_heading = "Resolution", long, value_name = "THRESHOLD", value_parser = parse_threshold, allow_hyphen_values = true)]
    pub refine: Option<f32>,
    /// With --refine: refine along the sheet axis too (more sheets; the paper's method in full).
    /// Off by default: on the refinement chart it bought 0.9 dB for 3.6x the time.
    #[arg(help_heading = "Resolution", long)]
    pub refine_sheets: bool,
    /// Threads (bands of image rows) for the core's render; 0 = every core. The image is
    /// byte-identical for any number. A streamed volume renders on one thread; more than 256
    /// render on 256.
    #[arg(help_heading = "Speed and quality", long, default_value_t = 0, value_parser = parse_threads)]
    pub threads: usize,
    /// Occlusion culling (Mueller et al. 1999), sheets and slabs: front to back, 8x8-pixel tiles
    /// whose every pixel reached opacity 1 - EPS take nothing more, and voxels landing only on
    /// them are skipped. Each such pixel is within EPS per channel (peak 1) of the unculled image;
    /// `off` (the default) culls nothing. Implies --order front-to-back. docs/performance.md.
    #[arg(help_heading = "Speed and quality", long, value_name = "EPS|off", default_value = "off", value_parser = parse_cull)]
    pub cull: Cull,
    /// Target PSNR, dB, against --quality-reference: choose the cheapest configuration expected
    /// to reach it for this scene and view (overrides the table, lookup, method and
    /// accumulation; with the continuous reference also the slab thickness). Against the sheet
    /// reference it aims at full resolution and also chooses the level of detail (`--lod auto`),
    /// measured on a pilot of image rows when the volume is minified.
    #[arg(help_heading = "Speed and quality", long, value_parser = parse_finite_f64, conflicts_with_all = ["table", "lookup", "method", "accum", "table_file", "slab"])]
    pub quality: Option<f64>,
    /// What --quality aims at: `sheets`, the f64 renderer of the volume's sheets at full
    /// resolution (the table's error predicted in milliseconds; a coarser level's measured on a
    /// pilot of rows, about one full-resolution frame), or `continuous`, the volume-rendering integral (the error a
    /// user sees; measured on a pilot of about 4096 sampled rays, which costs seconds, and may
    /// choose image slicing; with --slicing image only slab thicknesses are considered), or
    /// `field` (built-in scene only), the continuous integral of the same analytic field sampled
    /// --field-size N³: measured like `continuous`, and the one reference that can choose
    /// `--refine 0`.
    #[arg(help_heading = "Speed and quality", long, value_enum, default_value_t = QualityReferenceArg::Sheets, requires = "quality")]
    pub quality_reference: QualityReferenceArg,
}

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 3 {
        return Err("expected X,Y,Z".into());
    }
    let mut out = [0usize; 3];
    for (o, p) in out.iter_mut().zip(v) {
        *o =
            p.trim().parse().ok().filter(|&n| n >= 1).ok_or_else(|| {
                format!("'{p}' is not a whole number >= 1 (expected X,Y,Z voxels)")
            })?;
    }
    Ok(out)
}

impl GammaArg {
    /// The image module's curve.
    pub fn curve(self) -> crate::io::image::Gamma {
        match self {
            GammaArg::Linear => crate::io::image::Gamma::Linear,
            GammaArg::Srgb => crate::io::image::Gamma::Srgb,
        }
    }
}

impl RenderArgs {
    /// How a PNG output is written: `--background transparent`, `--gamma`, `--depth`.
    pub fn png_style(&self) -> crate::io::image::PngStyle {
        crate::io::image::PngStyle {
            alpha: self.background == Background::Transparent,
            gamma: self.gamma.curve(),
            sixteen: self.depth == 16,
        }
    }

    /// Records every file these flags name for reading (the volume, `--stream`, a `--tf` file,
    /// a `--background` image, `--table-file`) as an input, which no output may replace
    /// ([`crate::io::outputs`]).
    pub fn note_inputs(&self) {
        let named = [
            self.volume.as_deref(),
            self.stream.as_deref(),
            self.labels.as_deref().map(std::path::Path::new),
            self.background.file(),
            self.footprint.table_file.as_deref(),
        ];
        let tfs = self
            .tf
            .iter()
            .map(|t| Some(std::path::Path::new(t.as_str())));
        for path in named.into_iter().chain(tfs).flatten() {
            crate::io::note_input_path(path);
        }
    }

    /// `--threads`, with 0 resolved to the number of cores, and at most [`MAX_THREADS`].
    pub fn thread_count(&self) -> usize {
        crate::threads::count(self.threads)
    }
}

/// `--threads N`: a whole number ≥ 0, with a message that says so for `-2` or `two`.
fn parse_threads(s: &str) -> Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| format!("'{s}' is not a whole number of threads >= 0 (0 = every core)"))
}

pub use crate::threads::MAX_THREADS;

/// `render`'s flags from a list of arguments (as on the command line after `render`), for
/// programs that drive the harness (benches, charts).
pub fn parse_args(args: &[&str]) -> Result<RenderArgs, CliError> {
    #[derive(clap::Parser)]
    struct Wrapper {
        #[command(flatten)]
        render: RenderArgs,
    }
    use clap::Parser as _;
    Wrapper::try_parse_from(std::iter::once("render").chain(args.iter().copied()))
        .map(|w| w.render)
        .map_err(|e| CliError::input(e.to_string()))
}

#[derive(Args, Debug, Clone)]
pub struct SplatArgs {
    #[command(flatten)]
    pub footprint: FootprintArgs,
    /// Voxel spacing along i,j,k in world units.
    #[arg(long, default_value = "1,1,1", value_parser = parse_spacing, allow_hyphen_values = true)]
    pub spacing: [f32; 3],
    /// General grid-to-world matrix, nine numbers row-major (overrides --spacing).
    #[arg(long, value_parser = parse_list::<9>, allow_hyphen_values = true)]
    pub grid_matrix: Option<[f32; 9]>,
    /// World-to-screen matrix, nine numbers row-major (pixels per world unit). Default identity.
    #[arg(long, value_parser = parse_list::<9>, allow_hyphen_values = true)]
    pub view_matrix: Option<[f32; 9]>,
    /// Rotation about the screen x axis composed onto the view, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite_f32)]
    pub rotate_x: f32,
    /// Rotation about the screen y axis composed onto the view, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite_f32)]
    pub rotate_y: f32,
    /// Rotation about the view direction (screen z) composed onto the view, degrees; positive
    /// turns +x toward +y (clockwise on screen, y pointing down).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite_f32)]
    pub rotate_z: f32,
    /// Image size, WxH pixels.
    #[arg(short, long, default_value = "256x256", value_parser = parse_size)]
    pub size: (usize, usize),
    /// Voxel position on screen, pixels (default: the image centre W/2,H/2).
    #[arg(long, value_parser = parse_list::<2>, allow_hyphen_values = true)]
    pub center: Option<[f32; 2]>,
    /// Output: .pfm (float32 weights) or .png (8-bit, normalised to the peak).
    #[arg(short, long)]
    pub out: PathBuf,
}
