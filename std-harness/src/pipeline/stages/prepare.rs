//! A render set up and ready to run ([`Prepared`]): the volume, its frame for this view, the
//! transfer function and shading, the compositing order.
//!
//! View: `--view AZ,EL,ROLL` (degrees) builds V = zoom · Rz(roll) · Rx(el) · Ry(az): azimuth turns
//! the volume about the screen's vertical axis, elevation about its horizontal axis, roll about
//! the view direction. With AZ = EL = ROLL = 0 the viewer looks along +k with +i to the right and
//! +j down. The zoom that fits the volume's bounding box into 90 % of the image is multiplied by
//! `--zoom`. `--view-matrix` gives V (world → screen, pixels per world unit) explicitly instead.

use super::load::{load_background, load_voxels, Loaded, Voxels};
use super::supersample;
pub use super::window::outside_data_warnings;
use super::window::values_shading;
use crate::io::volume::Volume;
use crate::plan::{check_levels, Plan, Resolution, Supersample};
use crate::scene::Scene;
use crate::{tf, CliError};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::lod::{level_frame, level_kernel};
use footprint::shade::{Labels, Shader, Shading, TransferFunction};
use footprint::{Grid, Kernel, View};
use std::sync::Arc;

/// A render, set up and ready to run: the volume, the frame, the shading. A clone shares the
/// volume in memory.
#[derive(Clone)]
pub struct Prepared {
    pub voxels: Voxels,
    pub name: String,
    pub kernel: Kernel,
    /// The volume's grid at full resolution (voxel index → world).
    pub grid: Grid,
    /// The volume's dims at full resolution (`frame.dims` are the level's).
    pub fine_dims: [usize; 3],
    /// The level of detail rendered (0 = full resolution; see [`super::lod`]). A volume in
    /// memory is already coarsened to it; a streamed one is coarsened as it streams.
    pub level: u32,
    pub frame: FrameSetup,
    pub lut: Vec<[f32; 4]>,
    /// The window in the renderer's values (the data's through `voxels.values()`: the data's
    /// own units but for rebased wide samples; [`Prepared::data_window`] gives it in those).
    pub window: [f32; 2],
    pub shading: Shading,
    /// `--labels` in the renderer's values: the shader classifies by them instead of `lut`.
    pub labels: Option<Arc<[footprint::shade::Label]>>,
    pub tf_name: String,
    /// The background at the frame's (internal) size (shared with `background_out` when the
    /// frame is not supersampled).
    pub background: Option<Arc<[[f32; 4]]>>,
    /// The background at the output size, as loaded (shared by clones and subsampled frames).
    pub background_out: Option<Arc<[[f32; 4]]>>,
    pub order: Order,
    pub options: FootprintOptions,
    /// The frame is set up at `supersample` × the output size (see [`super::supersample`]).
    pub supersample: usize,
    /// The resolution chain the render was prepared with (its level aside): what
    /// [`Prepared::reframe`] and [`Prepared::at_level`] set a frame up with again.
    pub resolution: Resolution,
    /// The continuous model both slicings composite (`--absorption`).
    pub absorption: footprint::render::Absorption,
    /// The view at the output size (`--view`, `--zoom`, `--view-matrix`): what a subsampled
    /// frame scales.
    pub view: View,
    /// `--clip`: the half-spaces kept, world units (see [`Prepared::clip_planes`]).
    pub clip: Vec<crate::scene::ClipPlane>,
}

impl Prepared {
    /// The clipping planes in this frame's screen space, with its kernel's reach (empty without
    /// `--clip`); refused for a perspective frame or more planes than the core takes.
    pub fn clip_planes(&self) -> Result<footprint::render::clip::ClipPlanes, CliError> {
        let planes: Vec<[f32; 4]> = self.clip.iter().map(|c| c.in_screen(&self.frame)).collect();
        footprint::render::clip::ClipPlanes::new(&self.frame, self.kernel.spread(), &planes)
            .map_err(|e| CliError::input(format!("--clip: {e}")))
    }

    /// The window in the data's own units (as `--window` takes it and the JSON and the legend
    /// report it).
    pub fn data_window(&self) -> [f64; 2] {
        self.voxels.values().window_to_data(self.window)
    }

