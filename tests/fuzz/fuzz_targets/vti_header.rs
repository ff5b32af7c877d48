#![no_main]
//! Fuzz target: `vti_header` must return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = footprint_harness::io::formats::vti::parse_header(data);
});
