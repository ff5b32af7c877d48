//! The f64 reference renderer: the same frame, sheets, shading and compositing as the core, but
//! every footprint weight is the exact kernel integral ([`super::ReferenceFootprint`]) and every
//! accumulation and composite is in f64. Shading uses the core's shader (f32), so the difference
//! between the two renders isolates the tables and the f32 accumulation.

use super::perspective::PerspectiveVoxel;
use super::ReferenceFootprint;
use crate::CliError;
use footprint::frame::{FrameSetup, Order};
use footprint::lod::Coloured;
use footprint::render::{gradient, Absorption, SheetWindow};
use footprint::shade::{Lighting, Shader};
use footprint::Kernel;
use glam::{DMat3, DVec3};

/// What the reference renders: the core's frame and shading, the kernel, the compositing order
/// and the background (as in the core renderer).
#[derive(Clone, Copy, Debug)]
pub struct ReferenceScene<'a> {
    pub frame: &'a FrameSetup,
    pub kernel: &'a Kernel,
    pub min_radius_px: f32,
    pub shader: Shader<'a>,
    pub order: Order,
    pub background: Option<&'a [[f32; 4]]>,
    /// The model each sheet composites, as the core's `FloatPath` does.
    pub absorption: Absorption,
}

/// Renders the sheets `sheet(s, buffer)` supplies and returns the premultiplied RGBA image (f64,
/// row-major, top row first); `progress(done, total)` after each sheet. Samples that carry a
/// colour (a level of detail's) are shaded with it, as the core shades them.
pub fn render_reference(
    scene: &ReferenceScene<'_>,
    mut sheet: impl FnMut(usize, &mut [Coloured]),
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<[f64; 4]>, CliError> {
    let splat = SheetSplat::new(scene)?;
    let frame = scene.frame;
    let (w, h) = (frame.size[0], frame.size[1]);
    let n = w * h;
    let bg: Vec<[f64; 4]> = match scene.background {
        Some(b) => b.iter().map(|p| p.map(f64::from)).collect(),
        None => vec![[0.0; 4]; n],
    };
    let order = scene.order;
    let mut image = if order == Order::BackToFront {
        bg.clone()
    } else {
        vec![[0.0; 4]; n]
    };
    let mut accum = vec![[0.0f64; 4]; n];
    let (len, _, _) = frame.sheet_shape();
    let count = frame.sheet_count();
    let blank = Coloured::default();
    let mut bufs = [vec![blank; len], vec![blank; len], vec![blank; len]];
    for step in 0..count {
        let s = frame.sheet_at(order, step);
        // Sheets s−1, s, s+1 (read directly: the reference does not need to stream).
        let have_lo = s > 0;
        let have_hi = s + 1 < count;
        if have_lo {
            sheet(s - 1, &mut bufs[0]);
        }
        sheet(s, &mut bufs[1]);
        if have_hi {
            sheet(s + 1, &mut bufs[2]);
        }
        let window = SheetWindow {
            lower: have_lo.then_some(&bufs[0][..]),
            current: &bufs[1][..],
            upper: have_hi.then_some(&bufs[2][..]),
        };
        splat.sheet(s, &window, &mut accum)?;
        for (acc, img) in accum.iter_mut().zip(image.iter_mut()) {
            if *acc == [0.0; 4] {
                continue;
            }
            let src = match scene.absorption {
                Absorption::Opacity => acc.map(|x| x.clamp(0.0, 1.0)),
                Absorption::Extinction => extinction_layer64(*acc),
            };
            *img = match order {
                Order::BackToFront => over64(src, *img),
                Order::FrontToBack => over64(*img, src),
            };
            *acc = [0.0; 4];
        }
        progress(step + 1, count);
    }
    if order == Order::FrontToBack {
        for (img, b) in image.iter_mut().zip(&bg) {
            *img = over64(*img, *b);
        }
    }
    Ok(image)
}

/// One view's splatting of a sheet into the f64 accumulation image: the scene, the exact
/// footprint and what every voxel of the view shares.
struct SheetSplat<'a> {
    scene: ReferenceScene<'a>,
    fp: ReferenceFootprint,
    lighting: Lighting,
    /// Grid to screen (pixels per grid step), in f64.
    g2s: DMat3,
    origin: DVec3,
    /// Pixels per grid step squared: a voxel's footprint integrates to this.
    area: f64,
}

impl<'a> SheetSplat<'a> {
    fn new(scene: &ReferenceScene<'a>) -> Result<Self, CliError> {
        let frame = scene.frame;
        let g2s = frame.grid_to_screen.as_dmat3();
        let fp = ReferenceFootprint::new(scene.kernel, &g2s, f64::from(scene.min_radius_px))?;
        Ok(SheetSplat {
            scene: *scene,
            fp,
            lighting: Lighting::new(frame),
            g2s,
            origin: frame.origin.as_dvec3(),
            area: f64::from(frame.cell_area),
        })
    }

