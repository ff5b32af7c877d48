//! The embedded demo scene ([`footprint_scene`]) on a Cortex-M under QEMU, every buffer `static`,
//! no heap. Renders band by band (the volume streamed once per band), prints each finished band,
//! then its figures, over semihosting, and exits with the render's status:
//!
//! ```text
//! image W H
//! row Y RRRRRRRRGGGGGGGGBBBBBBBBAAAAAAAA…   (W pixels, Q24 hex; one line per row)
//! fixed checksum 0x…      (equal to `footprint-scene-host`'s, bit for bit)
//! rgb565 crc 0x… (N pixels …)   the rows a display was sent (equal to the host's)
//! stack high-water N bytes (painted stack)
//! static RAM N bytes (.data + .bss)
//! flash N bytes (.text + .rodata + .data image)
//! ```
//!
//! The board follows the target: Cortex-M0 (`thumbv6m-none-eabi`) is the BBC micro:bit (16 KiB
//! of RAM: a 48×48 image in bands of [`BAND`] rows), anything else QEMU's MPS2 boards (64×64).
//! Build with `--features float` for the float path instead (its checksum is informational).
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicU32, Ordering::Relaxed};
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::{debug, hio, hprintln};
use footprint::composite::RowSpan;
use footprint_scene::display::{send_band, CrcDisplay};
use footprint_scene::N;

/// Image side, pixels.
#[cfg(microbit)]
const SIDE: usize = footprint_scene::SIDE_MICROBIT;
/// Image side, pixels.
#[cfg(not(microbit))]
const SIDE: usize = footprint_scene::SIDE;
/// Rows per band: the accumulator and working image hold this many rows.
#[cfg(microbit)]
const BAND: usize = 2;
/// Rows per band: the accumulator and working image hold this many rows.
#[cfg(not(microbit))]
const BAND: usize = 8;
/// Pixels in a band.
const BAND_PIXELS: usize = BAND * SIDE;

/// The word the unused stack is painted with.
const PAINT: u32 = 0xC0DE_F00D;

extern "C" {
    // From cortex-m-rt's link.x: the end of static RAM (start of the free area the stack grows
    // down into), the start of .data in RAM and its load address in flash, and its end.
    static mut __sheap: u32;
    static mut __sdata: u32;
    static mut __edata: u32;
    static __sidata: u32;
}

#[entry]
fn main() -> ! {
    let free_start = core::ptr::addr_of_mut!(__sheap) as usize;
    if let Some(mut p) = cortex_m::Peripherals::take() {
        start_clock(&mut p.SYST);
    }
    // Instructions per SysTick tick, from a loop of known length (see `instructions`).
    let calibration = {
        const SPINS: u32 = 1 << 20;
        let t0 = ticks();
        spin(SPINS);
        (2 * u64::from(SPINS), ticks() - t0)
    };
    hprintln!("image {} {}", SIDE, SIDE);
    paint_stack(free_start);
    let t0 = ticks();
    let result = render();
    let frame_ticks = ticks() - t0 - u64::from(EMIT_TICKS.load(Relaxed));
    let high_water = stack_high_water(free_start);
    let (data_start, data_end) = (
        core::ptr::addr_of_mut!(__sdata) as usize,
        core::ptr::addr_of_mut!(__edata) as usize,
    );
    let data_load = core::ptr::addr_of!(__sidata) as usize;
    let ok = match result {
        Ok((report, (display_crc, drawn))) => {
            hprintln!("{} checksum 0x{:08x}", PATH, report.checksum);
            hprintln!(
                "rgb565 crc 0x{:08x} ({} pixels through the embedded-graphics adaptor)",
                display_crc,
                drawn
            );
            hprintln!(
                "scene: {}x{} in {} bands of {} rows, {} sheets, {} voxels splatted, {} pixel updates",
                SIDE,
                SIDE,
                report.bands,
                BAND,
                report.stats.sheets,
                report.stats.voxels_splatted,
                report.stats.pixel_updates
            );
            true
        }
        Err(e) => {
            hprintln!("render failed: {}", e);
            false
        }
    };
    match instructions(frame_ticks, calibration) {
        Some(n) => hprintln!(
            "frame instructions {} (the rows sent to the display included, printing the image excluded)",
            n
        ),
        None => hprintln!("frame instructions unknown (no clock: run QEMU with -icount)"),
    }
    hprintln!("stack high-water {} bytes", high_water);
    hprintln!("static RAM {} bytes", free_start - data_start);
    hprintln!("flash {} bytes", data_load + (data_end - data_start));
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a debugger to end the session.
    loop {
        cortex_m::asm::wfi();
    }
}

