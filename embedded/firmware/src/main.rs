//! The embedded demo scene ([`footprint_scene`]) on a Cortex-M under QEMU, every buffer `static`,
//! no heap. Renders an orbit of [`FRAMES`] frames (the view turned
//! [`footprint_scene::ORBIT_STEP_DEG`] each frame) on the compact fixed path, band by band (the
//! volume streamed once per band), printing the first frame's bands, then each frame's figures,
//! over semihosting, and exits with the render's status:
//!
//! ```text
//! image W H
//! row Y RRRRRRRRGGGGGGGGBBBBBBBBAAAAAAAA…   (frame 0: W pixels, Q24 hex; one line per row)
//! setup instructions N                      (the view-independent set-up, once per orbit)
//! frame K checksum 0x… instructions N       (per orbit frame; checksums equal to the host's)
//! compact checksum 0x…    (frame 0; equal to `footprint-scene-host`'s, bit for bit)
//! rgb565 crc 0x… (N pixels …)   frame 0's rows as a display was sent them (equal to the host's)
//! stack high-water N bytes (painted stack)
//! static RAM N bytes (.data + .bss)
//! flash N bytes (.text + .rodata + .data image)
//! ```
//!
//! The board follows the target and features: Cortex-M0 (`thumbv6m-none-eabi`) is the BBC
//! micro:bit (16 KiB of RAM: 48×48 in bands of [`BAND`] rows); `--features stm32f100` the
//! STM32VLDISCOVERY's STM32F100 (Cortex-M3, 8 KiB of RAM: 32×32); anything else QEMU's MPS2
//! boards (64×64, one band; 128×128 with `--features side128`). Build with `--features q24` for the Q24 fixed path (one frame,
//! bit-exact with the host's `footprint render --fixed`), or `--features float` for the float
//! path (its checksum is informational).
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicU32, Ordering::Relaxed};
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::{debug, hio, hprintln};
use footprint::composite::RowSpan;
#[cfg(any(feature = "q24", feature = "float"))]
use footprint_scene::display::send_band;
#[cfg(not(any(feature = "q24", feature = "float")))]
use footprint_scene::display::send_band_q15;
use footprint_scene::display::CrcDisplay;

/// Image side, pixels.
#[cfg(microbit)]
const SIDE: usize = footprint_scene::SIDE_MICROBIT;
/// Image side, pixels.
#[cfg(stm32f100)]
const SIDE: usize = footprint_scene::SIDE_STM32;
/// Image side, pixels.
#[cfg(not(any(microbit, stm32f100, feature = "side128")))]
const SIDE: usize = footprint_scene::SIDE;
/// Image side, pixels: the M4F's bigger picture.
#[cfg(all(feature = "side128", not(any(microbit, stm32f100))))]
const SIDE: usize = footprint_scene::SIDE_M4F_LARGE;
/// Rows per band: the accumulator and working image hold this many rows (as many as the
/// board's RAM leaves: README "Embedding").
#[cfg(all(microbit, not(any(feature = "q24", feature = "float"))))]
const BAND: usize = 8;
/// Rows per band (the Q24 and float paths' wider pixels on the micro:bit).
#[cfg(all(microbit, any(feature = "q24", feature = "float")))]
const BAND: usize = 2;
/// Rows per band.
#[cfg(stm32f100)]
const BAND: usize = 3;
/// Rows per band: the whole image on the 4 MiB MPS2 boards.
#[cfg(not(any(microbit, stm32f100)))]
const BAND: usize = SIDE;
/// Frames of the orbit (the Q24 and float paths render one).
#[cfg(not(any(feature = "q24", feature = "float")))]
const FRAMES: usize = 4;
/// Frames of the orbit (the Q24 and float paths render one).
#[cfg(any(feature = "q24", feature = "float"))]
const FRAMES: usize = 1;
/// Pixels in a band.
const BAND_PIXELS: usize = BAND * SIDE;

/// Where the board's flash starts (its memory map's FLASH origin).
#[cfg(stm32f100)]
const FLASH_ORIGIN: usize = 0x0800_0000;
/// Where the board's flash starts (its memory map's FLASH origin).
#[cfg(not(stm32f100))]
const FLASH_ORIGIN: usize = 0;

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
    // Each frame's checksum and ticks, printed after the stack's high-water mark is taken
    // (core::fmt's stack is not part of the render's bound).
    let mut frames = [(0u32, 0u64); FRAMES];
    let mut first = None;
    // The view-independent set-up, once for the orbit (timed on its own).
    let t0 = ticks();
    let mut failed = setup().err();
    let setup_ticks = ticks() - t0;
    for (step, out) in frames.iter_mut().enumerate() {
        if failed.is_some() {
            break;
        }
        EMIT_TICKS.store(0, Relaxed);
        let t0 = ticks();
        let result = render(step);
        let spent = ticks() - t0 - u64::from(EMIT_TICKS.load(Relaxed));
        match result {
            Ok(r) => {
                *out = (r.0.checksum, spent);
                first.get_or_insert(r);
            }
            Err(e) => {
                failed = Some(e);
                break;
            }
        }
    }
    let high_water = stack_high_water(free_start);
    let (data_start, data_end) = (
        core::ptr::addr_of_mut!(__sdata) as usize,
        core::ptr::addr_of_mut!(__edata) as usize,
    );
    let data_load = core::ptr::addr_of!(__sidata) as usize;
    if let Some(e) = failed {
        hprintln!("render failed: {}", e);
    }
    if let Some(n) = instructions(setup_ticks, calibration) {
        hprintln!(
            "setup instructions {} (view-independent, once per orbit)",
            n
        );
    }
    for (step, &(checksum, spent)) in frames.iter().enumerate() {
        match instructions(spent, calibration) {
            Some(n) => hprintln!(
                "frame {} checksum 0x{:08x} instructions {}",
                step,
                checksum,
                n
            ),
            None => hprintln!(
                "frame {} checksum 0x{:08x} instructions unknown",
                step,
                checksum
            ),
        }
    }
    let ok = failed.is_none();
    if let Some((report, (display_crc, drawn))) = first {
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
    }
    match instructions(frames[0].1, calibration) {
        Some(n) => hprintln!(
            "frame instructions {} (frame 0; the rows sent to the display included, printing the image excluded)",
            n
        ),
        None => hprintln!("frame instructions unknown (no clock: run QEMU with -icount)"),
    }
    hprintln!("stack high-water {} bytes", high_water);
    hprintln!("static RAM {} bytes", free_start - data_start);
    hprintln!(
        "flash {} bytes",
        data_load - FLASH_ORIGIN + (data_end - data_start)
    );
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

