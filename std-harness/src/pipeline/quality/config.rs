//! One table configuration (size, lookup, method, accumulation), or image-aligned slabs of one
//! thickness, and whether the grid is refined (`--refine 0`): what `footprint chart` sweeps and
//! `--quality` chooses among, with the names the benches use.

use crate::plan::{End, Footprints, Method, Plan, Precision, Supersample};
use footprint::Lookup;

/// Slab thicknesses the chart sweeps with `--slicing image`, voxel spacings.
pub const SLABS: [f32; 4] = [0.25, 0.5, 1.0, 2.0];

/// Table sizes swept.
pub const SIZES: [usize; 7] = [5, 11, 21, 33, 65, 101, 129];

/// One configuration of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    pub table: usize,
    pub lookup: Lookup,
    pub method: Method,
    pub accum: Precision,
    /// `Some(q)`: image-aligned slicing with slabs q/4 voxel spacings thick (the table fields
    /// then do not apply); `None`: the paper's object-aligned sheets.
    pub slab_quarters: Option<u16>,
    /// Object slicing with the grid refined wherever samples differ (`--refine 0`, the
    /// paper's adaptive re-sampling; float, robust method, orthographic only). Only the pilot
    /// against `--quality-reference field` ([`super::pilot`]) tries it.
    pub refine: bool,
    /// Object slicing with the stencils read at the nearest phase (`--phase-lookup nearest`);
    /// only the default plan's pilot tries it ([`super::pilot::choose_slicing`]).
    pub nearest_phase: bool,
    /// Rendered at 1/s of the size and resampled, s as `--subsample auto` picks it for the frame;
    /// only the default plan's pilot tries it, where `--subsample` is unset and s > 1
    /// ([`super::pilot::choose_slicing`]).
    pub subsample: bool,
}

impl Config {
    /// The configurations a frame can run: all of them orthographic; with perspective only float
    /// accumulation through the generic table (`direct`): every voxel has its own footprint, so
    /// there is no view table, and the fixed path is orthographic only.
    pub fn for_frame(frame: &footprint::frame::FrameSetup) -> Vec<Config> {
        let mut v = Self::all();
        if frame.camera().is_some() {
            v.retain(|c| c.method == Method::Direct && c.accum == Precision::Float);
        }
        v
    }

    /// Every configuration the chart sweeps.
    pub fn all() -> Vec<Config> {
        let mut v = Vec::new();
        for table in SIZES {
            for lookup in [Lookup::Nearest, Lookup::Bilinear] {
                for method in [Method::Robust, Method::Direct] {
                    for accum in [Precision::Float, Precision::Fixed] {
                        v.push(Config {
                            table,
                            lookup,
                            method,
                            accum,
                            slab_quarters: None,
                            refine: false,
                            nearest_phase: false,
                            subsample: false,
                        });
                    }
                }
            }
        }
        v
    }

    /// Image-aligned slicing at each of [`SLABS`] that `frame` and `kernel` can run (none for a
    /// perspective frame or a footprint-model kernel; none thinner than a kernel's depth allows,
    /// `footprint::render::slabs::MAX_RING`).
    pub fn slabs(frame: &footprint::frame::FrameSetup, kernel: &footprint::Kernel) -> Vec<Config> {
        SLABS
            .iter()
            .filter(|&&t| footprint::render::SlabSetup::new(frame, kernel, t).is_ok())
            .map(|&t| Config {
                table: 0,
                lookup: Lookup::Bilinear,
                method: Method::Direct,
                accum: Precision::Float,
                slab_quarters: Some((t * 4.0) as u16),
                refine: false,
                nearest_phase: false,
                subsample: false,
            })
            .collect()
    }

    /// The slab thickness (voxel spacings) of an image-slicing configuration.
    pub fn slab(&self) -> Option<f32> {
        self.slab_quarters.map(|q| f32::from(q) / 4.0)
    }

