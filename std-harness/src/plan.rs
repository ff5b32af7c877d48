//! The render plan (issue 41): what draws a frame, resolved once from the command line.
//!
//! [`plan`] turns `render`'s flags into a typed [`Plan`] and holds every compatibility rule that
//! the flags alone decide, before anything is loaded: between end points, precision and model,
//! with a streamed volume, and between the resolution decorators ([`check_levels`], which the
//! pipeline also applies to [`Inputs`] built in code). The rules that need the volume or the
//! frame (a subsampling factor too large for the footprints, a supersampling the minimum radius
//! asks for, a view a pipe cannot feed) stay where those are known. The pipeline renders `(&Prepared, &Plan)` ([`crate::pipeline::render_frame`]); `verify`,
//! `bench`, `chart` and `--quality` build or derive plans ([`Plan::with_precision`],
//! [`crate::pipeline::quality::config::Config::plan`]) instead of rewriting flags, so `verify` renders the
//! plan `render` would, defaults included.
//!
//! ```text
//! Plan { end, table, phases, threads, subsample }
//! end:        Sheets(Float | Fixed)   the paper's sheets (object slicing)
//!             Slabs { thickness }     image-aligned slabs (float)
//!             Refined { threshold }   sheets on a refined grid (float, robust, orthographic)
//!             Reference               the f64 sheet reference
//! subsample:  a decorator of Sheets and Slabs: render at 1/s of the size and resample
//! ```
//!
//! Levels of detail and supersampling are the other decorators; they are decided with the frame
//! and never act on one frame together (`pipeline::stages::prepare::setup_frame`).

use crate::args::{
    AccumArg, Background, ClassificationArg, FootprintArgs, GammaArg, Lod, LookupArg, MethodArg,
    OrderArg, QualityReferenceArg, RenderArgs, SlicingArg, Supersample,
};
use crate::CliError;
use footprint::render::Absorption;
use footprint::Lookup;
use std::path::PathBuf;

mod auto;
mod phase;
mod post;
pub use auto::DEFAULT_TARGET_DB;
use phase::phase_lookup_rules;
use post::{no_post_flags, post_plan};

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
    /// `--subsample` left unset where the default plan's pilot runs (`auto_slicing`): the pilot
    /// tries each candidate subsampled (`Supersample::Auto`) before it is tried at full size, and
    /// keeps the first that reaches the target (`pipeline::quality::pilot::choose_slicing`).
    pub auto_subsample: bool,
}

/// `--quality DB --quality-reference R`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// The target PSNR, dB.
    pub target_db: f64,
    /// What it is measured against.
    pub reference: QualityReferenceArg,
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

    /// The name `--slicing` and the JSON use: `image` for slabs, `object` otherwise.
    pub fn slicing(&self) -> &'static str {
        match self.end {
            End::Slabs { .. } | End::Post { .. } => "image",
            _ => "object",
        }
    }
}

