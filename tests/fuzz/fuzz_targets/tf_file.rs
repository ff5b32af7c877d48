#![no_main]
//! Fuzz target: the transfer-function file parser (`--tf FILE`: `t r g b a` lines) and the LUT it
//! builds. Parsed points must give a LUT of finite straight RGBA in [0, 1].
use footprint_harness::tf::{lut, parse_points, LUT_SIZE};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match parse_points(text, "fuzz.tf") {
        Ok(points) => {
            assert!(points.len() >= 2);
            let table = lut(&points);
            assert_eq!(table.len(), LUT_SIZE);
            assert!(table
                .iter()
                .all(|e| e.iter().all(|c| (0.0..=1.0).contains(c))));
        }
        Err(e) => assert!(!e.to_string().contains('\n')),
    }
});
