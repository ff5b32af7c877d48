//! `--classification post`: the core's post-classified slabs (`footprint::render::post`) over a
//! volume in memory, on several cores.
//!
//! 1. **Which voxels.** A sample is a convex combination of the voxels within a kernel radius R
//!    of it, so it can only be visible if one of those is: its value above the shader's
//!    [`transparent_at_or_below`](footprint::shade::Shader::transparent_at_or_below). Every voxel
//!    such a sample reads lies less than 2R (grid steps) from that voxel, so the frame splats the
//!    finite voxels less than 2R from a visible-valued one (an exact Euclidean distance transform
//!    of the visible mask): every sample that can be seen has all of its weights, exactly as the
//!    continuous model reads them, and samples short of weights are at or below the transparent
//!    value either way. The voxels, their values and world gradients (the renderer's central
//!    differences) are kept across frames in the [`FrameCache`], as the visible lists are.
//! 2. **Per frame** they are placed on screen and sorted by the slab each reaches first in
//!    compositing order, then by image row (counting sorts: the order does not depend on the
//!    thread count); each thread owns a band of image rows and walks the slabs in that order, splatting
//!    the voxels that enter at each slab, then classifying and compositing it.
//!
//! **Memory.** Finding the voxels takes a bit per voxel and a few planes of distances
//! (`near_visible`); keeping them, 28 bytes per kept voxel (grid index, value, gradient),
//! refused with a reason past the visible lists' budget before any is kept, and 36 per frame
//! (its [`PostVoxel`] and first slab); per band a ring of slab accumulators of 20 bytes per
//! pixel. Every one of these is asked of memory fallibly: a refusal is an error, never an abort.
//! A streamed volume is refused (an oblique slab crosses every sheet), as are fixed-point
//! accumulation and colour-carrying levels of detail (their colours are pre-classified).

use crate::pipeline::stages::bands::{equal_bands_for, on_bands, Bands};
use crate::pipeline::stages::bands::{CoreFrame, Phases};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::visible::{FrameCache, PostSamples};
use crate::plan::Supersample;
use crate::reference::continuous::Reconstruction;
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::frame::Order;
use footprint::render::post::{MAX_VALUE_SCALE, WEIGHT_NODES};
use footprint::render::{
    gradient, Blend, PostBuffers, PostRenderer, PostSetup, PostVoxel, RenderStats, ShadedLayers,
    SheetRing, WeightTable,
};
use footprint::shade::OPACITY_TABLE_LEN;
use std::time::Instant;

/// Bytes [`PostSamples`] keeps per voxel.
const BYTES_PER_SAMPLE: usize = 28;

/// Renders one frame of `p` post-classified, with slabs `thickness` voxel spacings thick, on
/// `threads` bands.
pub fn render_post(
    p: &Prepared,
    (thickness, values, blend, reconstruction): (f32, Supersample, Blend, Reconstruction),
    threads: usize,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    let refuse = |why: &str| CliError::input(format!("{}: --classification post: {why}", p.name));
    let volume = p.volume().ok_or_else(|| {
        refuse(
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded)",
        )
    })?;
    if volume.is_coloured() {
        return Err(refuse(&format!(
            "level {} of this volume carries pre-classified colours: give --lod 0",
            p.level
        )));
    }
    let setup = post_setup(p, thickness, reconstruction).map_err(|e| refuse(&e.to_string()))?;
    let scale = scale_for(&setup, values);
    let setup = setup
        .with_value_scale(scale)
        .map_err(|e| refuse(&e.to_string()))?;
    // A crop's samples exist inside its box only (the rest of the grid is missing).
    let setup = match sample_range(volume) {
        Some((first, last)) => setup.with_sample_box(first, last),
        None => setup,
    };
    let start = Instant::now();
    let weights =
        Box::new(WeightTable::<WEIGHT_NODES>::new(&p.kernel).map_err(|e| refuse(&e.to_string()))?);
    let mut opacity = vec![0.0f32; OPACITY_TABLE_LEN];
    let classify = ShadedLayers::new(&p.frame, &setup, p.shader(), &mut opacity)
        .map_err(|e| refuse(&e.to_string()))?;
    let tables = start.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let reach = 2.0 * setup.support_radius();
    if cache.post.as_ref().is_none_or(|(kept, _)| *kept != reach) {
        let budget = cache.list_budget_for(volume);
        cache.post = Some((reach, post_samples(p, volume, (blend, reach), budget)?));
    }
    let samples = &cache.post.as_ref().expect("just made").1;
    let classify_samples = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let voxels = place(p, &setup, samples)?;
    let classify_time = classify_samples + t1.elapsed().as_secs_f64();

    let (setup, weights, classify, sv) = (&setup, &*weights, &classify, &voxels);
    let bands = Bands {
        threads,
        cull: None,
    };
    let size = p.frame.size;
    let timing = (start, classify_time, tables);
    super::slabs::banded_frame(
        p,
        bands.count(size[1]),
        timing,
        voxels.voxels.len(),
        |image| {
            on_bands(
                image,
                size,
                equal_bands_for(size[1], bands),
                p.background.as_deref(),
                |rows, band, bg| {
                    render_band(p, setup, (weights, classify, blend), sv, bg, band, rows)
                },
            )
        },
    )
}