/// `args`' plan, with every rule the flags alone decide (see the module docs).
pub fn plan(args: &RenderArgs) -> Result<Plan, CliError> {
    let fa = &args.footprint;
    let precision = match args.accum {
        AccumArg::Float => Precision::Float,
        AccumArg::Fixed => Precision::Fixed,
    };
    if args.classification == ClassificationArg::Post {
        return post_plan(args, precision);
    }
    no_post_flags(args)?;
    let slicing = match args.slicing {
        Some(SlicingArg::Image) => SlicingArg::Image,
        _ => SlicingArg::Object,
    };
    let end = match (fa.method, args.refine, slicing) {
        (MethodArg::Reference, _, _) => End::Reference,
        (_, Some(threshold), _) => End::Refined {
            threshold,
            sheets: args.refine_sheets,
        },
        (_, None, SlicingArg::Image) => End::Slabs {
            thickness: args.slab,
        },
        (_, None, _) => End::Sheets(precision),
    };
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    match end {
        End::Refined { .. } if precision == Precision::Fixed => {
            return refuse("--refine", "float accumulation only (drop --accum fixed)")
        }
        End::Refined { .. } if slicing == SlicingArg::Image => {
            return refuse("--refine", "the paper's sheets only (drop --slicing image)")
        }
        End::Refined { .. } if args.perspective.is_some() => {
            return refuse("--refine", "orthographic views only (drop --perspective)")
        }
        End::Refined { .. } if fa.method != MethodArg::Robust => {
            return refuse(
                "--refine",
                "the rate tables are view tables built by the robust method (drop --method)",
            )
        }
        End::Slabs { .. } if precision == Precision::Fixed => {
            return refuse(
                "--slicing image",
                "there is no fixed-point slab path (each slab is composited with an exponential \
                 per pixel): use --accum float or --slicing object",
            )
        }
        _ => {}
    }
    flag_rules(&end, args)?;
    check_levels(&Inputs::from(args))?;
    let extinction = Absorption::from(args.absorption) == Absorption::Extinction;
    if extinction && matches!(end, End::Sheets(_) | End::Refined { .. }) {
        // (Perspective sheets place each voxel's optical depth along its own ray: `PerVoxel`.)
        if precision == Precision::Fixed {
            return refuse(
                "--absorption extinction",
                "--accum fixed composites the opacity model only: use --accum float (or \
                 --absorption opacity)",
            );
        }
    }
    subsample_rules(args)?;
    let auto_slicing = auto::slicing_target(&end, args);
    Ok(Plan {
        end,
        table: Table {
            size: fa.table,
            lookup: Lookup::from(fa.lookup),
            footprints: match fa.method {
                MethodArg::Direct => Footprints::Direct,
                _ => Footprints::ViewTable,
            },
            file: fa.table_file.clone(),
        },
        phases: args.phases,
        phase_lookup: args.phase_lookup.fixed(),
        threads: args.thread_count(),
        subsample: args.subsample.unwrap_or(Supersample::Fixed(1)),
        cull: args.cull.0,
        quality: args.quality.map(|target_db| Quality {
            target_db,
            reference: args.quality_reference,
        }),
        auto_slicing,
        auto_subsample: args.subsample.is_none() && auto_slicing.is_some(),
    })
}

/// The rules `--subsample` adds: not with `--quality` (which chooses at the output size), an
/// explicit factor not with `--refine`, a perspective view, supersampling or a coarser level.
fn subsample_rules(args: &RenderArgs) -> Result<(), CliError> {
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    let factor = match args.subsample {
        None | Some(Supersample::Fixed(1)) => None,
        Some(Supersample::Fixed(s)) => Some(s.to_string()),
        Some(Supersample::Auto) => Some("auto".to_string()),
    };
    let Some(s) = factor else {
        return Ok(());
    };
    if args.quality.is_some() {
        return refuse(
            &format!("--subsample {s}"),
            "--quality chooses the method from measured errors at the output size; drop one",
        );
    }
    if args.refine.is_some() && s != "auto" {
        return refuse(
            &format!("--subsample {s}"),
            "--refine adds samples for magnified volumes; subsampling removes pixels: drop one",
        );
    }
    // An explicit factor where the flags already rule subsampling out (`auto` then means
    // 1; the frame decides the rest: `pipeline::stages::subsample::factor`).
    let blocked = if s == "auto" {
        None
    } else if args.perspective.is_some() {
        Some(SUBSAMPLE_NOT_PERSPECTIVE)
    } else if matches!(args.supersample, Supersample::Fixed(2..)) {
        Some("the frame is supersampled (--supersample): give one of them")
    } else if matches!(args.lod, Lod::Level(1..)) {
        Some(SUBSAMPLE_NOT_AT_A_LEVEL)
    } else {
        None
    };
    if let Some(why) = blocked {
        return refuse(&format!("--subsample {s}"), why);
    }
    Ok(())
}

