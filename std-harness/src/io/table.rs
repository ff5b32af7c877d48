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

/// The generic table for `kernel`: loaded from `file` (which must be for `kernel` and of side N)
/// or built. What `--table-file` and `--kernel` ask for, whichever command asks.
pub fn generic_for<const N: usize>(
    file: Option<&std::path::Path>,
    kernel: &Kernel,
) -> Result<Box<GenericTable<N>>, CliError> {
    let Some(path) = file else {
        return Ok(Box::new(GenericTable::<N>::build(*kernel)));
    };
    let table = load_table::<N>(path)?;
    if table.kernel() != kernel {
        return Err(CliError::input(format!(
            "{}: table is for kernel {}, but --kernel is {kernel}",
            path.display(),
            table.kernel()
        )));
    }
    Ok(table)
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
