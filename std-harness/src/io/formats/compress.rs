//! gzip and zlib. Output grows as the stream inflates ([`crate::io::read_growing`]) and stops one
//! byte past what the header declares, so a stream that holds less costs only what it holds, a
//! stream that holds more (a decompression bomb) is cut off after `expected + 1` bytes, and memory
//! refusing is an error, not an abort.

use flate2::read::{GzDecoder, ZlibDecoder};
use std::io::Read;

/// The message for a failed read from a decoder: memory refusing, or corrupt data.
pub fn read_error(e: std::io::Error, what: &str) -> String {
    if e.kind() == std::io::ErrorKind::OutOfMemory {
        e.to_string()
    } else {
        format!("corrupt {what} data: {e}")
    }
}

fn inflate(r: impl Read, expected: usize, what: &str) -> Result<Vec<u8>, String> {
    // One byte more than expected, to tell "too long" from "exactly right".
    let out = crate::io::read_growing(r, expected as u64 + 1, "the inflated data")
        .map_err(|e| read_error(e, what))?;
    if out.len() != expected {
        return Err(format!(
            "{what} data decompresses to {}{} bytes, expected {expected}",
            if out.len() > expected {
                "more than "
            } else {
                ""
            },
            out.len().min(expected)
        ));
    }
    Ok(out)
}

/// Inflates a gzip stream that must decompress to exactly `expected` bytes (more is an error,
/// found after inflating one byte past them).
pub fn gunzip(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    inflate(GzDecoder::new(bytes), expected, "gzip")
}

/// Inflates a zlib stream that must decompress to exactly `expected` bytes (more is an error,
/// found after inflating one byte past them).
pub fn unzlib(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    inflate(ZlibDecoder::new(bytes), expected, "zlib")
}