/// The post-classified slabs of `p`'s frame, `thickness` spacings thick, reconstructing as asked.
pub fn post_setup(
    p: &Prepared,
    thickness: f32,
    reconstruction: Reconstruction,
) -> Result<PostSetup, footprint::render::SlabError> {
    match reconstruction {
        Reconstruction::Kernel => PostSetup::new(&p.frame, &p.kernel, thickness),
        Reconstruction::Trilinear => PostSetup::trilinear(&p.frame, thickness),
    }
}

/// The voxels a volume's samples exist among, `first..=last` per axis in whole-grid indices: a
/// crop's box (the volume is a brick owning it); `None` for the whole grid.
pub(crate) fn sample_range(volume: &crate::io::volume::Volume) -> Option<([usize; 3], [usize; 3])> {
    volume
        .brick
        .map(|b| (b.owned.lo, b.owned.hi.map(|h| h.saturating_sub(1))))
}

/// `--value-subsample auto`'s bound: the kernel's shorter semi-axis, in value pixels, stays at or
/// above this (docs/post-classification.md measures the error it costs).
pub const AUTO_VALUE_RADIUS: f32 = 3.0;

/// The largest value scale (at most [`MAX_VALUE_SCALE`]) that keeps the kernel's shorter
/// semi-axis at least [`AUTO_VALUE_RADIUS`] value pixels; 1 where it is narrower.
pub fn auto_value_scale(setup: &PostSetup) -> usize {
    let s = (setup.kernel_radius_px() / AUTO_VALUE_RADIUS).floor();
    if s >= 1.0 {
        (s as usize).min(MAX_VALUE_SCALE)
    } else {
        1
    }
}

/// The value scale `values` asks for on `setup`'s frame.
fn scale_for(setup: &PostSetup, values: Supersample) -> usize {
    match values {
        Supersample::Fixed(s) => s,
        Supersample::Auto => auto_value_scale(setup),
    }
}

/// The value scale a post-classified frame of `p` with slabs `thickness` thick renders at
/// (`None` where the slabs cannot be set up: the render says why).
pub fn value_scale(
    p: &Prepared,
    (thickness, values, reconstruction): (f32, Supersample, Reconstruction),
) -> Option<usize> {
    let setup = post_setup(p, thickness, reconstruction).ok()?;
    Some(scale_for(&setup, values))
}

