//! The embedded demo scene ([`footprint_scene`]) on a Cortex-M under QEMU, every buffer `static`,
//! no heap. Prints over semihosting, then exits with the render's status:
//!
//! ```text
//! fixed checksum 0x…      (equal to `footprint-scene-host`'s, bit for bit)
//! stack high-water N bytes (painted stack)
//! static RAM N bytes (.data + .bss)
//! flash N bytes (.text + .rodata + .data image)
//! ```
//!
//! Build with `--features float` for the float path instead (its checksum is informational).
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use footprint::composite::RowSpan;
use footprint::{GenericTable, Kernel};
use footprint_scene::{DIM, N, PIXELS, SIDE};

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
    paint_stack(free_start);
    let result = render();
    let high_water = stack_high_water(free_start);
    let (data_start, data_end) = (
        core::ptr::addr_of_mut!(__sdata) as usize,
        core::ptr::addr_of_mut!(__edata) as usize,
    );
    let data_load = core::ptr::addr_of!(__sidata) as usize;
    let ok = match result {
        Ok(report) => {
            hprintln!("{} checksum 0x{:08x}", PATH, report.checksum);
            hprintln!(
                "scene: {} sheets, {} voxels splatted, {} pixel updates",
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

/// The fixed-point render, from `static` buffers.
#[cfg(not(feature = "float"))]
#[inline(never)]
fn render() -> Result<footprint_scene::Report, footprint::Error> {
    use footprint::fixed::FixedTable;
    static mut GENERIC: GenericTable<N> = GenericTable::zeroed(Kernel::PAPER_GAUSSIAN);
    static mut TABLE: FixedTable<N> = FixedTable::zeroed();
    static mut LUT: [[u32; 4]; 256] = [[0; 4]; 256];
    static mut SHEET: [[u32; 4]; DIM * DIM] = [[0; 4]; DIM * DIM];
    static mut ACC: [[i64; 4]; PIXELS] = [[0; 4]; PIXELS];
    static mut IMAGE: [[u32; 4]; PIXELS] = [[0; 4]; PIXELS];
    static mut ROWS: [RowSpan; SIDE] = [RowSpan::EMPTY; SIDE];
    // SAFETY: `render` runs once (from `main`, which never returns), with no interrupts that touch
    // these, so each `static mut` is borrowed mutably exactly once.
    let b = unsafe {
        footprint_scene::FixedBuffers {
            generic: &mut *core::ptr::addr_of_mut!(GENERIC),
            table: &mut *core::ptr::addr_of_mut!(TABLE),
            lut: &mut *core::ptr::addr_of_mut!(LUT),
            sheet: &mut *core::ptr::addr_of_mut!(SHEET),
            acc: &mut *core::ptr::addr_of_mut!(ACC),
            image: &mut *core::ptr::addr_of_mut!(IMAGE),
            rows: &mut *core::ptr::addr_of_mut!(ROWS),
        }
    };
    footprint_scene::render_fixed(b)
}

/// The float render, from `static` buffers.
#[cfg(feature = "float")]
#[inline(never)]
fn render() -> Result<footprint_scene::Report, footprint::Error> {
    use footprint::ViewTable;
    static mut GENERIC: GenericTable<N> = GenericTable::zeroed(Kernel::PAPER_GAUSSIAN);
    static mut TABLE: ViewTable<N> = ViewTable::zeroed(footprint::Footprint::EMPTY);
    static mut SHEET: [[f32; 4]; DIM * DIM] = [[0.0; 4]; DIM * DIM];
    static mut ACC: [[f32; 4]; PIXELS] = [[0.0; 4]; PIXELS];
    static mut IMAGE: [[f32; 4]; PIXELS] = [[0.0; 4]; PIXELS];
    static mut ROWS: [RowSpan; SIDE] = [RowSpan::EMPTY; SIDE];
    // SAFETY: as in the fixed `render`: one call, one mutable borrow of each.
    let b = unsafe {
        footprint_scene::FloatBuffers {
            generic: &mut *core::ptr::addr_of_mut!(GENERIC),
            table: &mut *core::ptr::addr_of_mut!(TABLE),
            sheet: &mut *core::ptr::addr_of_mut!(SHEET),
            acc: &mut *core::ptr::addr_of_mut!(ACC),
            image: &mut *core::ptr::addr_of_mut!(IMAGE),
            rows: &mut *core::ptr::addr_of_mut!(ROWS),
        }
    };
    footprint_scene::render_float(b)
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
