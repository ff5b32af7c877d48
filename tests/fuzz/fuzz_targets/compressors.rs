#![no_main]
//! Fuzz target: the decompressors' data path (gzip and zlib, from bytes and as streams; VTK's LZ4
//! blocks and xz), each asked for a declared size taken from the input. A decoder returns exactly
//! the declared bytes or a one-line error; memory follows the data, never the declared size (an
//! LZ4 block that cannot reach it is refused before allocating; the others grow as they decode),
//! which libFuzzer's RSS limit checks.
use footprint_harness::io::formats::compress;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let Some((size, bytes)) = rest.split_first_chunk::<4>() else {
        return;
    };
    // Declared sizes up to 1 GiB: far more than any input here can hold.
    let expected = u32::from_le_bytes(*size) as usize % (1 << 30);
    let decoded = match pick % 6 {
        0 => compress::gunzip(bytes, expected),
        1 => compress::unzlib(bytes, expected),
        2 => compress::unlz4(bytes, expected),
        3 => compress::unxz(bytes, expected),
        4 => compress::gunzip_stream(bytes, expected),
        _ => compress::unzlib_stream(bytes, expected),
    };
    match decoded {
        Ok(out) => assert_eq!(out.len(), expected),
        Err(e) => assert!(!e.contains('\n'), "one line: {e}"),
    }
    if pick % 6 == 2 {
        // The LZ4 bound: nothing past 255 bytes out per byte in is ever allocated.
        let reach = bytes.len() * compress::LZ4_MAX_RATIO + 16;
        assert!(expected <= reach || compress::unlz4(bytes, expected).is_err());
    }
});