/// The finite voxels less than `reach` (2R) grid steps from a visible-valued one (see the module
/// docs).
fn post_samples(
    p: &Prepared,
    volume: &crate::io::volume::Volume,
    (blend, reach): (Blend, f32),
    budget: usize,
) -> Result<PostSamples, CliError> {
    let f = &p.frame;
    let dims = f.dims;
    let shader = p.shader();
    // A projection reads every finite sample: none is transparent to it.
    let clear = if blend.projects() {
        f32::NEG_INFINITY
    } else {
        shader.transparent_at_or_below()
    };
    let needs_gradient = shader.shading.needs_gradient();
    let (len, na, nb) = f.sheet_shape();
    let axis = f.sheet_axis;
    let grid = |s: usize, u: usize, v: usize| {
        let i = f.grid_index(s, u, v);
        (i[2] * dims[1] + i[1]) * dims[0] + i[0]
    };
    // The voxels near a visible value, one bit each (no full-volume distance map: the third
    // campaign's abort).
    let near = near_visible(volume, clear, reach)?;
    let count = near.count;
    if count.saturating_mul(BYTES_PER_SAMPLE) > budget {
        return Err(CliError::input(format!(
            "{}: --classification post keeps the {count} voxels near visible values in memory \
             ({BYTES_PER_SAMPLE} bytes each), more than {} MiB: narrow the transfer function's \
             visible values or use --classification pre",
            p.name,
            budget >> 20
        )));
    }
    let mut out = PostSamples::default();
    let reserve = |e: std::collections::TryReserveError| {
        CliError::input(format!(
            "cannot allocate the post-classified voxel list: {e}"
        ))
    };
    out.index.try_reserve_exact(count).map_err(reserve)?;
    out.value.try_reserve_exact(count).map_err(reserve)?;
    out.gradient.try_reserve_exact(count).map_err(reserve)?;
    // Each sheet read once, through a ring of three: a sheet's window is complete once the
    // next is in.
    let mut storage = vec![0.0f32; 3 * len];
    let mut ring = SheetRing::new(&mut storage, f, f.order_for_ascending())?;
    let mut keep = |ring: &SheetRing<'_, f32>, n: usize| {
        let (s, window) = (ring.sheet_index(n), ring.window(n));
        for v in 0..nb {
            for u in 0..na {
                let value = window.current[v * na + u];
                if !near.get(grid(s, u, v)) || !value.is_finite() {
                    continue;
                }
                let g = if needs_gradient {
                    gradient(f, &window, u, v).to_array()
                } else {
                    [0.0; 3]
                };
                out.index.push(f.grid_index(s, u, v).map(|c| c as u32));
                out.value.push(value);
                out.gradient.push(g);
            }
        }
    };
    for s in 0..f.sheet_count() {
        let done = ring.push_with(|slot| {
            volume.sheet_into(axis, s, slot);
            Ok::<_, footprint::render::RenderError>(())
        })?;
        if let Some(n) = done {
            keep(&ring, n);
        }
    }
    if let Some(n) = ring.last() {
        keep(&ring, n);
    }
    Ok(out)
}

/// One bit per voxel (x fastest): the voxels [`near_visible`] keeps, and how many.
struct Near {
    bits: Vec<u64>,
    count: usize,
}

impl Near {
    fn get(&self, i: usize) -> bool {
        self.bits[i / 64] >> (i % 64) & 1 == 1
    }
}

/// The voxels whose Euclidean distance (in grid steps) to a voxel valued above `clear` (NaN never
/// is) is below `reach`, in bounded memory: a bit per voxel and a window of planes.
///
/// Each z-slice's squared in-plane distance to its visible voxels is exact (the distance transform
/// of Felzenszwalb and Huttenlocher (2012): one pass of lower envelopes of parabolas along x, one
/// along y), and the squared distance in 3-D is the least of dz² plus the in-plane distance of
/// the slice dz away. Only |dz| < `reach` can give less than `reach`², so the slices are held
/// in a ring of 2⌈reach⌉ − 1 planes, and each slice's bits are set once the planes up to
/// ⌈reach⌉ − 1 beyond it are in. Memory: n/8 bytes and the ring (4 bytes a voxel of a plane).
fn near_visible(
    volume: &crate::io::volume::Volume,
    clear: f32,
    reach: f32,
) -> Result<Near, CliError> {
    const FAR: f32 = 1e20;
    let [nx, ny, nz] = volume.dims;
    let (plane, n) = (nx * ny, nx * ny * nz);
    let mut bits = crate::io::try_filled(n.div_ceil(64), 0u64, "the post-classification mask")?;
    if !(reach > 0.0) {
        return Ok(Near { bits, count: 0 });
    }
    let r2 = reach * reach;
    // |dz| ≤ dz_max ⇔ dz² < reach².
    let dz_max = ((reach.ceil() as usize).saturating_sub(1)).min(nz);
    let width = 2 * dz_max + 1;
    let mut ring = crate::io::try_filled(
        width.saturating_mul(plane),
        FAR,
        "the post-classification distance planes",
    )?;
    let mut sheet = vec![0.0f32; plane];
    let m = nx.max(ny);
    let (mut f, mut out, mut v, mut z) = (
        vec![0.0f32; m],
        vec![0.0f32; m],
        vec![0usize; m],
        vec![0.0f32; m + 1],
    );
    let mut count = 0;
    // Slice `k` in, then slice `k − dz_max` out (its window complete).
    for k in 0..nz + dz_max {
        if k < nz {
            volume.sheet_into(2, k, &mut sheet);
            let d = &mut ring[(k % width) * plane..][..plane];
            for (di, &s) in d.iter_mut().zip(&sheet) {
                *di = if s > clear { 0.0 } else { FAR };
            }
            for row in d.chunks_exact_mut(nx) {
                f[..nx].copy_from_slice(row);
                envelope(&f[..nx], &mut out[..nx], &mut v, &mut z);
                row.copy_from_slice(&out[..nx]);
            }
            for x in 0..nx {
                for y in 0..ny {
                    f[y] = d[y * nx + x];
                }
                envelope(&f[..ny], &mut out[..ny], &mut v, &mut z);
                for y in 0..ny {
                    d[y * nx + x] = out[y];
                }
            }
        }
        let Some(at) = k.checked_sub(dz_max) else {
            continue;
        };
        let (lo, hi) = (at.saturating_sub(dz_max), (at + dz_max).min(nz - 1));
        for i in 0..plane {
            let least = (lo..=hi)
                .map(|s| {
                    let dz = s.abs_diff(at) as f32;
                    dz * dz + ring[(s % width) * plane + i]
                })
                .fold(FAR, f32::min);
            if least < r2 {
                let g = at * plane + i;
                bits[g / 64] |= 1 << (g % 64);
                count += 1;
            }
        }
    }
    Ok(Near { bits, count })
}

