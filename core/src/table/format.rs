//! The generic table's byte format, so the harness can save tables and the core reload them
//! without allocating.
//!
//! All integers and floats little-endian:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `FPGT` |
//! | 4 | 2 | format version (1) |
//! | 6 | 2 | length L of the kernel spec, bytes (1 ≤ L ≤ 64) |
//! | 8 | 4 | N (table size) |
//! | 12 | L | kernel spec, canonical form (ASCII) |
//! | 12+L | 4·N² | samples, f32, row-major |
//! | 12+L+4N² | 4 | CRC-32 (IEEE 802.3, as in zlib/PNG) of every preceding byte |
//!
//! Loading checks, in order: length, magic, version, N, checksum, spec, and that every sample is
//! finite; each failure is a [`TableError`].

use super::GenericTable;
use crate::kernel::{Kernel, KernelSpecError, MAX_SPEC_LEN};
use core::fmt;

/// File magic.
pub const MAGIC: [u8; 4] = *b"FPGT";
/// Format version written and accepted.
pub const FORMAT_VERSION: u16 = 1;
const HEADER: usize = 12;

/// Why a table could not be loaded or saved.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum TableError {
    /// Fewer bytes than the header says the table needs (or than a header).
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// More bytes than the table occupies.
    TrailingBytes {
        /// Bytes expected.
        expected: usize,
        /// Bytes given.
        got: usize,
    },
    /// Not a footprint table.
    BadMagic,
    /// A format version this build does not read.
    UnsupportedVersion {
        /// Version found.
        found: u16,
    },
    /// The table holds N×N samples for a different N than asked for.
    SizeMismatch {
        /// N of the receiving `GenericTable<N>`.
        expected: u32,
        /// N in the bytes.
        found: u32,
    },
    /// The checksum does not match the contents.
    ChecksumMismatch {
        /// CRC-32 stored in the bytes.
        stored: u32,
        /// CRC-32 of the contents.
        computed: u32,
    },
    /// The kernel spec is not valid UTF-8 or not a valid spec.
    BadSpec(KernelSpecError),
    /// A sample is NaN or infinite.
    NonFinite {
        /// Index of the first bad sample (row-major).
        index: usize,
    },
    /// The output buffer is too small to hold the serialised table.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Truncated { needed, got } => {
                write!(f, "table truncated: need {needed} bytes, got {got}")
            }
            Self::TrailingBytes { expected, got } => {
                write!(
                    f,
                    "table has trailing bytes: expected {expected}, got {got}"
                )
            }
            Self::BadMagic => f.write_str("not a footprint table (bad magic)"),
            Self::UnsupportedVersion { found } => {
                write!(
                    f,
                    "unsupported table format version {found} (this build reads {FORMAT_VERSION})"
                )
            }
            Self::SizeMismatch { expected, found } => {
                write!(
                    f,
                    "table is {found}x{found}, expected {expected}x{expected}"
                )
            }
            Self::ChecksumMismatch { stored, computed } => {
                write!(
                    f,
                    "table checksum mismatch: stored {stored:08x}, computed {computed:08x}"
                )
            }
            Self::BadSpec(e) => write!(f, "table kernel spec: {e}"),
            Self::NonFinite { index } => write!(f, "table sample {index} is not finite"),
            Self::BufferTooSmall { needed, got } => {
                write!(f, "output buffer too small: need {needed} bytes, got {got}")
            }
        }
    }
}

impl core::error::Error for TableError {}

/// CRC-32 (IEEE, reflected, polynomial 0xEDB88320), as used by zlib and PNG, through a 256-entry
/// table built at compile time.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = Crc32::new();
    crc.update(bytes);
    crc.finish()
}

/// The CRC-32 (IEEE, reflected) of each byte value: the eight bit-steps of a byte, done once at
/// compile time (1 KiB of flash).
const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = (c >> 1) ^ (0xEDB8_8320 & (c & 1).wrapping_neg());
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

