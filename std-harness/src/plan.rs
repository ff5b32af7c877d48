//! The render plan (issue 41): what draws a frame, resolved once from the command line.
//!
//! [`plan`] turns `render`'s flags into a typed [`Plan`] and holds every compatibility rule that
//! the flags alone decide (the rules that need the volume or the frame, such as a stream refused
//! by slabs or a subsampling factor too large for the footprints, stay where those are known, each
//! once). The pipeline renders `(&Prepared, &Plan)` ([`crate::pipeline::render_frame`]); `verify`,
//! `bench`, `chart` and `--quality` build or derive plans ([`Plan::with_precision`],
//! [`crate::pipeline::config::Config::apply`]) instead of rewriting flags, so `verify` renders the
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
//! and never act on one frame together (`pipeline::prepare::setup_frame`).

use crate::args::{AccumArg, LookupArg, MethodArg, RenderArgs, SlicingArg, Supersample};
use crate::CliError;
use footprint::render::Absorption;
use footprint::Lookup;
use std::path::PathBuf;

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
        let Some(path) = &self.file else {
            return Ok(Box::new(footprint::GenericTable::<N>::build(*kernel)));
        };
        let table = crate::io::table::load_table::<N>(path)?;
        if table.kernel() != kernel {
            return Err(CliError::input(format!(
                "{}: table is for kernel {}, but --kernel is {kernel}",
                path.display(),
                table.kernel()
            )));
        }
        Ok(table)
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
    /// Threads (bands of image rows), at least one.
    pub threads: usize,
    /// The subsampling decorator (`--subsample`): `Fixed(1)` off, `Fixed(s)` at 1/s of the size,
    /// `Auto` where the footprints allow it.
    pub subsample: Supersample,
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

    /// The name `--slicing` and the JSON use: `image` for slabs, `object` otherwise.
    pub fn slicing(&self) -> &'static str {
        match self.end {
            End::Slabs { .. } => "image",
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
    let end = match (fa.method, args.refine, args.slicing) {
        (MethodArg::Reference, _, _) => End::Reference,
        (_, Some(threshold), _) => End::Refined {
            threshold,
            sheets: args.refine_sheets,
        },
        (_, None, SlicingArg::Image) => End::Slabs {
            thickness: args.slab,
        },
        (_, None, SlicingArg::Object) => End::Sheets(precision),
    };
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    match end {
        End::Refined { .. } if precision == Precision::Fixed => {
            return refuse("--refine", "float accumulation only (drop --accum fixed)")
        }
        End::Refined { .. } if args.slicing == SlicingArg::Image => {
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
    let extinction = Absorption::from(args.absorption) == Absorption::Extinction;
    if extinction && matches!(end, End::Sheets(_) | End::Refined { .. }) {
        if precision == Precision::Fixed {
            return refuse(
                "--absorption extinction",
                "--accum fixed composites the opacity model only: use --accum float (or \
                 --absorption opacity)",
            );
        }
        if args.perspective.is_some() {
            return refuse(
                "--absorption extinction",
                "--perspective composites the opacity model only (or --absorption opacity)",
            );
        }
    }
    let factor = match args.subsample {
        Supersample::Fixed(1) => None,
        Supersample::Fixed(s) => Some(s.to_string()),
        Supersample::Auto => Some("auto".to_string()),
    };
    if let Some(s) = factor {
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
    }
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
        threads: args.thread_count(),
        subsample: args.subsample,
    })
}

impl From<Lookup> for LookupArg {
    fn from(l: Lookup) -> Self {
        match l {
            Lookup::Nearest => LookupArg::Nearest,
            Lookup::Bilinear => LookupArg::Bilinear,
        }
    }
}
