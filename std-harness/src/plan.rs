//! The render plan (issues 41, 76): what draws a frame and at which resolution ([`Plan`]), as a
//! typed value beside what is rendered ([`Scene`]). The command line is resolved into both once
//! (`crate::args::resolve`, with every rule the flags alone decide); programs build them
//! themselves ([`Plan::default`] is the command line's default; [`Request`] for
//! `(Scene, Plan)`). Nothing here names a flag's clap type. The rules that need the volume or
//! the frame (a subsampling factor too large for the footprints, a supersampling the minimum
//! radius asks for, a view a pipe cannot feed) stay where those are known; the rules between the
//! resolution decorators that the scene and plan decide are [`check_levels`], applied to every
//! frame's set-up. The pipeline's door is `crate::pipeline::render`; it renders `(&Prepared, &Plan)` ([`crate::pipeline::render_frame`]);
//! `verify`, `bench`, `chart` and `--quality` build or derive plans ([`Plan::with_precision`],
//! [`crate::pipeline::quality::config::Config::plan`]) instead of rewriting flags, so `verify`
//! renders the plan `render` would, defaults included.
//!
//! ```text
//! Plan { end, table, phases, threads, subsample }
//! end:        Sheets(Float | Fixed)   the paper's sheets (object slicing)
//!             Slabs { thickness }     image-aligned slabs (float)
//!             Post { thickness, .. }  post-classified image-aligned slabs (float)
//!             Refined { threshold }   sheets on a refined grid (float, robust, orthographic)
//!             Reference               the f64 sheet reference
//! subsample:  a decorator of Sheets and Slabs: render at 1/s of the size and resample
//! ```
//!
//! Levels of detail and supersampling are the other decorators ([`resolution`]); they are
//! decided with the frame and never act on one frame together
//! (`pipeline::stages::prepare::setup_frame`).

use crate::scene::Scene;
use crate::CliError;
use footprint::frame::Order;
use footprint::Lookup;
use std::path::PathBuf;

mod phase;
pub mod resolution;
pub use phase::phase_lookup_name;
pub use resolution::{Lod, Resolution, Supersample};

/// The PSNR, dB, against the continuous model (`--absorption`'s, opacity by default) that the
/// default plan's frame is measured to reach on its pilot before object slicing is kept.
pub const DEFAULT_TARGET_DB: f64 = 44.0;

/// How a footprint is evaluated (`--method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// View table built through the Cholesky (or sheet-parallelogram) map: no singular angle.
    Robust,
    /// View table built through the paper's θ/Sx/Sy decomposition with its rotation cheat.
    Paper,
    /// No view table: each pixel is mapped straight into the generic table.
    Direct,
    /// f64, no tables: the exact line integral (the float reference).
    Reference,
}

impl Method {
    /// The name the command line and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            Method::Robust => "robust",
            Method::Paper => "paper",
            Method::Direct => "direct",
            Method::Reference => "reference",
        }
    }
}

/// What `--quality DB` aims at (`--quality-reference`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QualityReference {
    /// The f64 renderer with the same sheets: the table configuration's error, predicted from
    /// one footprint.
    Sheets,
    /// The continuous volume-rendering integral, measured on a pilot of sampled rays.
    Continuous,
    /// The built-in scene only: the continuous integral of its analytic field sampled finer.
    Field,
}

impl QualityReference {
    /// The name `--quality-reference` and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            QualityReference::Sheets => "sheets",
            QualityReference::Continuous => "continuous",
            QualityReference::Field => "field",
        }
    }
}

/// How the float or fixed sheets accumulate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// f32 accumulator and image.
    Float,
    /// Integer table, accumulator and image (bit-exact on every target).
    Fixed,
}

