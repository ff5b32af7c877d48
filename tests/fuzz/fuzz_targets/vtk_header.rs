#![no_main]
//! Fuzz target: `vtk_header` must return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = footprint_harness::io::formats::vtk::parse_header(data);
});