impl From<Lookup> for LookupArg {
    fn from(l: Lookup) -> Self {
        match l {
            Lookup::Nearest => LookupArg::Nearest,
            Lookup::Bilinear => LookupArg::Bilinear,
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

/// The rules a streamed volume and `--cull` add to `end`.
fn flag_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    phase_lookup_rules(end, args)?;
    if args.stream.is_some() {
        streamed_rules(end, args)?;
    }
    match args.cull.0 {
        Some(eps) => cull_rules(eps, end, args),
        None => Ok(()),
    }
}

/// `flag` refused for reason `why`, if there is one.
fn refused_if(flag: &str, why: Option<&str>) -> Result<(), CliError> {
    match why {
        Some(why) => Err(CliError::input(format!("{flag}: {why}"))),
        None => Ok(()),
    }
}

/// The rules `--cull EPS` adds: sheets or pre-classified slabs, front to back, orthographic, and
/// not with `--quality` (which chooses the method itself).
fn cull_rules(eps: f32, end: &End, args: &RenderArgs) -> Result<(), CliError> {
    let why = if !matches!(end, End::Sheets(_) | End::Slabs { .. }) {
        Some("the paper's sheets and pre-classified slabs only: drop --classification post, --refine or --method reference")
    } else if args.perspective.is_some() {
        Some("orthographic views only (a perspective view's footprints vary per voxel)")
    } else if args.order == Some(OrderArg::BackToFront) {
        Some("culling needs front-to-back compositing: drop --order back-to-front")
    } else if args.quality.is_some() {
        Some("--quality chooses the method from measured errors: drop one")
    } else {
        None
    };
    refused_if(&format!("--cull {eps}"), why)
}

/// The rules a streamed volume (`--stream`: read once, a few sheets at a time) adds to `end`.
fn streamed_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    match end {
        End::Refined { .. } => refuse("--refine", "the volume must be in memory (drop --stream)"),
        End::Slabs { .. } => refuse(
            "--slicing image",
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded) or use --slicing object",
        ),
        _ => match (args.quality, args.lod) {
            (Some(_), Lod::Level(n @ 1..)) => Err(quality_level_of_stream(n)),
            _ => Ok(()),
        },
    }
}

/// `--quality` with `--lod N` (N ≥ 1) of a streamed volume: refused.
pub fn quality_level_of_stream(n: u32) -> CliError {
    CliError::input(format!(
        "--quality measures level {n}'s error against full resolution, which a streamed volume \
         (read once) cannot give: load it (a volume argument instead of --stream) or drop --lod \
         {n} (level 0)"
    ))
}