    /// The same volume, transfer function and shading seen with `args`' view (`--view`, `--zoom`,
    /// `--view-matrix`, `--size`): only the frame is set up again, nothing is loaded. The
    /// compositing order and the level of detail stay as prepared.
    pub fn reframe(&mut self, args: &Scene) -> Result<(), CliError> {
        let (frame, k, _) = setup_frame(
            args,
            self.resolution.at_level(self.level),
            self.fine_dims,
            &self.grid,
            &self.kernel,
            self.options,
        )?;
        self.frame = frame;
        self.view = view_for(args, self.fine_dims, &self.grid)?;
        self.supersample = k;
        self.background = at_frame(self.background_out.as_ref(), args.size, k);
        Ok(())
    }

    /// This volume (prepared at level 0, in memory or streamed from a file) at level `level` ≥ 1
    /// for `args`' view: that level's frame, supersampling, kernel and shading; a volume in memory
    /// coarsened from `from` (a shallower level of this volume, prepared by this function) when
    /// given, else from this one; a file coarsened as it streams, when rendered. Nothing is
    /// loaded again.
    pub fn at_level(
        &self,
        args: &Scene,
        level: u32,
        from: Option<&Prepared>,
    ) -> Result<Prepared, CliError> {
        let fine = match &self.voxels {
            Voxels::Memory(fine) => Some(fine),
            Voxels::File(_) => None,
            Voxels::Stdin { .. } => {
                return Err(CliError::input(
                    "a level of a pipe is built as it streams, not from a prepared one",
                ))
            }
        };
        if self.labels.is_some() {
            return Err(CliError::input(format!(
                "{}: a label volume renders level 0 alone (an average of labels names none)",
                self.name
            )));
        }
        if self.level != 0 || level == 0 {
            return Err(CliError::input(format!(
                "level {level} is built from level 0 (this is level {})",
                self.level
            )));
        }
        let (frame, supersample, _) = setup_frame(
            args,
            self.resolution.at_level(level),
            self.fine_dims,
            &self.grid,
            &self.kernel,
            self.options,
        )?;
        let kernel = kernel_at(args, &self.kernel, level);
        let min_spacing = frame.spacing.iter().copied().fold(f32::INFINITY, f32::min);
        let shading = args.shading.at_spacing(min_spacing);
        let averaging = super::lod::averaging_for(&shading, self.shader().tf, self.absorption);
        let voxels = match (fine, from) {
            (None, _) => self.voxels.clone(),
            (
                Some(_),
                Some(Prepared {
                    voxels: Voxels::Memory(v),
                    level: l @ 1..,
                    ..
                }),
            ) if *l < level => Voxels::Memory(Arc::new(super::lod::coarsen_volume(
                v,
                level - l,
                &*averaging,
            )?)),
            (Some(fine), _) => Voxels::Memory(Arc::new(super::lod::coarsen_volume(
                fine,
                level,
                &*averaging,
            )?)),
        };
        Ok(Prepared {
            voxels,
            name: self.name.clone(),
            kernel,
            grid: self.grid,
            fine_dims: self.fine_dims,
            level,
            frame,
            lut: self.lut.clone(),
            window: self.window,
            shading,
            labels: self.labels.clone(),
            tf_name: self.tf_name.clone(),
            background: at_frame(self.background_out.as_ref(), args.size, supersample),
            background_out: self.background_out.clone(),
            order: self.order,
            options: self.options,
            supersample,
            resolution: self.resolution,
            absorption: self.absorption,
            view: self.view,
            clip: self.clip.clone(),
        })
    }

    /// The `--subsample` factor `args` asks for with this render (1: off; see
    /// [`super::subsample::factor`], which refuses what cannot be honoured).
    pub fn subsample_factor(&self, plan: &Plan) -> Result<usize, CliError> {
        super::subsample::factor(
            &self.frame,
            &self.kernel,
            self.options,
            self.supersample,
            self.level,
            plan,
        )
    }

    /// This render (prepared at the output size) seen at 1/s of it, and `plan` for that frame
    /// (see [`super::subsample`]): the same volume (shared, not copied), transfer function and
    /// shading; the frame set up again with the view scaled by 1/s at
    /// [`super::subsample::low_size`]; no background (it is composited at the output size).
    pub fn subsampled(&self, plan: &Plan, s: usize) -> Result<(Prepared, Plan), CliError> {
        let view = View::new(self.view.to_screen() * (1.0 / s as f32))
            .map_err(|e| CliError::input(format!("--subsample {s}: view: {e}")))?;
        let (w, h) = super::subsample::low_size(self.out_size(), s);
        let frame = FrameSetup::new(
            self.fine_dims,
            &self.grid,
            &view,
            &self.kernel,
            self.options,
            [w, h],
        )?;
        let mut low = self.clone();
        low.frame = frame;
        low.view = view;
        low.background = None;
        low.background_out = None;
        let mut at_low = plan.clone();
        at_low.subsample = crate::plan::Supersample::Fixed(1);
        Ok((low, at_low))
    }