    /// Adds sheet `s` (the middle of `window`) to `accum`. The image's rows are split between
    /// threads; each shades every voxel (cheap) and evaluates footprints only on its own rows
    /// (the expensive part), so the sum is the same as a single pass.
    fn sheet(
        &self,
        s: usize,
        window: &SheetWindow<'_, Coloured>,
        accum: &mut [[f64; 4]],
    ) -> Result<(), CliError> {
        let frame = self.scene.frame;
        let (w, h) = (frame.size[0], frame.size[1]);
        let (_, na, nb) = frame.sheet_shape();
        let threads = std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .clamp(1, 8);
        let band = h.div_ceil(threads);
        let failed = std::sync::Mutex::new(false);
        std::thread::scope(|scope| {
            for (t, chunk) in accum.chunks_mut(band * w).enumerate() {
                let failed = &failed;
                crate::threads::spawn(scope, move || {
                    let rows = t * band..(t * band + chunk.len() / w);
                    for v in 0..nb {
                        for u in 0..na {
                            if self.voxel(s, [u, v], window, rows.clone(), chunk).is_err() {
                                *failed.lock().expect("no panics hold it") = true;
                            }
                        }
                    }
                });
            }
        });
        if *failed.lock().expect("no panics hold it") {
            return Err(CliError::input(
                "the reference could not project a voxel (behind the eye or not finite)",
            ));
        }
        Ok(())
    }

    /// Shades voxel (u, v) of sheet `s` and adds its footprint to `chunk`, image rows `rows`;
    /// `Err` when a perspective view cannot project it.
    fn voxel(
        &self,
        s: usize,
        [u, v]: [usize; 2],
        window: &SheetWindow<'_, Coloured>,
        rows: std::ops::Range<usize>,
        chunk: &mut [[f64; 4]],
    ) -> Result<(), ()> {
        let ReferenceScene {
            frame,
            kernel,
            min_radius_px,
            shader,
            absorption,
            ..
        } = self.scene;
        let na = frame.sheet_shape().1;
        let sample = window.current[v * na + u];
        let rgba = shader.shade_coloured(
            &self.lighting,
            None,
            sample.value,
            sample.colour,
            || gradient(frame, window, u, v),
            frame.grid_index(s, u, v),
            frame.dims,
        );
        if !(rgba[3] > 0.0) {
            return Ok(());
        }
        let w = frame.size[0];
        let first = rows.start * w;
        let mut add = |i: usize, c: &[f64; 4], wt: f64| {
            let px = &mut chunk[i - first];
            for ch in 0..4 {
                px[ch] += c[ch] * wt;
            }
        };
        if let Some(cam) = frame.camera() {
            let idx = frame.grid_index(s, u, v).map(|i| i as f64);
            let min_r = f64::from(min_radius_px);
            let pv = PerspectiveVoxel::new(frame, cam, kernel, min_r, idx).map_err(|_| ())?;
            let Some(value) = absorption.voxel_value(rgba) else {
                return Ok(());
            };
            let scale = match absorption {
                Absorption::Opacity => {
                    let a = f64::from(rgba[3]);
                    if a < 1.0 && pv.exponent != 1.0 {
                        (1.0 - (1.0 - a).powf(pv.exponent)) / a
                    } else {
                        1.0
                    }
                }
                // Optical depth is linear in the distance along the ray.
                Absorption::Extinction => pv.exponent,
            };
            let c = value.map(|x| f64::from(x) * scale);
            pv.for_each_weight(w, rows, |i, wt| add(i, &c, wt));
            return Ok(());
        }
        let (k, (a, b)) = (frame.sheet_axis, frame.in_sheet);
        let g = &self.g2s;
        let p = self.origin + g.col(k) * s as f64 + g.col(a) * u as f64 + g.col(b) * v as f64;
        let Some(value) = absorption.voxel_value(rgba) else {
            return Ok(());
        };
        let c = value.map(|x| f64::from(x) * self.area);
        self.fp
            .for_each_weight([p.x, p.y], w, rows, |i, wt| add(i, &c, wt));
        Ok(())
    }
}

/// An extinction sheet's [E, τ] as a premultiplied layer, in f64: α = 1 − e^(−τ), colour E·α/τ.
fn extinction_layer64(acc: [f64; 4]) -> [f64; 4] {
    let tau = acc[3].max(0.0);
    let k = if tau > 0.0 {
        -(-tau).exp_m1() / tau
    } else {
        1.0
    };
    [
        acc[0].max(0.0) * k,
        acc[1].max(0.0) * k,
        acc[2].max(0.0) * k,
        tau * k,
    ]
}

fn over64(front: [f64; 4], back: [f64; 4]) -> [f64; 4] {
    let k = 1.0 - front[3];
    [
        front[0] + k * back[0],
        front[1] + k * back[1],
        front[2] + k * back[2],
        front[3] + k * back[3],
    ]
}
