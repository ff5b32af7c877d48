//! gzip and zlib, with the output capped so a corrupt or hostile stream cannot allocate more than
//! the header says the data holds.

use flate2::read::{GzDecoder, ZlibDecoder};
use std::io::Read;

fn inflate(r: impl Read, expected: usize, what: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(expected.min(1 << 28));
    // One byte more than expected, to tell "too long" from "exactly right".
    r.take(expected as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("corrupt {what} data: {e}"))?;
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

/// Inflates a gzip stream that must decompress to exactly `expected` bytes.
pub fn gunzip(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    inflate(GzDecoder::new(bytes), expected, "gzip")
}

/// Inflates a zlib stream that must decompress to exactly `expected` bytes.
pub fn unzlib(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    inflate(ZlibDecoder::new(bytes), expected, "zlib")
}

/// Inflates a gzip stream of unknown length, up to `limit` bytes (for `.nii.gz`, whose header is
/// inside the stream).
pub fn gunzip_limited(bytes: &[u8], limit: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    GzDecoder::new(bytes)
        .take(limit as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("corrupt gzip data: {e}"))?;
    if out.len() > limit {
        return Err(format!("gzip data decompresses to more than {limit} bytes"));
    }
    Ok(out)
}
