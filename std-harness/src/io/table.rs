//! Generic footprint tables on disk, in the core's byte format (`footprint tables` writes them,
//! `--table-file` reads them).

use crate::dispatch::{with_size, TableSize};
use crate::{io, CliError};
use footprint::{GenericTable, Kernel};

/// Builds a table and returns its serialised bytes.
pub fn table_bytes(kernel: &Kernel, size: usize) -> Result<Vec<u8>, CliError> {
    struct Bytes<'a>(&'a Kernel);
    impl TableSize for Bytes<'_> {
        type Output = Vec<u8>;
        fn run<const N: usize>(self) -> Result<Vec<u8>, CliError> {
            let table = Box::new(GenericTable::<N>::build(*self.0));
            let mut bytes = vec![0u8; table.serialized_len()];
            let len = table.write_bytes(&mut bytes)?;
            bytes.truncate(len);
            Ok(bytes)
        }
    }
    with_size(size, Bytes(kernel))
}

/// Loads a table file for a `GenericTable<N>`, with the path in any error.
pub fn load_table<const N: usize>(
    path: &std::path::Path,
) -> Result<Box<GenericTable<N>>, CliError> {
    let bytes = io::read_file(path)?;
    let mut table = Box::new(GenericTable::<N>::zeroed(Kernel::PAPER_GAUSSIAN));
    table
        .load_into(&bytes)
        .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    Ok(table)
}