/// The rules between the resolution decorators that the inputs decide before any frame: an
/// explicit level of detail (`--lod N`, N ≥ 1) is refused with a perspective view, with
/// `--refine` (which refines full resolution) and with `--supersample K` (K ≥ 2: both would act
/// on one frame). [`plan`] applies them to the flags; the pipeline's `setup_frame` to every
/// [`Inputs`], including those built in code.
pub fn check_levels(inputs: &Inputs) -> Result<(), CliError> {
    let Lod::Level(n @ 1..) = inputs.lod else {
        return Ok(());
    };
    if inputs.perspective.is_some() {
        return Err(no_level_in_perspective(n));
    }
    if inputs.refine {
        return Err(CliError::input(format!(
            "--refine adds samples to full resolution; --lod {n} removes them: give --lod 0 or \
             auto"
        )));
    }
    if let Supersample::Fixed(k @ 2..) = inputs.supersample {
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

/// What a render loads and how it sees it, resolved from the command line: the volume and its
/// layout, classification, camera, picture, kernel and the resolution decorators decided with
/// the frame (levels, supersampling). The pipeline prepares from these ([`crate::pipeline::prepare()`])
/// and never reads the command-line struct; what draws the frame is the [`Plan`].
#[derive(Clone, Debug)]
pub struct Inputs {
    /// A volume already in memory (set by a program, such as the Python package).
    pub memory: Option<crate::io::stream::InMemory>,
    /// What `--stream -` reads instead of standard input.
    pub stdin: Option<crate::io::stream::Pipe>,
    /// The volume file; `None`: the built-in scene.
    pub volume: Option<PathBuf>,
    /// `--stream FILE|-`.
    pub stream: Option<PathBuf>,
    /// Raw layout: `--dims`, `--type`, `--endian`, `--spacing`; `--array`.
    pub dims: Option<[usize; 3]>,
    pub sample_type: Option<String>,
    pub endian: String,
    pub spacing: [f32; 3],
    pub array: Option<String>,
    /// The built-in scene's grid, and its finer field's (`--reference field`).
    pub scene_size: usize,
    pub field_size: usize,
    /// Output size, pixels (width, height).
    pub size: (usize, usize),
    /// Camera: VTK's azimuth, elevation, roll (degrees), zoom, an explicit matrix, perspective.
    pub view: [f32; 3],
    pub zoom: f32,
    pub view_matrix: Option<[f32; 9]>,
    pub perspective: Option<f32>,
    pub eye_distance: Option<f32>,
    /// Classification: `--tf`, `--window`, `--shading`.
    pub tf: Option<String>,
    pub window: Option<[f64; 2]>,
    pub shading: String,
    /// Picture: background, gamma, PNG depth.
    pub background: Background,
    pub gamma: GammaArg,
    pub depth: u8,
    /// Kernel and footprint options (`--kernel`, `--min-radius`, `--method paper`'s mapping).
    pub footprint: FootprintArgs,
    /// The continuous model both slicings composite.
    pub absorption: Absorption,
    /// Compositing order; `None`: the default for the source.
    pub order: Option<OrderArg>,
    /// Decorators decided with the frame: supersampling and level of detail.
    pub supersample: Supersample,
    pub lod: Lod,
    /// Whether the frame must stay at full resolution: `--refine` (it refines level 0) or
    /// `--quality` (it measures the levels itself).
    pub refine: bool,
    pub quality: bool,
}

impl From<&RenderArgs> for Inputs {
    fn from(a: &RenderArgs) -> Self {
        Inputs {
            memory: a.memory.clone(),
            stdin: a.stdin.clone(),
            volume: a.volume.clone(),
            stream: a.stream.clone(),
            dims: a.dims,
            sample_type: a.sample_type.clone(),
            endian: a.endian.clone(),
            spacing: a.spacing,
            array: a.array.clone(),
            scene_size: a.scene_size,
            field_size: a.field_size,
            size: a.size,
            view: a.view,
            zoom: a.zoom,
            view_matrix: a.view_matrix,
            perspective: a.perspective,
            eye_distance: a.eye_distance,
            tf: a.tf.clone(),
            window: a.window,
            shading: a.shading.clone(),
            background: a.background.clone(),
            gamma: a.gamma,
            depth: a.depth,
            footprint: a.footprint.clone(),
            absorption: a.absorption.into(),
            // Post-classification composites front to back unless told: opaque pixels then take
            // nothing more (exact), where back to front must classify every slab.
            // Culling needs what is in front first.
            order: match (a.classification, a.order) {
                (ClassificationArg::Post, None) => Some(crate::args::OrderArg::FrontToBack),
                (_, None) if a.cull.0.is_some() => Some(crate::args::OrderArg::FrontToBack),
                (_, order) => order,
            },
            supersample: a.supersample,
            // Post-classification reconstructs the values at full resolution (a coarser level
            // carries pre-classified colours): `auto` means level 0 there.
            lod: match (a.classification, a.lod) {
                (ClassificationArg::Post, Lod::Auto) => Lod::Level(0),
                (_, lod) => lod,
            },
            refine: a.refine.is_some(),
            quality: a.quality.is_some(),
        }
    }
}

/// `base` turned `degrees` of azimuth further about the volume's vertical axis: `--view`'s
/// azimuth plus `degrees`, or a `--view-matrix` V as V · Ry(degrees) (the same turn). What
/// `render --orbit` and `bench --orbit` step by.
pub fn turned(base: &RenderArgs, degrees: f32) -> RenderArgs {
    let mut a = base.clone();
    a.view[0] += degrees;
    if let Some(m) = a.view_matrix {
        let v = glam::Mat3::from_cols_array(&m).transpose()
            * glam::Mat3::from_rotation_y(degrees.to_radians());
        a.view_matrix = Some(v.transpose().to_cols_array());
    }
    a
}

/// What a render was asked for: its [`Inputs`] and its [`Plan`]. The command line's
/// [`RenderArgs`] is one (and `(Inputs, Plan)`, for a program that builds them itself): the
/// pipeline's entry ([`crate::pipeline::prepare()`]) takes any, so it never names the command line.
pub trait Request {
    /// What to load and how to see it.
    fn inputs(&self) -> Inputs;
    /// What draws the frame (its rules checked).
    fn plan(&self) -> Result<Plan, CliError>;
}

impl Request for RenderArgs {
    fn inputs(&self) -> Inputs {
        Inputs::from(self)
    }
    fn plan(&self) -> Result<Plan, CliError> {
        plan(self)
    }
}

impl Request for (Inputs, Plan) {
    fn inputs(&self) -> Inputs {
        self.0.clone()
    }
    fn plan(&self) -> Result<Plan, CliError> {
        Ok(self.1.clone())
    }
}
