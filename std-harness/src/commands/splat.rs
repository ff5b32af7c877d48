//! `footprint splat`: one voxel of value 1, its raw footprint weights written as an image (see
//! [`crate::pipeline::ends::single`] for the conventions). PFM rows are stored bottom to top, as PFM
//! requires.

use crate::args::SplatArgs;
use crate::io::image::save_grey;
use crate::pipeline::ends::single::splat_image;
use crate::CliError;

pub fn run(args: &SplatArgs) -> Result<(), CliError> {
    crate::io::outputs::check(&[crate::io::outputs::Planned {
        flag: "--out",
        path: &args.out,
        extensions: &crate::io::image::GREY_EXTENSIONS,
    }])?;
    let (img, r) = splat_image(&crate::args::single(args)?)?;
    save_grey(&img, &args.out)?;
    let fa = &args.footprint;
    crate::say!(
        "{}: {:?} {}x{} table, footprint half-extent {:.3} x {:.3} px, sheet axis {}, \
         {}sum of weights {:.6}, peak {:.6e} px^-2{}{}, {:.3} ms",
        args.out.display(),
        fa.method,
        fa.table,
        fa.table,
        r.half_extent[0],
        r.half_extent[1],
        ["i", "j", "k"][r.sheet_axis],
        match r.layout {
            Some(footprint::ViewLayout::ScreenBox) => "view table over the screen box, ",
            Some(footprint::ViewLayout::Unit) => "view table over the unit square (thin oblique), ",
            None => "",
        },
        r.sum,
        r.peak,
        if r.clamped {
            ", widened to --min-radius"
        } else {
            ""
        },
        if r.cheated {
            ", paper cheat applied"
        } else {
            ""
        },
        r.seconds * 1e3
    );
    Ok(())
}