    /// `n=65/bilinear/view/float/libm`, the bench naming; `image/slab=0.5/float/libm` for slabs;
    /// `n=65/bilinear/view/float/libm/refine=0` refined, `…/phase=nearest` read at the nearest
    /// phase, `…/subsample=auto` subsampled.
    pub fn label(&self) -> String {
        let sub = if self.subsample {
            "/subsample=auto"
        } else {
            ""
        };
        if let Some(t) = self.slab() {
            return format!("image/slab={t}/float/{}{sub}", footprint::math::BACKEND);
        }
        format!(
            "n={}/{}/{}/{}/{}{}{}{sub}",
            self.table,
            lookup_name(self.lookup),
            method_name(self.method),
            accum_name(self.accum),
            footprint::math::BACKEND,
            if self.refine { "/refine=0" } else { "" },
            if self.nearest_phase {
                "/phase=nearest"
            } else {
                ""
            }
        )
    }

    /// This object-slicing configuration refined (`--refine 0`): float accumulation through the
    /// robust method's view table, as refinement needs, with the same table size and lookup.
    pub fn refined(&self) -> Config {
        Config {
            method: Method::Robust,
            accum: Precision::Float,
            slab_quarters: None,
            refine: true,
            nearest_phase: false,
            ..*self
        }
    }
}

impl Config {
    /// The configuration `plan` renders with as object slicing in float: its table, lookup and
    /// footprint method (`direct`, or `robust` through the view table), unrefined.
    pub fn of_plan(plan: &Plan) -> Config {
        Config {
            table: plan.table.size,
            lookup: plan.table.lookup,
            method: match plan.table.footprints {
                Footprints::Direct => Method::Direct,
                Footprints::ViewTable => Method::Robust,
            },
            accum: Precision::Float,
            slab_quarters: None,
            refine: false,
            nearest_phase: plan.phase_lookup == Some(footprint::stencil::PhaseLookup::Nearest),
            subsample: false,
        }
    }

    /// This configuration subsampled ([`Config::subsample`]).
    pub fn subsampled(&self) -> Config {
        Config {
            subsample: true,
            ..*self
        }
    }

    /// This configuration read at the nearest phase ([`Config::nearest_phase`]).
    pub fn nearest(&self) -> Config {
        Config {
            nearest_phase: true,
            ..*self
        }
    }

    /// `base` with this configuration's table, lookup, method, accumulation and slicing, and
    /// refined at threshold 0 if it refines (`base`'s own refinement is kept otherwise), read at
    /// the nearest phase if it is (`base`'s phase lookup otherwise): the plan `--quality` and
    /// `chart` render, derived, not rewritten from flags.
    pub fn plan(&self, base: &Plan) -> Plan {
        let mut p = base.clone();
        p.table.size = self.table;
        p.table.file = None;
        p.table.lookup = self.lookup;
        p.table.footprints = match self.method {
            Method::Direct => Footprints::Direct,
            _ => Footprints::ViewTable,
        };
        let precision = self.accum;
        if self.nearest_phase {
            p.phase_lookup = Some(footprint::stencil::PhaseLookup::Nearest);
        }
        if self.subsample {
            p.subsample = Supersample::Auto;
        }
        p.end = match (self.slab(), self.refine, base.end) {
            (_, true, _) => End::Refined {
                threshold: 0.0,
                sheets: false,
            },
            (Some(thickness), false, _) => End::Slabs { thickness },
            (None, false, End::Refined { threshold, sheets }) => End::Refined { threshold, sheets },
            (None, false, _) => End::Sheets(precision),
        };
        if !p.reads_phase_stencils() {
            p.phase_lookup = None;
        }
        p
    }
}

pub fn lookup_name(l: Lookup) -> &'static str {
    match l {
        Lookup::Nearest => "nearest",
        Lookup::Bilinear => "bilinear",
    }
}

/// `view` for the two-stage (view-table) methods, as in the bench names.
pub fn method_name(m: Method) -> &'static str {
    match m {
        Method::Robust => "view",
        Method::Paper => "paper",
        Method::Direct => "direct",
        Method::Reference => "reference",
    }
}

pub fn accum_name(a: Precision) -> &'static str {
    match a {
        Precision::Float => "float",
        Precision::Fixed => "fixed",
    }
}