    /// The output image's width and height, pixels: the frame's, divided by the supersampling.
    pub fn out_size(&self) -> (usize, usize) {
        (
            self.frame.size[0] / self.supersample,
            self.frame.size[1] / self.supersample,
        )
    }

    /// The shader over this render's lookup table.
    pub fn shader(&self) -> Shader<'_> {
        Shader {
            labels: self.labels.as_deref().map(|entries| Labels { entries }),
            tf: TransferFunction {
                lut: &self.lut,
                lo: self.window[0],
                hi: self.window[1],
            },
            shading: self.shading,
        }
    }

    /// The volume, when it is in memory (not streamed).
    pub fn volume(&self) -> Option<&Volume> {
        match &self.voxels {
            Voxels::Memory(v) => Some(v),
            _ => None,
        }
    }
}

/// The view for `--view`/`--zoom` (VTK's camera fitted to a volume of `dims` on `grid`, the
/// core's [`View::from_vtk_camera`]) or `--view-matrix` (exactly as given).
pub fn view_for(args: &Scene, dims: [usize; 3], grid: &Grid) -> Result<View, CliError> {
    let view = match args.view_matrix {
        Some(m) => View::from_rows(m).map_err(|e| CliError::input(format!("--view-matrix: {e}"))),
        None => {
            let size = [args.size.0, args.size.1];
            View::from_vtk_camera(args.view, args.zoom, dims, grid, size).map_err(|e| {
                // Blame the flags only where they are at fault: if the same camera fits a grid
                // of unit spacing, the volume's own geometry (a spacing of 10³⁸, say, whose
                // extent f32 cannot hold) is what cannot be viewed.
                let unit = Grid::from_spacing([1.0; 3]);
                if unit.is_ok_and(|u| {
                    View::from_vtk_camera(args.view, args.zoom, dims, &u, size).is_ok()
                }) {
                    CliError::input(format!(
                        "the volume's grid cannot be viewed ({e}): its spacing makes a world \
                         extent too large or too small for f32 arithmetic; rescale the spacing \
                         (--spacing for raw data)"
                    ))
                } else {
                    CliError::input(format!("--view/--zoom: {e}"))
                }
            })
        }
    }?;
    Ok(view)
}

/// The kernel level `level` is reconstructed with: a narrower one for a coarser level (the core's
/// `lod::level_kernel`), unless `--table-file` fixes the table (and so the kernel) as given.
fn kernel_at(args: &Scene, kernel: &Kernel, level: u32) -> Kernel {
    if args.kernel.table_from_file {
        *kernel
    } else {
        level_kernel(kernel, level)
    }
}

/// The frame for `args`' view, at the output size or, when [`supersample::factor`] asks for it,
/// at k× that size (the view scaled by k, so the picture is the same); returns it and k.
/// With `--perspective` the frame is a pinhole's (`perspective_frame`).
///
/// `dims` and `grid` are the volume's at full resolution; the frame returned is that of the level
/// of detail `--lod` picks ([`super::lod`]), placed exactly where level 0 would be seen, and the
/// level is returned third.
pub fn setup_frame(
    args: &Scene,
    res: Resolution,
    dims: [usize; 3],
    grid: &Grid,
    kernel: &Kernel,
    options: FootprintOptions,
) -> Result<(FrameSetup, usize, u32), CliError> {
    check_levels(args, &res)?;
    let view = view_for(args, dims, grid)?;
    let size = [args.size.0, args.size.1];
    if let Some(fovy) = args.perspective {
        let (frame, k) = perspective_frame(
            args,
            res.supersample,
            fovy,
            &view,
            dims,
            grid,
            kernel,
            options,
        )?;
        return Ok((frame, k, 0));
    }
    let fine = FrameSetup::new(dims, grid, &view, kernel, options, size)?;
    let fixed_k = match res.supersample {
        crate::plan::Supersample::Fixed(k @ 2..) => Some(k),
        _ => None,
    };
    let level = match (res.refine, fixed_k) {
        // Refinement is for magnified volumes: it always starts from full resolution; so does
        // a frame supersampled on request.
        (true, _) | (false, Some(_)) => 0,
        (false, None) => super::lod::choose_level(res.lod, &fine, kernel),
    };
    let coarse_kernel = kernel_at(args, kernel, level);
    let at_level = |fine: &FrameSetup, view: &View| {
        level_frame(fine, grid, view, &coarse_kernel, options, level)
            .map_err(|e| CliError::input(format!("--lod {level}: {e}")))
    };
    let frame = at_level(&fine, &view)?;
    // Levels and supersampling never act on one frame: a coarser level is rendered at the
    // output size (its own error is what `--lod auto` validates, `crate::pipeline::quality::level_pilot`).
    let k = match level {
        0 => supersample::factor(res.supersample, &frame, options),
        _ => 1,
    };
    if k == 1 {
        return Ok((frame, 1, level));
    }
    let view = View::new(view.to_screen() * k as f32)
        .map_err(|e| CliError::input(format!("view: {e}")))?;
    let fine = FrameSetup::new(dims, grid, &view, kernel, options, size.map(|n| n * k))?;
    Ok((at_level(&fine, &view)?, k, level))
}

