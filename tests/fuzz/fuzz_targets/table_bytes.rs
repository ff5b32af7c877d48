#![no_main]
//! Fuzz target: `table_bytes` must return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = footprint::GenericTable::<9>::from_bytes(data);
});