/// [`crc32`] fed in pieces.
#[derive(Clone, Copy, Debug)]
pub struct Crc32(u32);

impl Crc32 {
    /// A fresh checksum.
    pub const fn new() -> Self {
        Crc32(!0)
    }

    /// Feeds `bytes` (a byte at a time through a 256-entry table: a load, a shift and two xors).
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 >> 8) ^ CRC_TABLE[((self.0 ^ u32::from(b)) & 0xff) as usize];
        }
    }

    /// The CRC-32 of everything fed so far.
    pub const fn finish(&self) -> u32 {
        !self.0
    }
}

impl Default for Crc32 {
    fn default() -> Self {
        Self::new()
    }
}

fn read_u16(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn read_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn read_f32(b: &[u8], at: usize) -> f32 {
    f32::from_bits(read_u32(b, at))
}

impl<const N: usize> GenericTable<N> {
    /// Serialised size in bytes for this table.
    pub fn serialized_len(&self) -> usize {
        HEADER + self.kernel.spec().len() + 4 * N * N + 4
    }

    /// Writes the table into `out`, returning the number of bytes written.
    pub fn write_bytes(&self, out: &mut [u8]) -> Result<usize, TableError> {
        let spec = self.kernel.spec();
        let len = self.serialized_len();
        if out.len() < len {
            return Err(TableError::BufferTooSmall {
                needed: len,
                got: out.len(),
            });
        }
        out[0..4].copy_from_slice(&MAGIC);
        out[4..6].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
        // Canonical specs are at most MAX_SPEC_LEN (64) bytes: they fit in u16.
        out[6..8].copy_from_slice(&(spec.len() as u16).to_le_bytes());
        out[8..12].copy_from_slice(&(N as u32).to_le_bytes());
        let mut at = HEADER;
        out[at..at + spec.len()].copy_from_slice(spec.as_bytes());
        at += spec.len();
        for v in self.as_slice() {
            out[at..at + 4].copy_from_slice(&v.to_le_bytes());
            at += 4;
        }
        let crc = crc32(&out[..at]);
        out[at..at + 4].copy_from_slice(&crc.to_le_bytes());
        Ok(at + 4)
    }

    /// Loads a table written by [`GenericTable::write_bytes`] into this one, in place (no N×N
    /// temporary). On error `self` is left unchanged.
    pub fn load_into(&mut self, bytes: &[u8]) -> Result<(), TableError> {
        let kernel = validate::<N>(bytes)?;
        let spec_len = usize::from(read_u16(bytes, 6));
        let body = HEADER + spec_len;
        for (i, v) in self.data.as_flattened_mut().iter_mut().enumerate() {
            *v = read_f32(bytes, body + 4 * i);
        }
        self.kernel = kernel;
        Ok(())
    }

    /// Loads a table written by [`GenericTable::write_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableError> {
        let mut t = Self::zeroed(Kernel::PAPER_GAUSSIAN);
        t.load_into(bytes)?;
        Ok(t)
    }
}