#[cfg(not(feature = "float"))]
const PATH: &str = "fixed";
#[cfg(feature = "float")]
const PATH: &str = "float";

/// SysTick wraps (each 2²⁴ ticks), counted by its exception.
static WRAPS: AtomicU32 = AtomicU32::new(0);
/// Ticks spent printing the image, subtracted from the frame's.
static EMIT_TICKS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    // The only writer (thumbv6m has no atomic read-modify-write).
    WRAPS.store(WRAPS.load(Relaxed).wrapping_add(1), Relaxed);
}

/// Runs SysTick from the core clock over its full 24-bit range, interrupting at each wrap.
fn start_clock(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    // The counter reads 0 until its first reload; wait for it (bounded: a core without a running
    // SysTick just reports no clock).
    for _ in 0..10_000 {
        if SYST::get_current() != 0 {
            break;
        }
    }
}

/// SysTick ticks since [`start_clock`].
fn ticks() -> u64 {
    loop {
        let w = WRAPS.load(Relaxed);
        let down = SYST::get_current();
        // A wrap whose exception has not run yet: the count has reloaded (is high) and the
        // exception is pending.
        let pending = cortex_m::peripheral::SCB::is_pendst_pending() && down > 0x0080_0000;
        if WRAPS.load(Relaxed) == w {
            let w = u64::from(w) + u64::from(pending);
            return (w << 24) + u64::from(0x00FF_FFFF - down);
        }
    }
}

/// `n` turns of a two-instruction loop (`subs`, `bne`): 2n instructions.
#[inline(never)]
fn spin(n: u32) {
    // SAFETY: a register-only countdown; touches no memory and no stack.
    unsafe {
        core::arch::asm!("2:", "subs {0}, #1", "bne 2b", inout(reg) n => _, options(nomem, nostack));
    }
}

/// Instructions executed in `ticks`, from a calibration of (instructions, ticks). Under QEMU's
/// `-icount shift=0` the virtual clock advances 1 ns per instruction and SysTick counts that
/// clock, so this is an instruction count, deterministic from run to run. It is not a cycle
/// count: QEMU models no pipeline, wait states or multi-cycle instructions. Without `-icount`
/// the clock follows the host and the figure means little; with no clock at all, `None`.
fn instructions(ticks: u64, (cal_instructions, cal_ticks): (u64, u64)) -> Option<u64> {
    (cal_ticks > 0).then(|| (ticks * cal_instructions + cal_ticks / 2) / cal_ticks)
}

/// Prints band rows as `row Y` and hex Q24 RGBA (float images are quantised to Q24 first).
fn emit(first: usize, pixels: &[[u32; 4]]) {
    let t0 = ticks();
    print_rows(first, pixels);
    let spent = (ticks() - t0) as u32;
    EMIT_TICKS.store(EMIT_TICKS.load(Relaxed).wrapping_add(spent), Relaxed);
}

fn print_rows(first: usize, pixels: &[[u32; 4]]) {
    let Ok(mut out) = hio::hstdout() else {
        return;
    };
    for (r, row) in pixels.chunks(SIDE).enumerate() {
        // `row Y ` without core::fmt (its indirect calls would escape the stack bound).
        let mut head = *b"row 0000 ";
        let y = first + r;
        for (d, b) in head[4..8].iter_mut().enumerate() {
            *b = b'0' + ((y / 10usize.pow(3 - d as u32)) % 10) as u8;
        }
        let _ = out.write_all(&head);
        // Hex for a row's pixels a pixel at a time: 32 digits, one write each.
        for px in row {
            let mut hex = [0u8; 32];
            for (c, v) in px.iter().enumerate() {
                for d in 0..8 {
                    let nibble = (v >> (28 - 4 * d)) & 0xF;
                    hex[8 * c + d] = b"0123456789abcdef"[nibble as usize];
                }
            }
            let _ = out.write_all(&hex);
        }
        let _ = out.write_all(b"\n");
    }
}