/// `out[p]` = min over q of (p − q)² + f[q] over the sites with f[q] below [`near_visible`]'s FAR (FAR
/// where there are none): the lower envelope of the parabolas rooted at the sites; `v` and `z`
/// are scratch of at least `f.len()` (+1) entries.
fn envelope(f: &[f32], out: &mut [f32], v: &mut [usize], z: &mut [f32]) {
    const FAR: f32 = 1e20;
    let cross = |q: usize, p: usize| {
        let (q2, p2) = ((q * q) as f32, (p * p) as f32);
        ((f[q] + q2) - (f[p] + p2)) / (2.0 * (q as f32 - p as f32))
    };
    let mut sites = (0..f.len()).filter(|&q| f[q] < FAR);
    let Some(first) = sites.next() else {
        out.fill(FAR);
        return;
    };
    let mut k = 0;
    v[0] = first;
    z[0] = f32::NEG_INFINITY;
    z[1] = f32::INFINITY;
    for q in sites {
        let mut s = cross(q, v[k]);
        while k > 0 && s <= z[k] {
            k -= 1;
            s = cross(q, v[k]);
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f32::INFINITY;
    }
    k = 0;
    for (p, o) in out.iter_mut().enumerate() {
        while z[k + 1] < p as f32 {
            k += 1;
        }
        let dq = p as f32 - v[k] as f32;
        *o = dq * dq + f[v[k]];
    }
}

/// A frame's voxels on screen, grouped by the compositing step at which each enters (its first
/// slab front to back, its last back to front), by image row within a step, in grid order within
/// a row (a stable sort: the same order for any thread count).
struct Placed {
    voxels: Vec<PostVoxel>,
    starts: Vec<usize>,
}

fn place(p: &Prepared, setup: &PostSetup, s: &PostSamples) -> Result<Placed, CliError> {
    let f = &p.frame;
    let slabs = setup.slabs();
    let count = slabs.slab_count();
    let n = s.value.len();
    let mut voxels = Vec::new();
    let mut keys = Vec::new();
    voxels
        .try_reserve_exact(n)
        .and_then(|_| keys.try_reserve_exact(n))
        .map_err(|_| CliError::input("cannot allocate the post-classified frame's voxels"))?;
    // Within a slab, by image row: consecutive voxels then touch the same accumulator rows,
    // which stay in cache (a whole frame's ring of accumulators does not).
    let rows = f.size[1] + 1;
    for k in 0..n {
        let position = f.affine_position(s.index[k].map(|c| c as f32)).to_array();
        let (first, last) = slabs.slabs_of(position[2]);
        let step = match p.order {
            Order::FrontToBack => first,
            Order::BackToFront => count - 1 - last,
        };
        let row = position[1].clamp(0.0, (rows - 1) as f32) as usize;
        keys.push(step * rows + row);
        voxels.push(PostVoxel {
            position,
            value: s.value[k],
            gradient: s.gradient[k],
        });
    }
    let (voxels, starts) = super::slabs::counting_sort(
        voxels.len(),
        count * rows,
        |i| keys[i],
        |i| voxels[i],
        "the post-classified frame's voxels",
    )?;
    Ok(Placed {
        voxels,
        starts: starts.into_iter().step_by(rows).collect(),
    })
}

/// One band: every slab in compositing order, its entering voxels splatted, then classified and
/// composited.
#[allow(clippy::too_many_arguments)]
fn render_band(
    p: &Prepared,
    setup: &PostSetup,
    (weights, classify, blend): (&WeightTable<WEIGHT_NODES>, &ShadedLayers<'_>, Blend),
    sv: &Placed,
    background: Option<&[[f32; 4]]>,
    image: &mut [[f32; 4]],
    rows: std::ops::Range<usize>,
) -> Result<(RenderStats, Phases), CliError> {
    let slabs = setup.slabs();
    let ring = setup.ring();
    let vr = setup.value_rows(rows.clone());
    let n = setup.value_size()[0] * vr.len();
    let mut acc = crate::io::try_filled(ring.saturating_mul(n), [0.0f32; 5], "a band's slabs")?;
    let mut spans = vec![RowSpan::EMPTY; ring * vr.len()];
    let buffers = PostBuffers {
        accumulators: &mut acc,
        image,
        rows: &mut spans,
    };
    // Whether a voxel reaches the band's value rows (a conservative test at image scale: the
    // renderer clips exactly).
    let s = setup.value_scale();
    let (ya, yb) = (vr.start * s, (vr.end * s).min(p.frame.size[1]));
    let reaches = |v: &PostVoxel| {
        let r = slabs.rows_of(v.position[1]);
        r.start < yb + s && r.end + s > ya
    };
    let mut renderer = PostRenderer::with_band(
        setup,
        weights,
        classify,
        p.order,
        buffers,
        background,
        rows.clone(),
    )?
    .with_blend(blend);
    let mut phases = Phases::default();
    for k in 0..slabs.slab_count() {
        crate::cancel::check()?;
        let t0 = Instant::now();
        for v in &sv.voxels[sv.starts[k]..sv.starts[k + 1]] {
            if reaches(v) {
                renderer.splat_voxel(v)?;
            }
        }
        let t1 = Instant::now();
        renderer.composite_next();
        phases.splat += (t1 - t0).as_secs_f64();
        phases.composite += t1.elapsed().as_secs_f64();
    }
    Ok((renderer.finish(), phases))
}

#[cfg(test)]
mod tests {
    use crate::io::volume::{Samples, Volume};

    /// The kept voxels are exactly those whose Euclidean distance to a visible one is below the
    /// reach (brute force over every voxel), for reaches below, at and past whole steps and
    /// volumes thinner than the window (one voxel along z, and along every axis).
    #[test]
    fn near_visible_is_the_euclidean_distance_below_the_reach() {
        for (dims, set) in [
            (
                [9usize, 7, 6],
                vec![(1usize, 1usize, 1usize), (7, 5, 4), (4, 0, 5)],
            ),
            ([5, 4, 1], vec![(2, 1, 0)]),
            ([1, 1, 1], vec![(0, 0, 0)]),
            ([3, 1, 8], vec![(0, 0, 7), (2, 0, 0)]),
            ([6, 6, 6], vec![]),
        ] {
            let n = dims.iter().product::<usize>();
            let mut values = vec![0.0f32; n];
            for &(x, y, z) in &set {
                values[(z * dims[1] + y) * dims[0] + x] = 1.0;
            }
            let volume = Volume::new(dims, [1.0; 3], Samples::F32(values.into()));
            for reach in [0.5f32, 1.0, 2.0, 2.3, 3.2, 7.5] {
                let near = super::near_visible(&volume, 0.5, reach).unwrap();
                let mut count = 0;
                for z in 0..dims[2] {
                    for y in 0..dims[1] {
                        for x in 0..dims[0] {
                            let d2 = set
                                .iter()
                                .map(|&(a, b, c)| {
                                    let d = |p: usize, q: usize| (p as f32 - q as f32).powi(2);
                                    d(x, a) + d(y, b) + d(z, c)
                                })
                                .fold(f32::INFINITY, f32::min);
                            let got = near.get((z * dims[1] + y) * dims[0] + x);
                            assert_eq!(
                                got,
                                d2 < reach * reach,
                                "{dims:?} ({x},{y},{z}) reach {reach}"
                            );
                            count += usize::from(got);
                        }
                    }
                }
                assert_eq!(near.count, count);
            }
        }
    }
}
