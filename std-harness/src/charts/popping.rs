//! The popping sweep (issue 12): the chart's scene turned through azimuth 40°–50° in 0.1° steps
//! (elevation and roll from `--view`), where a volume's most image-parallel grid axis switches
//! at 45° for equal in-plane spacings. Each frame is rendered with object slicing (the paper's
//! sheets), image slicing (`--slab` as given) and the continuous reference; what is charted is
//! the change between consecutive frames, as PSNR (RGB) of frame i+1 against frame i: a pop is a
//! dip in that curve that the continuous reference does not have. Each frame's PSNR against the
//! continuous reference is recorded too.

use crate::args::{RenderArgs, SlicingArg};
use crate::metrics::compare;
use crate::pipeline::render_continuous_ref;
use crate::reference::continuous::Reconstruction;
use crate::CliError;

/// First and last azimuth, tenths of a degree.
const SWEEP: (i32, i32) = (400, 500);

/// The sweep's results: per frame, and per pair of consecutive frames.
pub struct Popping {
    /// Azimuth of each frame, degrees.
    pub azimuths: Vec<f64>,
    /// Consecutive-frame change, PSNR dB, for object slicing, image slicing and the continuous
    /// reference (`azimuths.len() − 1` each: entry i compares frames i and i+1).
    pub change_db: [Vec<f64>; 3],
    /// Each frame's PSNR against the continuous reference: object, image slicing.
    pub truth_db: [Vec<f64>; 2],
    /// The slab thickness image slicing used, voxel spacings.
    pub slab: f32,
}

/// The curves' names, in `change_db` order.
pub const NAMES: [&str; 3] = ["object slicing", "image slicing", "continuous reference"];

/// Runs the sweep on `base`'s scene (its `--view` elevation and roll, its size).
pub fn popping(
    base: &RenderArgs,
    mut progress: impl FnMut(usize, usize),
) -> Result<Popping, CliError> {
    let mut args = base.clone();
    let mut r = super::open(&args)?;
    // The previous frame of each curve, and each new frame's change against it.
    let mut previous: [Option<Vec<[f64; 4]>>; 3] = Default::default();
    let mut out = Popping {
        azimuths: Vec::new(),
        change_db: Default::default(),
        truth_db: Default::default(),
        slab: base.slab,
    };
    let mut advance = |out: &mut Popping, k: usize, now: &[[f32; 4]], now64: Vec<[f64; 4]>| {
        if let Some(prev) = &previous[k] {
            out.change_db[k].push(compare(now, prev).1.psnr_db);
        }
        previous[k] = Some(now64);
    };
    let total = (SWEEP.1 - SWEEP.0 + 1) as usize;
    for (i, tenth) in (SWEEP.0..=SWEEP.1).enumerate() {
        let az = f64::from(tenth) / 10.0;
        args.view = [az as f32, base.view[1], base.view[2]];
        args.view_matrix = None;
        r.reframe(&crate::args::scene(&args)?)?;
        let (truth, _) = render_continuous_ref(r.prepared(), Reconstruction::Kernel)?;
        for (k, slicing) in [SlicingArg::Object, SlicingArg::Image]
            .into_iter()
            .enumerate()
        {
            args.slicing = Some(slicing);
            let plan = crate::args::plan(&args)?.with_precision(crate::plan::Precision::Float);
            let f = r.frame_of(&plan)?;
            out.truth_db[k].push(compare(&f.image, &truth.image).1.psnr_db);
            let img64 = f.image.iter().map(|c| c.map(f64::from)).collect();
            advance(&mut out, k, &f.image, img64);
        }
        let truth32: Vec<[f32; 4]> = truth.image.iter().map(|c| c.map(|v| v as f32)).collect();
        advance(&mut out, 2, &truth32, truth.image);
        out.azimuths.push(az);
        progress(i + 1, total);
    }
    Ok(out)
}

impl Popping {
    /// The lowest consecutive-frame PSNR of curve `k` (its largest change) and where (the later
    /// frame's azimuth).
    pub fn worst(&self, k: usize) -> (f64, f64) {
        self.change_db[k]
            .iter()
            .enumerate()
            .map(|(i, &db)| (db, self.azimuths[i + 1]))
            .fold(
                (f64::INFINITY, f64::NAN),
                |a, b| if b.0 < a.0 { b } else { a },
            )
    }

    /// CSV: one row per frame; the change columns compare it with the previous frame (empty on
    /// the first).
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "azimuth_deg,object_change_db,image_change_db,continuous_change_db,\
             object_vs_continuous_db,image_vs_continuous_db,slab\n",
        );
        for (i, az) in self.azimuths.iter().enumerate() {
            let change = |k: usize| {
                i.checked_sub(1)
                    .map_or(String::new(), |j| format!("{:.3}", self.change_db[k][j]))
            };
            s.push_str(&format!(
                "{az:.1},{},{},{},{:.3},{:.3},{}\n",
                change(0),
                change(1),
                change(2),
                self.truth_db[0][i],
                self.truth_db[1][i],
                self.slab
            ));
        }
        s
    }
}