/// What draws the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// The paper's sheets along the grid axis most parallel to the image.
    Sheets(Precision),
    /// Image-aligned slabs `thickness` smallest grid spacings thick (float).
    Slabs {
        /// Voxel spacings along the ray.
        thickness: f32,
    },
    /// Post-classified image-aligned slabs `thickness` smallest grid spacings thick (float):
    /// values reconstructed, then classified per pixel (`--classification post`).
    Post {
        /// Voxel spacings along the ray.
        thickness: f32,
        /// The values' subsampling (`--value-subsample`).
        values: Supersample,
        /// Composited, or projected (`--blend`).
        blend: footprint::render::Blend,
        /// How the values are reconstructed (`--reconstruction`).
        reconstruction: crate::reference::continuous::Reconstruction,
    },
    /// Sheets on a grid refined wherever samples differ by more than `threshold` (float, robust
    /// method, orthographic, volume in memory); `sheets` also refines across sheets.
    Refined {
        /// The refinement threshold (`--refine`).
        threshold: f32,
        /// `--refine-sheets`.
        sheets: bool,
    },
    /// The f64 sheet reference: exact footprints, no tables (`--method reference`).
    Reference,
}

/// How footprints are sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Footprints {
    /// A view table per frame, built from the generic table (`robust`, `paper`).
    ViewTable,
    /// The generic table sampled per pixel through the footprint's mapping (`direct`).
    Direct,
}

/// The tables a frame samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Generic and view table side N (N × N).
    pub size: usize,
    /// Lookup when building the view table and when sampling.
    pub lookup: Lookup,
    /// View table or direct sampling.
    pub footprints: Footprints,
    /// A generic table loaded from this file (`--table-file`) instead of built.
    pub file: Option<PathBuf>,
}

impl Table {
    /// The generic table for `kernel`: loaded from [`Table::file`] (which must be for `kernel`
    /// and of side N) or built.
    pub fn generic<const N: usize>(
        &self,
        kernel: &footprint::Kernel,
    ) -> Result<Box<footprint::GenericTable<N>>, CliError> {
        crate::io::table::generic_for::<N>(self.file.as_deref(), kernel)
    }
}

/// One frame's render, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// What draws the frame.
    pub end: End,
    /// The tables sheets sample (the slab section table is fixed).
    pub table: Table,
    /// Sub-pixel phases of the stencils (0: walk the table).
    pub phases: usize,
    /// Slab depth phases (`--depth-phases`): each voxel's depth snapped to one of these per slab
    /// and its sections splatted through section stencils; 0: cut per pixel.
    pub depth_phases: usize,
    /// How sheets (float, or the fixed path's integer stencils) read the stencils at a voxel's
    /// phase (`--phase-lookup`); `None` (`auto`): blended, unless the default plan's pilot chose
    /// the nearest (`pilot::choose_slicing`; the fixed path has no pilot, so it blends).
    pub phase_lookup: Option<footprint::stencil::PhaseLookup>,
    /// Threads (bands of image rows), at least one.
    pub threads: usize,
    /// The subsampling decorator (`--subsample`): `Fixed(1)` off, `Fixed(s)` at 1/s of the size,
    /// `Auto` where the footprints allow it.
    pub subsample: Supersample,
    /// Occlusion culling's ε (`--cull`; sheets and slabs, front to back, orthographic), or none.
    pub cull: Option<f32>,
    /// `--quality DB`: the table, level and slicing are chosen by measured error
    /// (`pipeline::quality::choose::apply_quality` returns the plan it chose, with this `None`).
    pub quality: Option<Quality>,
    /// `--slicing auto` (the default) where the flags leave the choice open: the PSNR, dB, the
    /// frame must reach against the continuous model for object slicing to be kept
    /// ([`DEFAULT_TARGET_DB`]); the pipeline measures it on a pilot and returns the plan it chose,
    /// with this `None` (`pipeline::quality::choose::apply_quality`). `None`: `end` as it is.
    pub auto_slicing: Option<f64>,
    /// The level of detail (`--lod`): `Auto` is the spacing rule's level, validated on the level
    /// pilot where the volume can be read again (`pipeline::entry::prepare`).
    pub lod: Lod,
    /// Supersampling (`--supersample`): `Auto` where footprints would be widened to the
    /// minimum radius; never with a coarser level on one frame ([`check_levels`]).
    pub supersample: Supersample,
    /// The compositing order; `None`: the source's (back to front; a pipe's file order).
    pub order: Option<Order>,
    /// The sort-last split (`render --bricks X,Y,Z`): X·Y·Z bricks rendered on their own and
    /// composited front to back (`crate::distributed::render_split`); `None`: one frame, or
    /// under `mpirun -np N` a balanced split into N.
    pub bricks: Option<[usize; 3]>,
    /// `--subsample` left unset where the default plan's pilot runs (`auto_slicing`): the pilot
    /// tries each candidate subsampled (`Supersample::Auto`) before it is tried at full size, and
    /// keeps the first that reaches the target (`pipeline::quality::pilot::choose_slicing`).
    pub auto_subsample: bool,
}

