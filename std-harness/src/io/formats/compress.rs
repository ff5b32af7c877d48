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

/// Inflates a gzip stream (members back to back, as `gzip` concatenates them) read from `r` as it
/// inflates, to exactly `expected` bytes (more is an error, found one byte past them); the
/// compressed input is read only as far as that.
pub fn gunzip_stream(r: impl std::io::BufRead, expected: usize) -> Result<Vec<u8>, String> {
    inflate(flate2::bufread::MultiGzDecoder::new(r), expected, "gzip")
}

/// Inflates a zlib stream read from `r` as it inflates, to exactly `expected` bytes (more is an
/// error, found one byte past them).
pub fn unzlib_stream(r: impl std::io::BufRead, expected: usize) -> Result<Vec<u8>, String> {
    inflate(flate2::bufread::ZlibDecoder::new(r), expected, "zlib")
}

/// Inflates a zlib stream that must decompress to exactly `expected` bytes (more is an error,
/// found after inflating one byte past them).
pub fn unzlib(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    inflate(ZlibDecoder::new(bytes), expected, "zlib")
}

/// Decodes an LZ4 *block* (no frame: what VTK's `vtkLZ4DataCompressor` writes, one per data
/// block) into exactly `expected` bytes. The output buffer is the declared size, so a block that
/// would decode to more is an error, not an allocation; and a declared size the block cannot
/// reach (LZ4 makes at most [`LZ4_MAX_RATIO`] bytes of each byte it reads) is an error before
/// anything is allocated, so memory follows the data, not the header.
pub fn unlz4(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    let reach = bytes.len().saturating_mul(LZ4_MAX_RATIO).saturating_add(16);
    if expected > reach {
        return Err(format!(
            "LZ4 block of {} bytes cannot decode to the {expected} bytes declared",
            bytes.len()
        ));
    }
    let mut out = crate::io::try_vec::<u8>(expected, "the decoded LZ4 data")?;
    out.resize(expected, 0);
    let n = lz4_flex::block::decompress_into(bytes, &mut out)
        .map_err(|e| format!("corrupt LZ4 data: {e}"))?;
    if n != expected {
        return Err(format!(
            "LZ4 data decompress to {n} bytes, expected {expected}"
        ));
    }
    Ok(out)
}

/// The most bytes an LZ4 block can decode to per byte it holds: a match's length grows by 255
/// per extension byte (LZ4's block format), so no block expands by more.
pub const LZ4_MAX_RATIO: usize = 255;

/// A sink that keeps at most `limit` bytes and fails on the byte after: bounds what a decoder
/// writing into it can make memory hold.
struct Capped {
    out: Vec<u8>,
    limit: usize,
}

impl std::io::Write for Capped {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.out.len() + buf.len() > self.limit {
            return Err(std::io::Error::other("more data than declared"));
        }
        self.out.try_reserve(buf.len()).map_err(|_| {
            std::io::Error::new(
                std::io::ErrorKind::OutOfMemory,
                crate::io::alloc_failed(self.out.len() + buf.len(), "the decoded data"),
            )
        })?;
        self.out.extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Decodes an `.xz` stream (what VTK's `vtkLZMADataCompressor` writes: liblzma's "easy" encoder,
/// CRC-64 check) into exactly `expected` bytes. Output past `expected` stops the decoder at once.
///
/// lzma-rs 0.3.0 computes a stream footer's index size as `(backward_size + 1) << 2` in `u32`
/// (`src/decode/xz.rs:52`), which overflows for the backward size 2³² − 1 wherever the decoder
/// happens to read it. The workspace builds lzma-rs without overflow checks (`Cargo.toml`, also
/// `tests/fuzz/Cargo.toml`), so the sum wraps to 0, which no index measures, and the stream is
/// refused as corrupt in every build, as the release build always did.
pub fn unxz(bytes: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    let mut sink = Capped {
        out: Vec::new(),
        limit: expected,
    };
    let mut input = bytes;
    if let Err(e) = lzma_rs::xz_decompress(&mut input, &mut sink) {
        return Err(match e {
            lzma_rs::error::Error::IoError(e) if e.kind() == std::io::ErrorKind::OutOfMemory => {
                e.to_string()
            }
            lzma_rs::error::Error::IoError(e) if e.to_string() == "more data than declared" => {
                format!("LZMA data decompress to more than {expected} bytes")
            }
            e => format!("corrupt LZMA data: {e}"),
        });
    }
    if sink.out.len() != expected {
        return Err(format!(
            "LZMA data decompress to {} bytes, expected {expected}",
            sink.out.len()
        ));
    }
    Ok(sink.out)
}

#[cfg(test)]
mod xz_footer_tests {
    /// A fuzzed stream (found by `tests/fuzz` `compressors`) whose footer declares backward size
    /// 2³² − 1: refused with a typed error, not a panic in the decoder.
    #[test]
    fn a_footer_with_the_largest_backward_size_is_refused() {
        let mut bytes = vec![
            0xfd, b'7', b'z', b'X', b'Z', 0, 0, 4, 0xe6, 0xd6, 0xb4, 0x46,
        ];
        bytes.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0]);
        bytes.extend_from_slice(&[0xf0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x5f, 0x2d]);
        bytes.extend_from_slice(b"YZ");
        let e = super::unxz(&bytes, 16).expect_err("refused");
        assert!(e.contains("corrupt LZMA data"), "{e}");
    }

    /// The second such stream the fuzzer found (CI, stop 63): its footer is not at the end, so no
    /// "YZ" follows the backward size, which a scan of the bytes for a footer therefore missed.
    /// The decoder's sum wraps (the workspace turns lzma-rs's overflow checks off) to an index
    /// size no index has, and the stream is refused.
    #[test]
    fn a_backward_size_of_all_ones_anywhere_is_refused() {
        let data = include_bytes!(
            "../../../../tests/fuzz/corpus/compressors/xz-backward-size-all-ones-mid-stream"
        );
        // The fuzz target's framing: a selector byte (3: xz) and the declared size, then the stream.
        let expected = u32::from_le_bytes(data[1..5].try_into().unwrap()) as usize;
        let e = super::unxz(&data[5..], expected).expect_err("refused");
        assert!(e.contains("corrupt LZMA data"), "{e}");
    }
}
