#![no_main]
//! Fuzz target: `nifti_header` must return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = footprint_harness::io::formats::nifti::parse_header(data);
});
