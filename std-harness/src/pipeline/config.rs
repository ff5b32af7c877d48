//! One table configuration (size, lookup, method, accumulation): what `footprint chart` sweeps and
//! `--quality` chooses among, with the names the benches use.

use crate::args::{AccumArg, LookupArg, MethodArg, RenderArgs};

/// Table sizes swept.
pub const SIZES: [usize; 7] = [5, 11, 21, 33, 65, 101, 129];

/// One configuration of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    pub table: usize,
    pub lookup: LookupArg,
    pub method: MethodArg,
    pub accum: AccumArg,
}

impl Config {
    /// The configurations a frame can run: all of them orthographic; with perspective only float
    /// accumulation through the generic table (`direct`): every voxel has its own footprint, so
    /// there is no view table, and the fixed path is orthographic only.
    pub fn for_frame(frame: &footprint::frame::FrameSetup) -> Vec<Config> {
        let mut v = Self::all();
        if frame.camera().is_some() {
            v.retain(|c| c.method == MethodArg::Direct && c.accum == AccumArg::Float);
        }
        v
    }

    /// Every configuration the chart sweeps.
    pub fn all() -> Vec<Config> {
        let mut v = Vec::new();
        for table in SIZES {
            for lookup in [LookupArg::Nearest, LookupArg::Bilinear] {
                for method in [MethodArg::Robust, MethodArg::Direct] {
                    for accum in [AccumArg::Float, AccumArg::Fixed] {
                        v.push(Config {
                            table,
                            lookup,
                            method,
                            accum,
                        });
                    }
                }
            }
        }
        v
    }

    /// `n=65/bilinear/view/float/libm`, the bench naming.
    pub fn label(&self) -> String {
        format!(
            "n={}/{}/{}/{}/{}",
            self.table,
            lookup_name(self.lookup),
            method_name(self.method),
            accum_name(self.accum),
            footprint::math::BACKEND
        )
    }

    /// `args` with this configuration's table, lookup, method and accumulation.
    pub fn apply(&self, args: &RenderArgs) -> RenderArgs {
        let mut a = args.clone();
        a.footprint.table = self.table;
        a.footprint.table_file = None;
        a.footprint.lookup = self.lookup;
        a.footprint.method = self.method;
        a.accum = self.accum;
        a
    }
}

pub fn lookup_name(l: LookupArg) -> &'static str {
    match l {
        LookupArg::Nearest => "nearest",
        LookupArg::Bilinear => "bilinear",
    }
}

/// `view` for the two-stage (view-table) methods, as in the bench names.
pub fn method_name(m: MethodArg) -> &'static str {
    match m {
        MethodArg::Robust => "view",
        MethodArg::Paper => "paper",
        MethodArg::Direct => "direct",
        MethodArg::Reference => "reference",
    }
}

pub fn accum_name(a: AccumArg) -> &'static str {
    match a {
        AccumArg::Float => "float",
        AccumArg::Fixed => "fixed",
    }
}