impl<const N: usize> GenericTable<N> {
    /// A table from a table file's bytes (as [`GenericTable::write_bytes`] and `footprint tables`
    /// write them), at compile time: `static T: GenericTable<33> =
    /// GenericTable::from_file_const(Kernel::PAPER_GAUSSIAN, include_bytes!("g.fpt"));` puts the
    /// table in flash, so a microcontroller spends no RAM on it and no time building it.
    ///
    /// Checks the length, magic, version, N, CRC and that every sample is finite; evaluated in a
    /// `const` or `static`, a bad file is a compile error. The kernel spec stored in the file is
    /// not parsed here (that is not possible in a `const fn`): `kernel` is the caller's word for
    /// it, and a test comparing the result with [`GenericTable::from_bytes`] of the same bytes
    /// checks that word. At run time, prefer [`GenericTable::from_bytes`].
    ///
    /// # Panics
    /// On any failed check (at compile time when used in a `const` or `static`).
    pub const fn from_file_const(kernel: Kernel, bytes: &[u8]) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        const fn u32_at(b: &[u8], at: usize) -> u32 {
            u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
        }
        assert!(bytes.len() >= HEADER, "table file: shorter than its header");
        assert!(
            bytes[0] == MAGIC[0]
                && bytes[1] == MAGIC[1]
                && bytes[2] == MAGIC[2]
                && bytes[3] == MAGIC[3],
            "table file: bad magic"
        );
        assert!(
            u16::from_le_bytes([bytes[4], bytes[5]]) == FORMAT_VERSION,
            "table file: unsupported version"
        );
        assert!(
            u32_at(bytes, 8) as usize == N,
            "table file: N differs from the table type's"
        );
        let body = HEADER + u16::from_le_bytes([bytes[6], bytes[7]]) as usize;
        let end = body + 4 * N * N;
        assert!(
            bytes.len() == end + 4,
            "table file: length does not match its header"
        );
        // CRC-32 of everything before the stored checksum, bitwise as in `Crc32::update`.
        let mut crc = !0u32;
        let mut i = 0;
        while i < end {
            crc ^= bytes[i] as u32;
            let mut bit = 0;
            while bit < 8 {
                crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
                bit += 1;
            }
            i += 1;
        }
        assert!(!crc == u32_at(bytes, end), "table file: checksum mismatch");
        let mut data = [[0.0f32; N]; N];
        let mut k = 0;
        while k < N * N {
            let v = f32::from_bits(u32_at(bytes, body + 4 * k));
            assert!(v.is_finite(), "table file: a sample is not finite");
            data[k / N][k % N] = v;
            k += 1;
        }
        GenericTable { kernel, data }
    }
}

/// Checks everything about `bytes` before a sample is copied; returns the parsed kernel.
fn validate<const N: usize>(bytes: &[u8]) -> Result<Kernel, TableError> {
    if bytes.len() < HEADER {
        return Err(TableError::Truncated {
            needed: HEADER,
            got: bytes.len(),
        });
    }
    if bytes[0..4] != MAGIC {
        return Err(TableError::BadMagic);
    }
    let version = read_u16(bytes, 4);
    if version != FORMAT_VERSION {
        return Err(TableError::UnsupportedVersion { found: version });
    }
    let spec_len = usize::from(read_u16(bytes, 6));
    let n = read_u32(bytes, 8);
    if n as usize != N {
        return Err(TableError::SizeMismatch {
            expected: N as u32,
            found: n,
        });
    }
    if spec_len == 0 || spec_len > MAX_SPEC_LEN {
        return Err(TableError::BadSpec(KernelSpecError::BadLength {
            len: spec_len,
        }));
    }
    let total = HEADER + spec_len + 4 * N * N + 4;
    if bytes.len() < total {
        return Err(TableError::Truncated {
            needed: total,
            got: bytes.len(),
        });
    }
    if bytes.len() > total {
        return Err(TableError::TrailingBytes {
            expected: total,
            got: bytes.len(),
        });
    }
    let stored = read_u32(bytes, total - 4);
    let computed = crc32(&bytes[..total - 4]);
    if stored != computed {
        return Err(TableError::ChecksumMismatch { stored, computed });
    }
    let spec = core::str::from_utf8(&bytes[HEADER..HEADER + spec_len])
        .map_err(|_| TableError::BadSpec(KernelSpecError::UnknownKernel))?;
    let kernel = Kernel::parse(spec).map_err(TableError::BadSpec)?;
    let body = HEADER + spec_len;
    for i in 0..N * N {
        if !read_f32(bytes, body + 4 * i).is_finite() {
            return Err(TableError::NonFinite { index: i });
        }
    }
    Ok(kernel)
}
