//! [`PerVoxel`]: how the float path ([`super::FloatPath`]) places the voxels of a perspective
//! frame, every voxel splatted with its own footprint (the paper: "the image plane footprint
//! extent and mapping must be generated for each sample"). Perspective is a placement of the one
//! float path, not a path of its own: `FloatPath::new(&PerVoxel::new(…)?)`.
//!
//! Per voxel: its screen position and the Jacobian of the projection there
//! ([`crate::geometry::Perspective::project`]); the footprint of the kernel under that local
//! affine map ([`Footprint::with_sheet_axis`], so clamping to the minimum radius and
//! renormalising small footprints work as in orthographic frames); the generic table sampled
//! directly through it (no view table: every voxel's map differs). Two per-voxel corrections keep
//! a flat sheet accumulating to its value, as in an orthographic frame:
//! - the sheet cell's screen area under the voxel's Jacobian replaces the frame's `cell_area`;
//! - the opacity, corrected by the shader for the distance Δ₀ between sheets along the central
//!   ray, is corrected again to the distance Δ along the voxel's own ray: α' = 1 − (1 − α)^(Δ/Δ₀),
//!   with the colour scaled as α (premultiplied); in the extinction model the optical depth τ
//!   simply scales, τ' = τ·Δ/Δ₀ (and its emission with it).
//!
//! Lighting stays a directional head-light along the central view direction (as VTK's default
//! light).

use super::absorption::Absorption;
use super::precision::VoxelSplat;
use super::RenderError;
use crate::frame::FrameSetup;
use crate::geometry::{Footprint, FootprintOptions, Perspective};
use crate::kernel::Kernel;
use crate::math;
use crate::splat::{splat_rows, Direct, ImageMut, SplatStats};
use crate::table::{GenericTable, Lookup};
use glam::Vec3;

/// A footprint per voxel, sampled straight from the generic table: how the float path places the
/// voxels of a perspective frame ([`FrameSetup::perspective`]).
#[derive(Clone, Copy, Debug)]
pub struct PerVoxel<'a, const N: usize> {
    table: &'a GenericTable<N>,
    lookup: Lookup,
    kernel: Kernel,
    options: FootprintOptions,
    camera: Perspective,
    /// Row `sheet_axis` of (V·G)⁻¹: a ray's component along the sheet axis, grid steps.
    inv_row_k: Vec3,
    /// |inv_row_k.z|: the central ray's component (Δ₀ ∝ 1 / it).
    central_k: f32,
}

impl<'a, const N: usize> PerVoxel<'a, N> {
    /// The placement for a perspective `frame` (made with `kernel` and `options`), reading `table`
    /// with `lookup`. Refused ([`RenderError::Projection`]) for an orthographic frame.
    pub fn new(
        frame: &FrameSetup,
        kernel: &Kernel,
        options: FootprintOptions,
        table: &'a GenericTable<N>,
        lookup: Lookup,
    ) -> Result<Self, RenderError> {
        let camera = *frame.camera().ok_or(RenderError::Projection)?;
        let inv = frame.grid_to_screen.inverse();
        let k = frame.sheet_axis;
        let inv_row_k = inv.row(k);
        Ok(PerVoxel {
            table,
            lookup,
            kernel: *kernel,
            options,
            camera,
            inv_row_k,
            central_k: math::abs(inv_row_k.z),
        })
    }

    /// The footprint, screen position, cell area (px²) and opacity exponent Δ/Δ₀ of grid point
    /// `index` of `frame` (exposed for tests and tools; the splat uses the same numbers).
    pub fn voxel(
        &self,
        frame: &FrameSetup,
        index: [f32; 3],
    ) -> Result<(Footprint, [f32; 2], f32, f32), RenderError> {
        let p = frame.affine_position(index);
        let pr = self
            .camera
            .project(p, &frame.grid_to_screen)
            .ok_or(RenderError::Geometry(
                crate::geometry::GeometryError::NonFinite,
            ))?;
        let fp =
            Footprint::with_sheet_axis(&self.kernel, &pr.jacobian, self.options, frame.sheet_axis)
                .map_err(RenderError::Geometry)?;
        let (a, b) = frame.in_sheet;
        let (ca, cb) = (pr.jacobian.col(a), pr.jacobian.col(b));
        let area = math::abs(ca.x * cb.y - ca.y * cb.x);
        // Δ ∝ |ray| / |ray_k| (grid steps along the sheet axis per unit length of ray).
        let along = math::abs(self.inv_row_k.dot(pr.ray));
        let exponent = pr.ray.length() * self.central_k / along;
        Ok((fp, pr.center, area, exponent))
    }
}

impl<const N: usize> VoxelSplat for PerVoxel<'_, N> {
    const PERSPECTIVE: bool = true;

    fn splat_voxel_of(
        &self,
        f: &FrameSetup,
        sheet: usize,
        (u, v): (usize, usize),
        row0: usize,
        value: &[f32; 4],
        absorption: Absorption,
        acc: &mut ImageMut<'_, [f32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError> {
        let idx = f.grid_index(sheet, u, v).map(|i| i as f32);
        let (footprint, center, area, exponent) = self.voxel(f, idx)?;
        let scale = match absorption {
            Absorption::Opacity => {
                let alpha = value[3];
                if alpha < 1.0 && exponent.is_finite() && exponent != 1.0 {
                    (1.0 - math::powf(1.0 - alpha, exponent)) / alpha
                } else {
                    1.0
                }
            }
            // Optical depth is linear in the distance.
            Absorption::Extinction if exponent.is_finite() => exponent,
            Absorption::Extinction => 1.0,
        };
        let value = value.map(|c| c * scale * area);
        let sampler = Direct {
            footprint,
            table: self.table,
            lookup: self.lookup,
        };
        Ok(splat_rows(
            &sampler,
            [center[0], center[1] - row0 as f32],
            &value,
            acc,
            touched,
        )?)
    }
}