/// The perspective frame of `--perspective FOVY`: `view`'s rotation (its scale dropped), the eye
/// at `--eye-distance` or R / sin(FOVY/2) from the centre, focal length (H/2)/tan(FOVY/2) ×
/// `--zoom` pixels. Supersampling (`auto`) is decided by the farthest voxels, whose footprints
/// are the smallest.
#[allow(clippy::too_many_arguments)]
fn perspective_frame(
    args: &Scene,
    supersample: Supersample,
    fovy: f32,
    view: &View,
    dims: [usize; 3],
    grid: &Grid,
    kernel: &Kernel,
    options: FootprintOptions,
) -> Result<(FrameSetup, usize), CliError> {
    let size = [args.size.0, args.size.1];
    let m = view.to_screen();
    let rotation = m * (1.0 / m.row(0).length());
    let half = (fovy as f64).to_radians() * 0.5;
    let focal = (size[1] as f64 * 0.5) / half.tan() * f64::from(args.zoom);
    let distance = match args.eye_distance {
        Some(d) => f64::from(d),
        None => f64::from(footprint::geometry::bounding_radius(dims, grid)) / half.sin(),
    };
    let eye = distance as f32;
    // Focal length over eye distance is the view's scale at the centre, pixels per world unit:
    // out of f32's comfortable range the eye is inside the volume (or the volume vanishes).
    let scale = focal / distance;
    if !(scale.is_finite() && scale <= 1e12) {
        return Err(CliError::input(format!(
            "--perspective {fovy}: {scale:e} pixels per world unit at the volume's centre (focal \
             length {focal:e} px over the eye's distance {distance:e}): the eye is inside the volume \
             or --zoom is far too large"
        )));
    }
    if !(scale >= 1e-12 && eye.is_finite()) {
        return Err(CliError::input(format!(
            "--perspective {fovy}: the eye, {distance:e} world units from the volume's centre, is \
             so far away (or the focal length so short) that the volume projects to nothing"
        )));
    }
    let scaled = |k: f32| {
        View::new(rotation * (focal / distance) as f32 * k)
            .map_err(|e| CliError::input(format!("--perspective: {e}")))
    };
    let bad =
        |e: footprint::frame::FrameError| CliError::input(format!("--perspective {fovy}: {e}"));
    let frame = FrameSetup::perspective(dims, grid, &scaled(1.0)?, kernel, options, size, eye)
        .map_err(bad)?;
    // The farthest voxel-centre corner's magnification f/Z, relative to the centre's.
    let cam = frame.camera().copied().expect("a perspective frame");
    let far = footprint::geometry::box_corners(dims, 0.0)
        .into_iter()
        .map(|c| cam.focal_px + frame.affine_position(c.to_array()).z)
        .fold(0.0f32, f32::max);
    let shrink = cam.focal_px / far;
    let far_frame = FrameSetup::new(dims, grid, &scaled(shrink)?, kernel, options, size)?;
    let k = supersample::factor(supersample, &far_frame, options);
    if k == 1 {
        return Ok((frame, 1));
    }
    let frame = FrameSetup::perspective(
        dims,
        grid,
        &scaled(k as f32)?,
        kernel,
        options,
        size.map(|n| n * k),
        eye,
    )
    .map_err(bad)?;
    Ok((frame, k))
}