impl Default for Plan {
    /// The plan `footprint render` resolves with no flags: float sheets through a 129² view
    /// table (bilinear, robust), the default phases, the default plan's pilot choosing the slicing
    /// ([`DEFAULT_TARGET_DB`]) and trying subsampling, `--lod auto`, `--supersample auto`, no
    /// culling, every core (`tests/door.rs` checks it against the command line's).
    fn default() -> Plan {
        Plan {
            end: End::Sheets(Precision::Float),
            table: Table {
                size: 129,
                lookup: Lookup::Bilinear,
                footprints: Footprints::ViewTable,
                file: None,
            },
            phases: footprint::stencil::DEFAULT_PHASES,
            depth_phases: 0,
            phase_lookup: None,
            threads: crate::threads::count(0),
            subsample: Supersample::Fixed(1),
            cull: None,
            quality: None,
            auto_slicing: Some(DEFAULT_TARGET_DB),
            auto_subsample: true,
            lod: Lod::Auto,
            supersample: Supersample::Auto,
            order: None,
            bricks: None,
        }
    }
}

/// `--quality DB --quality-reference R`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// The target PSNR, dB.
    pub target_db: f64,
    /// What it is measured against.
    pub reference: QualityReference,
}

impl Plan {
    /// The same plan accumulating in `precision` (what `verify --accum fixed` compares against);
    /// plans that do not draw sheets are unchanged.
    pub fn with_precision(&self, precision: Precision) -> Plan {
        let mut p = self.clone();
        if let End::Sheets(_) = p.end {
            p.end = End::Sheets(precision);
        }
        p
    }

    /// The precision the sheets accumulate in (float for every end point but fixed sheets).
    pub fn precision(&self) -> Precision {
        match self.end {
            End::Sheets(p) => p,
            _ => Precision::Float,
        }
    }

    /// The name `--classification` and the JSON use: `post` for post-classified slabs.
    pub fn classification(&self) -> &'static str {
        match self.end {
            End::Post { .. } => "post",
            _ => "pre",
        }
    }

    /// How the frame reconstructs between voxels (`--reconstruction`): post-classified slabs
    /// as asked; every pre-classified end with the kernel.
    pub fn reconstruction(&self) -> crate::reference::continuous::Reconstruction {
        match self.end {
            End::Post { reconstruction, .. } => reconstruction,
            _ => crate::reference::continuous::Reconstruction::Kernel,
        }
    }

    /// The same plan at full resolution with nothing left to choose about the level: level 0,
    /// no `--quality` (what `--lod auto`'s pilot, the field reference and `verify`'s
    /// full-resolution figure compare against).
    pub fn at_level_0(&self) -> Plan {
        Plan {
            lod: Lod::Level(0),
            quality: None,
            ..self.clone()
        }
    }

    /// The resolution chain a frame's set-up reads.
    pub fn resolution(&self) -> Resolution {
        Resolution {
            lod: self.lod,
            supersample: self.supersample,
            refine: self.refines(),
            quality: self.quality.is_some(),
        }
    }

    /// Whether the end refines the grid (`--refine`).
    pub fn refines(&self) -> bool {
        matches!(self.end, End::Refined { .. })
    }

    /// The name `--slicing` and the JSON use: `image` for slabs, `object` otherwise.
    pub fn slicing(&self) -> &'static str {
        match self.end {
            End::Slabs { .. } | End::Post { .. } => "image",
            _ => "object",
        }
    }
}

