//! Table sizes are const generics in the core; the command line picks one at run time from this
//! list.

/// Table sizes (N for N×N) the harness is compiled for.
pub const TABLE_SIZES: [usize; 12] = [3, 5, 7, 9, 11, 17, 21, 33, 65, 101, 129, 257];

/// Calls `$body` with `const $n: usize` bound to the runtime value `$size`, or evaluates to
/// `Err(CliError)` for a size not in [`TABLE_SIZES`]. Only [`with_size`] uses it.
macro_rules! with_table_size {
    ($size:expr, $n:ident => $body:expr) => {
        match $size {
            3 => {
                const $n: usize = 3;
                Ok($body)
            }
            5 => {
                const $n: usize = 5;
                Ok($body)
            }
            7 => {
                const $n: usize = 7;
                Ok($body)
            }
            9 => {
                const $n: usize = 9;
                Ok($body)
            }
            11 => {
                const $n: usize = 11;
                Ok($body)
            }
            17 => {
                const $n: usize = 17;
                Ok($body)
            }
            21 => {
                const $n: usize = 21;
                Ok($body)
            }
            33 => {
                const $n: usize = 33;
                Ok($body)
            }
            65 => {
                const $n: usize = 65;
                Ok($body)
            }
            101 => {
                const $n: usize = 101;
                Ok($body)
            }
            129 => {
                const $n: usize = 129;
                Ok($body)
            }
            257 => {
                const $n: usize = 257;
                Ok($body)
            }
            other => Err($crate::CliError::input(format!(
                "table size {other} is not supported (choose one of {:?})",
                $crate::dispatch::TABLE_SIZES
            ))),
        }
    };
}

/// Code generic over the table side N: what [`with_size`] runs with the N asked for at run time.
/// A site that needs a table writes its work once, as a function generic over `N`, and a small
/// struct carrying its arguments implements this; the list of sizes is matched in one place.
pub trait TableSize {
    /// What the work returns.
    type Output;
    /// The work, with the table side `N`.
    fn run<const N: usize>(self) -> Result<Self::Output, crate::CliError>;
}

/// Runs `work` with `const N` = `size`, or refuses a size not in [`TABLE_SIZES`]: the one place
/// a runtime table size becomes a const generic.
pub fn with_size<W: TableSize>(size: usize, work: W) -> Result<W::Output, crate::CliError> {
    with_table_size!(size, N => work.run::<N>())?
}