/// Loads and sets up everything `args` describes, with `--lod` taken as it is (`auto`: the
/// geometric rule of [`super::lod`]); [`crate::pipeline::entry::prepare`] validates that rule's level.
pub fn prepare_as_asked(args: &Scene, plan: &Plan) -> Result<Prepared, CliError> {
    let resolution = plan.resolution();
    let kernel = args.kernel.kernel;
    let Loaded {
        voxels,
        name,
        dims,
        grid,
        range,
        sample,
        labels: classified,
    } = load_voxels(args)?;
    let grid = Grid::from_matrix(grid).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    let options = args.kernel.options;
    // With --quality the volume is prepared at full resolution: the choice measures the levels
    // against it and builds the one it picks (`crate::pipeline::quality::choose`).
    let framing = if resolution.quality {
        resolution.at_level(0)
    } else {
        resolution
    };
    let (frame, supersample, level) = setup_frame(args, framing, dims, &grid, &kernel, options)?;
    let kernel = kernel_at(args, &kernel, level);

    let order = compositing_order(plan.order, &voxels, &frame)?;
    let tf_name = args.tf_name();
    let lut = tf::lut(&tf::load(&tf_name)?);
    let values = voxels.values();
    let labels = super::components::labels_of(classified.as_ref(), args, plan, &name, values)?;
    let window = match args.window {
        // A multi-component volume's windows are its components' (`super::components`).
        _ if classified.is_some() => [0.0, 1.0],
        Some(w) => super::window::check_given(w, values)?,
        None => super::window::default_window(&name, range, voxels.piped(), sample.as_deref())?,
    };
    let shading = values_shading(
        args.shading
            .at_spacing(frame.spacing.iter().copied().fold(f32::INFINITY, f32::min)),
        args.shading,
        values,
    );
    if let Some((lo, hi)) = range {
        let given = args.window.map(|_| window);
        for w in outside_data_warnings(&shading, given, (lo, hi)) {
            crate::warn!("{w}");
        }
    }
    // A coarser level of a volume in memory is built once, here; a streamed one as it streams.
    let voxels = match voxels {
        Voxels::Memory(v) if level > 0 => {
            let tf = TransferFunction {
                lut: &lut,
                lo: window[0],
                hi: window[1],
            };
            let averaging = super::lod::averaging_for(&shading, tf, args.absorption);
            Voxels::Memory(Arc::new(super::lod::coarsen_volume(
                &v,
                level,
                &*averaging,
            )?))
        }
        other => other,
    };
    let background_out: Option<Arc<[[f32; 4]]>> = args
        .background
        .file()
        .map(|p| load_background(p, args.size, args.gamma))
        .transpose()?
        .map(Into::into);
    let background = at_frame(background_out.as_ref(), args.size, supersample);
    Ok(Prepared {
        voxels,
        name,
        kernel,
        grid,
        fine_dims: dims,
        level,
        frame,
        lut,
        window,
        shading,
        labels,
        tf_name,
        background,
        background_out,
        order,
        options,
        supersample,
        resolution,
        absorption: args.absorption,
        view: view_for(args, dims, &grid)?,
        clip: args.clip.clone(),
    })
}

/// The compositing order: `--order`, back to front by default; from a pipe, the order its
/// file order gives (refused for a view whose sheets do not run along z, or an `--order` against
/// it).
fn compositing_order(
    asked: Option<Order>,
    voxels: &Voxels,
    frame: &FrameSetup,
) -> Result<Order, CliError> {
    Ok(match voxels {
        Voxels::Stdin { .. } => {
            if frame.sheet_axis != 2 {
                return Err(CliError::input(format!(
                    "standard input delivers z-slices in file order, but this view's sheets run along {}: \
                     only views looking within 45° of the z axis work from a pipe (for example --view 0,0,0, \
                     --view 180,0,0 or --view 30,20,0); stream a file to render any view",
                    ["x", "y", "z"][frame.sheet_axis]
                )));
            }
            let needed = frame.order_for_ascending();
            if let Some(asked) = asked {
                if asked != needed {
                    return Err(CliError::input(format!(
                        "from a pipe this view composites {needed:?} (file order runs {} the viewer); drop --order",
                        if frame.ascending_recedes { "away from" } else { "toward" }
                    )));
                }
            }
            needed
        }
        _ => asked.unwrap_or(Order::BackToFront),
    })
}

/// A background loaded at the output `size` as the frame needs it: the same image when the frame
/// is not supersampled (`k` = 1), else each pixel repeated k × k times.
fn at_frame(
    out: Option<&Arc<[[f32; 4]]>>,
    size: (usize, usize),
    k: usize,
) -> Option<Arc<[[f32; 4]]>> {
    out.map(|b| {
        if k == 1 {
            Arc::clone(b)
        } else {
            supersample::upsample(b, size, k).into()
        }
    })
}