#[cfg(not(any(feature = "q24", feature = "float")))]
const PATH: &str = "compact";
#[cfg(feature = "q24")]
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
/// count: QEMU models no pipeline, wait states or multi-cycle instructions (`embedded/cycles.py`
/// estimates cycles from QEMU's log of the blocks executed). Without `-icount`
/// the clock follows the host and the figure means little; with no clock at all, `None`.
fn instructions(ticks: u64, (cal_instructions, cal_ticks): (u64, u64)) -> Option<u64> {
    (cal_ticks > 0).then(|| (ticks * cal_instructions + cal_ticks / 2) / cal_ticks)
}

/// Prints band rows as `row Y` and hex Q24 RGBA (float images are quantised to Q24 first).
#[inline(never)]
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

/// The compact path's shading table: view-independent, built once by [`setup`].
#[cfg(not(any(feature = "q24", feature = "float")))]
static mut LUT: [[u16; 4]; 256] = [[0; 4]; 256];

/// The view-independent set-up: the compact path's shading table (the Q24 and float paths
/// build theirs per frame).
#[inline(never)]
fn setup() -> Result<(), footprint::Error> {
    #[cfg(not(any(feature = "q24", feature = "float")))]
    // SAFETY: called once from `main`, before any `render`; the only borrow of LUT then.
    footprint_scene::compact_lut(unsafe { &mut *core::ptr::addr_of_mut!(LUT) })?;
    Ok(())
}

/// The compact fixed-point render of orbit frame `step`, from `static` buffers, through the
/// shading table [`setup`] built. Frame 0's rows are printed.
#[cfg(not(any(feature = "q24", feature = "float")))]
#[inline(never)]
fn render(step: usize) -> Result<(footprint_scene::Report, (u32, usize)), footprint::Error> {
    const STENCILS: usize = footprint_scene::compact_stencil_len(SIDE);
    static mut STENCIL: [i16; STENCILS] = [0; STENCILS];
    static mut ACC: [[i32; 4]; BAND_PIXELS] = [[0; 4]; BAND_PIXELS];
    static mut IMAGE: [[u16; 4]; BAND_PIXELS] = [[0; 4]; BAND_PIXELS];
    static mut ROWS: [RowSpan; BAND] = [RowSpan::EMPTY; BAND];
    // SAFETY: `render` is called from `main` only, after `setup`, one frame after another, with
    // no interrupts that touch these: LUT is only read here, each other `static mut` is borrowed
    // mutably once per call, and every borrow ends when the call returns.
    let (lut, b) = unsafe {
        (
            &*core::ptr::addr_of!(LUT),
            footprint_scene::CompactBuffers {
                stencils: &mut *core::ptr::addr_of_mut!(STENCIL),
                acc: &mut *core::ptr::addr_of_mut!(ACC),
                image: &mut *core::ptr::addr_of_mut!(IMAGE),
                rows: &mut *core::ptr::addr_of_mut!(ROWS),
            },
        )
    };
    let mut display = CrcDisplay::new(SIDE);
    let mut row = [0u16; SIDE];
    let report = footprint_scene::render_compact(SIDE, step, lut, b, |first, px| {
        if step == 0 {
            emit_q15(first, px);
        }
        // Whole rows of SIDE pixels into a row of SIDE: cannot fail.
        let _ = send_band_q15(first, SIDE, px, &mut row, &mut display);
    })?;
    Ok((report, display.finish()))
}

/// Prints Q15 band rows as Q24 (exact: a shift), a row at a time.
#[cfg(not(any(feature = "q24", feature = "float")))]
fn emit_q15(first: usize, pixels: &[[u16; 4]]) {
    for (r, row) in pixels.chunks(SIDE).enumerate() {
        let mut q = [[0u32; 4]; SIDE];
        for (o, &p) in q.iter_mut().zip(row) {
            *o = footprint::fixed::compact::to_q24(p);
        }
        emit(first + r, &q);
    }
}

/// The Q24 fixed-point render, from `static` buffers (one frame).
#[cfg(feature = "q24")]
#[inline(never)]
fn render(_step: usize) -> Result<(footprint_scene::Report, (u32, usize)), footprint::Error> {
    use footprint::fixed::FixedTable;
    static mut TABLE: FixedTable<{ footprint_scene::N }> = FixedTable::zeroed();
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

/// The float render, from `static` buffers (one frame).
#[cfg(feature = "float")]
#[inline(never)]
fn render(_step: usize) -> Result<(footprint_scene::Report, (u32, usize)), footprint::Error> {
    use footprint::ViewTable;
    static mut TABLE: ViewTable<{ footprint_scene::N }> =
        ViewTable::zeroed(footprint::Footprint::EMPTY);
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
