//! The embedded demo scene rendered on the host: prints the same lines the firmware prints for
//! its checksums, so CI can compare them (`fixed checksum 0x…` must match bit for bit).
//!
//! `--threads N` renders it on N threads at once and checks they all agree.

use footprint::composite::RowSpan;
use footprint::fixed::FixedTable;
use footprint::{GenericTable, Kernel, ViewTable};
use footprint_scene::{render_fixed, render_float, FixedBuffers, FloatBuffers, Report};
use footprint_scene::{DIM, PIXELS, SIDE};
use std::process::ExitCode;

fn main() -> ExitCode {
    let threads = match std::env::args().skip(1).collect::<Vec<_>>().as_slice() {
        [] => 1,
        [flag, n] if flag == "--threads" => match n.parse::<usize>() {
            Ok(n) if n >= 1 => n,
            _ => {
                eprintln!("--threads needs a whole number ≥ 1, got '{n}'");
                return ExitCode::from(2);
            }
        },
        _ => {
            eprintln!("usage: footprint-scene-host [--threads N]");
            return ExitCode::from(2);
        }
    };
    let fixed = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| s.spawn(|| render_fixed_boxed().map(|r| (r.checksum, r.stats))))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("render thread panicked"))
            .collect::<Result<Vec<_>, _>>()
    });
    let fixed = match fixed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("fixed render failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let (sum, stats) = fixed[0];
    if fixed.iter().any(|&(c, _)| c != sum) {
        eprintln!("threads disagree: {fixed:x?}");
        return ExitCode::FAILURE;
    }
    let float = match render_float_boxed() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("float render failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!(
        "scene: {} sheets, {} voxels splatted, {} pixel updates ({threads} thread(s) agree)",
        stats.sheets, stats.voxels_splatted, stats.pixel_updates
    );
    println!("fixed checksum 0x{sum:08x}");
    println!("float checksum 0x{:08x} (informational)", float.checksum);
    ExitCode::SUCCESS
}

/// The fixed render with heap buffers.
fn render_fixed_boxed() -> Result<Report, footprint::Error> {
    render_fixed(FixedBuffers {
        generic: &mut Box::new(GenericTable::zeroed(Kernel::PAPER_GAUSSIAN)),
        table: &mut Box::new(FixedTable::zeroed()),
        lut: &mut Box::new([[0; 4]; 256]),
        sheet: &mut Box::new([[0; 4]; DIM * DIM]),
        acc: &mut vec![[0; 4]; PIXELS].try_into().expect("PIXELS long"),
        image: &mut vec![[0; 4]; PIXELS].try_into().expect("PIXELS long"),
        rows: &mut Box::new([RowSpan::EMPTY; SIDE]),
    })
}

/// The float render with heap buffers.
fn render_float_boxed() -> Result<Report, footprint::Error> {
    render_float(FloatBuffers {
        generic: &mut Box::new(GenericTable::zeroed(Kernel::PAPER_GAUSSIAN)),
        table: &mut Box::new(ViewTable::zeroed(footprint::Footprint::EMPTY)),
        sheet: &mut Box::new([[0.0; 4]; DIM * DIM]),
        acc: &mut vec![[0.0; 4]; PIXELS].try_into().expect("PIXELS long"),
        image: &mut vec![[0.0; 4]; PIXELS].try_into().expect("PIXELS long"),
        rows: &mut Box::new([RowSpan::EMPTY; SIDE]),
    })
}
