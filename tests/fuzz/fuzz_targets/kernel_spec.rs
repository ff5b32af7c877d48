#![no_main]
//! Fuzz target: `kernel_spec` must return a value or an error for any input, never panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = std::str::from_utf8(data) {
        if let Ok(k) = footprint::Kernel::parse(s) {
            assert_eq!(footprint::Kernel::parse(&k.spec()), Ok(k));
        }
    }
});
