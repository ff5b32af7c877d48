//! Tables kept across the frames of one [`super::visible::FrameCache`]: the generic table a plan
//! builds, once per kernel and side, as the paper has it, instead of once per frame (0.25 ms of
//! a 512² re-render's 0.9 ms of tables on the walnut, `footprint bench --frames 8`, 2026-12-04).
//! It is what building it again would give (a function of the kernel and the side alone). A
//! generic table loaded from a file (`--table-file`) is read again every frame, as before.
//!
//! The view table and its phase stencils are not kept: the footprint they are built for differs
//! in its last bits from view to view even where it is the same disc (an orthographic orbit of
//! an isotropic grid), so a cache keyed by it never hit in the benchmark orbits; one keyed
//! looser would make a frame's bits depend on the frames before it.

use crate::plan::Table;
use crate::CliError;
use footprint::{GenericTable, Kernel};
use std::any::Any;

/// The kept tables (see the module docs).
#[derive(Default)]
pub struct TableCache {
    /// The built generic table, keyed by its side and kernel.
    generic: Option<(String, Box<dyn Any + Send + Sync>)>,
}

impl std::fmt::Debug for TableCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TableCache")
            .field("generic", &self.generic.as_ref().map(|g| &g.0))
            .finish()
    }
}

impl TableCache {
    /// `table`'s generic table of side N for `kernel`: the kept one where it was built before,
    /// else built (and kept) or loaded from its file (not kept).
    pub fn generic<const N: usize>(
        &mut self,
        table: &Table,
        kernel: &Kernel,
    ) -> Result<Box<GenericTable<N>>, CliError> {
        if table.file.is_some() {
            return table.generic::<N>(kernel);
        }
        // `Debug` gives a float's exact digits: equal keys are equal kernels.
        let key = format!("{N} {kernel:?}");
        if let Some((k, g)) = &self.generic {
            if *k == key {
                if let Some(g) = g.downcast_ref::<GenericTable<N>>() {
                    return Ok(Box::new(g.clone()));
                }
            }
        }
        let built = table.generic::<N>(kernel)?;
        self.generic = Some((key, Box::new((*built).clone())));
        Ok(built)
    }
}

#[cfg(test)]
mod tests {
    use super::TableCache;
    use crate::plan::{Footprints, Table};
    use footprint::{GenericTable, Kernel, Lookup};

    /// The kept table is the one a fresh build gives, bit for bit, for each kernel and side in
    /// turn; a table from a file is never kept.
    #[test]
    fn kept_generic_tables_are_fresh_builds() {
        let table = Table {
            size: 33,
            lookup: Lookup::Bilinear,
            footprints: Footprints::ViewTable,
            file: None,
        };
        let wide = Kernel::gaussian(2.0, 2.5).expect("a kernel");
        let mut cache = TableCache::default();
        for kernel in [Kernel::PAPER_GAUSSIAN, wide, wide, Kernel::PAPER_GAUSSIAN] {
            let got = cache.generic::<33>(&table, &kernel).expect("built");
            assert!(*got == GenericTable::<33>::build(kernel), "{kernel:?}");
            let got = cache.generic::<17>(&table, &kernel).expect("built");
            assert!(
                *got == GenericTable::<17>::build(kernel),
                "{kernel:?} at 17"
            );
        }
        let from_file = Table {
            file: Some("/nonexistent/footprint-table.bin".into()),
            ..table
        };
        assert!(cache
            .generic::<33>(&from_file, &Kernel::PAPER_GAUSSIAN)
            .is_err());
    }
}