/// The fixed-point render, from `static` buffers.
#[cfg(not(feature = "float"))]
#[inline(never)]
fn render() -> Result<(footprint_scene::Report, (u32, usize)), footprint::Error> {
    use footprint::fixed::FixedTable;
    static mut TABLE: FixedTable<N> = FixedTable::zeroed();
    static mut LUT: [[u32; 4]; 256] = [[0; 4]; 256];
    static mut ACC: [[i64; 4]; BAND_PIXELS] = [[0; 4]; BAND_PIXELS];
    static mut IMAGE: [[u32; 4]; BAND_PIXELS] = [[0; 4]; BAND_PIXELS];
    static mut ROWS: [RowSpan; BAND] = [RowSpan::EMPTY; BAND];
    // SAFETY: `render` runs once (from `main`, which never returns), with no interrupts that touch
    // these, so each `static mut` is borrowed mutably exactly once.
    let b = unsafe {
        footprint_scene::FixedBuffers {
            table: &mut *core::ptr::addr_of_mut!(TABLE),
            lut: &mut *core::ptr::addr_of_mut!(LUT),
            acc: &mut *core::ptr::addr_of_mut!(ACC),
            image: &mut *core::ptr::addr_of_mut!(IMAGE),
            rows: &mut *core::ptr::addr_of_mut!(ROWS),
        }
    };
    let mut display = CrcDisplay::new(SIDE);
    let mut row = [0u16; SIDE];
    let report = footprint_scene::render_fixed(SIDE, b, |first, px| {
        emit(first, px);
        // Whole rows of SIDE pixels into a row of SIDE: cannot fail.
        let _ = send_band(first, SIDE, px, &mut row, &mut display);
    })?;
    Ok((report, display.finish()))
}

/// The float render, from `static` buffers.
#[cfg(feature = "float")]
#[inline(never)]
fn render() -> Result<(footprint_scene::Report, (u32, usize)), footprint::Error> {
    use footprint::ViewTable;
    static mut TABLE: ViewTable<N> = ViewTable::zeroed(footprint::Footprint::EMPTY);
    static mut ACC: [[f32; 4]; BAND_PIXELS] = [[0.0; 4]; BAND_PIXELS];
    static mut IMAGE: [[f32; 4]; BAND_PIXELS] = [[0.0; 4]; BAND_PIXELS];
    static mut ROWS: [RowSpan; BAND] = [RowSpan::EMPTY; BAND];
    // SAFETY: as in the fixed `render`: one call, one mutable borrow of each.
    let b = unsafe {
        footprint_scene::FloatBuffers {
            table: &mut *core::ptr::addr_of_mut!(TABLE),
            acc: &mut *core::ptr::addr_of_mut!(ACC),
            image: &mut *core::ptr::addr_of_mut!(IMAGE),
            rows: &mut *core::ptr::addr_of_mut!(ROWS),
        }
    };
    let mut display = CrcDisplay::new(SIDE);
    let mut out = [0u16; SIDE];
    let report = footprint_scene::render_float(SIDE, b, |first, px| {
        // A row at a time, quantised to Q24 for printing and the display.
        for (r, row) in px.chunks(SIDE).enumerate() {
            let mut q = [[0u32; 4]; SIDE];
            for (o, c) in q.iter_mut().zip(row) {
                *o = footprint::fixed::quantise(*c);
            }
            emit(first + r, &q);
            let _ = send_band(first + r, SIDE, &q, &mut out, &mut display);
        }
    })?;
    Ok((report, display.finish()))
}

/// Fills the free RAM between the statics and (a margin below) the current stack pointer with
/// [`PAINT`].
#[inline(never)]
fn paint_stack(free_start: usize) {
    let sp = cortex_m::register::msp::read() as usize;
    let mut p = free_start;
    while p + 4 <= sp - 64 {
        // SAFETY: [free_start, sp − 64) is RAM no one uses yet: above the statics, below the
        // live stack.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// Bytes of stack ever used: from the stack top down to the lowest word no longer painted.
fn stack_high_water(free_start: usize) -> usize {
    extern "C" {
        static _stack_start: u32;
    }
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let mut p = free_start;
    // SAFETY: reading RAM between the statics and the stack top, all of it mapped.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    top - p
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    // Only reached without a debugger to end the session.
    loop {
        cortex_m::asm::wfi();
    }
}