/// Why `--subsample` is refused with a perspective view: here from the flags, and in
/// `pipeline::stages::subsample::factor` for a frame built in code.
pub const SUBSAMPLE_NOT_PERSPECTIVE: &str =
    "orthographic views only (a perspective view's footprints vary per voxel)";

/// Why `--subsample` is refused at a coarser level of detail (the flags' `--lod N` here, `auto`'s
/// choice in `pipeline::stages::subsample::factor`).
pub const SUBSAMPLE_NOT_AT_A_LEVEL: &str =
    "the volume renders at a coarser level of detail (--lod); give --lod 0 or auto";

/// `--quality` with `--lod N` (N ≥ 1) of a streamed volume: refused.
pub fn quality_level_of_stream(n: u32) -> CliError {
    CliError::input(format!(
        "--quality measures level {n}'s error against full resolution, which a streamed volume \
         (read once) cannot give: load it (a volume argument instead of --stream) or drop --lod \
         {n} (level 0)"
    ))
}

/// The rules between the resolution decorators that the scene and plan decide before any
/// frame: an explicit level of detail (`--lod N`, N ≥ 1) is refused with a perspective view, with
/// `--refine` (which refines full resolution) and with `--supersample K` (K ≥ 2: both would act
/// on one frame). The command line's resolution applies them to the flags; the pipeline's
/// `setup_frame` to every scene and plan, including those built in code.
pub fn check_levels(scene: &Scene, res: &Resolution) -> Result<(), CliError> {
    let Lod::Level(n @ 1..) = res.lod else {
        return Ok(());
    };
    if scene.perspective.is_some() {
        return Err(no_level_in_perspective(n));
    }
    if res.refine {
        return Err(CliError::input(format!(
            "--refine adds samples to full resolution; --lod {n} removes them: give --lod 0 or \
             auto"
        )));
    }
    if let Supersample::Fixed(k @ 2..) = res.supersample {
        return Err(CliError::input(format!(
            "--lod {n} and --supersample {k} would both act on one frame (a coarser level seen \
             at k x the size): give one of them (--lod 0, or --supersample 1 or auto)"
        )));
    }
    Ok(())
}

/// `--lod N` (N ≥ 1) with `--perspective`: refused (levels are for orthographic views).
pub fn no_level_in_perspective(n: u32) -> CliError {
    CliError::input(format!(
        "--lod {n}: {}; use --lod 0 or auto with --perspective",
        footprint::lod::LodError::Perspective
    ))
}

/// What a render was asked for: its [`Scene`] and its [`Plan`]. The command line's
/// `RenderArgs` is one (resolved in `crate::args::resolve`), and `(Scene, Plan)`, for a
/// program that builds them itself: the pipeline's entry ([`crate::pipeline::prepare()`]) takes
/// any, so it never names the command line.
pub trait Request {
    /// What to load and how to see it (the kernel's and the mapping's rules checked).
    fn scene(&self) -> Result<Scene, CliError>;
    /// What draws the frame (its rules checked).
    fn plan(&self) -> Result<Plan, CliError>;
}

impl Request for (Scene, Plan) {
    fn scene(&self) -> Result<Scene, CliError> {
        Ok(self.0.clone())
    }
    fn plan(&self) -> Result<Plan, CliError> {
        Ok(self.1.clone())
    }
}
