#![no_main]
//! Fuzz target: `vtr_header` (a rectilinear grid's XML, its coordinate arrays included) must
//! return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = footprint_harness::io::formats::vtr::parse_header_array(data, None);
});
