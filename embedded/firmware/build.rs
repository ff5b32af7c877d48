//! Puts the board's memory map where cortex-m-rt's link.x finds it as `memory.x`: the micro:bit's
//! (`memory-microbit.x`, 16 KiB RAM) for Cortex-M0 (`thumbv6m-none-eabi`), QEMU's MPS2 boards'
//! (`memory-stm32f100.x`, 8 KiB) with the `stm32f100` feature, QEMU's MPS2 boards' (`memory.x`,
//! 4 MiB) otherwise.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let stm32 = env::var_os("CARGO_FEATURE_STM32F100").is_some();
    let map = if target.starts_with("thumbv6m") {
        "memory-microbit.x"
    } else if stm32 {
        "memory-stm32f100.x"
    } else {
        "memory.x"
    };
    // `cfg(microbit)`, `cfg(stm32f100)`: the firmware's image and band sizes for the 16 KiB and
    // 8 KiB parts.
    println!("cargo::rustc-check-cfg=cfg(microbit)");
    println!("cargo::rustc-check-cfg=cfg(stm32f100)");
    if target.starts_with("thumbv6m") {
        println!("cargo:rustc-cfg=microbit");
    } else if stm32 {
        println!("cargo:rustc-cfg=stm32f100");
    }
    fs::copy(map, out.join("memory.x")).expect("the memory map is readable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=memory-microbit.x");
    println!("cargo:rerun-if-changed=memory-stm32f100.x");
}
