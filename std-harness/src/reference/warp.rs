//! A rectilinear grid in the continuous reference (`crate::io::grid`): the field of a grid whose
//! samples stand at given positions is the uniform grid's field composed with the
//! piecewise-linear map, per axis, from position to sample index ([`Warp::index`]), so every
//! kernel is the uniform one scaled, interval by interval, to the length of the interval it lies
//! over, and the kernels still sum as the uniform lattice's do. Past the first and the last
//! sample the map goes on with the end interval's length. The rays stay straight in world space:
//! only the field's argument is warped.

use footprint::frame::FrameSetup;
use glam::{DVec3, Vec3};

/// Per axis, every sample's position in the frame's grid steps (strictly increasing).
#[derive(Clone, Debug)]
pub struct Warp {
    positions: [Vec<f64>; 3],
}

impl Warp {
    /// The warp of samples at `positions` (per axis, grid steps, strictly increasing, one or more).
    pub fn new(positions: [Vec<f64>; 3]) -> Self {
        Warp { positions }
    }

    /// Sample-index coordinates of the frame's grid point `g`.
    pub fn index(&self, g: DVec3) -> DVec3 {
        DVec3::new(
            to_index(&self.positions[0], g.x),
            to_index(&self.positions[1], g.y),
            to_index(&self.positions[2], g.z),
        )
    }

    /// The frame's grid point of sample-index coordinates `i` (the inverse of [`Warp::index`]).
    pub fn grid(&self, i: DVec3) -> DVec3 {
        DVec3::new(
            to_grid(&self.positions[0], i.x),
            to_grid(&self.positions[1], i.y),
            to_grid(&self.positions[2], i.z),
        )
    }

    /// A voxel's world gradient `g` from central differences per index step (the uniform
    /// grid's, `footprint::render::gradient`) made the non-uniform central difference of the
    /// grid at voxel `idx` (one-sided at an end): each grid-axis component times index steps
    /// per grid step there, as the renderer's samples take it (`footprint::refine`'s
    /// `RefinedSample::rate`). `f` is the frame (its grid-to-world map).
    pub fn gradient(&self, f: &FrameSetup, g: Vec3, idx: [usize; 3]) -> Vec3 {
        // Per grid step: G⁻ᵀ back out; the rates; G⁻ᵀ again.
        let per_step = f.grid_inverse_transpose.inverse() * g;
        let rate = Vec3::from_array(std::array::from_fn(|a| {
            rate(&self.positions[a], idx[a]) as f32
        }));
        f.grid_inverse_transpose * (per_step * rate)
    }

    /// The shortest distance between neighbouring samples, world units (`spacing`: the frame's,
    /// world units per grid step); `None` where no axis has two samples.
    pub fn smallest_gap(&self, spacing: [f32; 3]) -> Option<f64> {
        (0..3)
            .flat_map(|a| {
                self.positions[a]
                    .windows(2)
                    .map(move |w| (w[1] - w[0]) * f64::from(spacing[a]))
            })
            .reduce(f64::min)
    }
}

/// Index steps per grid step at sample `i` of an axis of samples at `p`: 2 / (the sum of its
/// two intervals), 1 / the one interval at an end, 1 for a lone sample.
fn rate(p: &[f64], i: usize) -> f64 {
    let length = |k: usize| p[k + 1] - p[k];
    match (
        i.checked_sub(1).filter(|_| p.len() > 1),
        (i + 1 < p.len()).then_some(i),
    ) {
        (Some(before), Some(after)) => 2.0 / (length(before) + length(after)),
        (Some(before), None) => 1.0 / length(before),
        (None, Some(after)) => 1.0 / length(after),
        (None, None) => 1.0,
    }
}

/// The interval of `p` (at least two positions) that `u` falls in, extended past the ends.
fn interval(p: &[f64], u: f64) -> usize {
    p.partition_point(|&x| x <= u).clamp(1, p.len() - 1) - 1
}

/// The index coordinate of position `u` on an axis of samples at `p`.
fn to_index(p: &[f64], u: f64) -> f64 {
    if p.len() < 2 {
        return u - p.first().copied().unwrap_or(0.0);
    }
    let k = interval(p, u);
    k as f64 + (u - p[k]) / (p[k + 1] - p[k])
}

/// The position of index coordinate `i` on an axis of samples at `p`.
fn to_grid(p: &[f64], i: f64) -> f64 {
    if p.len() < 2 {
        return i + p.first().copied().unwrap_or(0.0);
    }
    let k = (i.floor().max(0.0) as usize).min(p.len() - 2);
    p[k] + (i - k as f64) * (p[k + 1] - p[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_is_piecewise_linear_and_inverts() {
        let w = Warp::new([vec![0.0, 1.0, 3.0], vec![0.0], vec![0.0, 0.5]]);
        let i = w.index(DVec3::new(2.0, 0.25, 1.0));
        assert_eq!(i, DVec3::new(1.5, 0.25, 2.0));
        // Past the ends, with the end intervals.
        assert_eq!(w.index(DVec3::new(-1.0, 0.0, -0.5)).x, -1.0);
        assert_eq!(w.index(DVec3::new(5.0, 0.0, 0.0)).x, 3.0);
        for g in [-1.3, 0.0, 0.4, 1.0, 2.7, 3.0, 4.5] {
            let back = w.grid(w.index(DVec3::new(g, g, g)));
            assert!(
                (back - DVec3::splat(g)).abs().max_element() < 1e-12,
                "{g}: {back}"
            );
        }
        assert_eq!(w.smallest_gap([1.0, 1.0, 2.0]), Some(1.0));
        let x = &w.positions[0];
        assert_eq!([0, 1, 2].map(|i| rate(x, i)), [1.0, 2.0 / 3.0, 0.5]);
        assert_eq!(rate(&w.positions[1], 0), 1.0);
    }
}
