//! What is rendered ([`Scene`]): the volume's source and layout, the camera, classification and
//! shading, the picture's style, the kernel and the continuous model. One of the two typed values
//! a request is resolved into once (issue 76; the command line's resolution is
//! `crate::args::resolve`); the other, what draws it and at which resolution, is
//! `crate::plan::Plan`. Programs build a scene themselves. Nothing here is a flag's clap type.

use crate::io::image::{Background, Gamma};
use crate::CliError;
use footprint::geometry::FootprintOptions;
use footprint::render::Absorption;
use footprint::shade::{Phong, Shading};
use footprint::Kernel;
use std::path::PathBuf;

/// How the samples are lit (`--shading`), as a request gives it, before the volume is known:
/// what [`ShadingSpec::at_spacing`] completes into the core's [`Shading`] when the volume is
/// prepared. Phong's light and material are [`Phong::default`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadingSpec {
    /// The classified colour as it is (`emission`).
    Emission,
    /// Lit by the value's gradient (`phong`).
    Phong,
    /// Lit, with the gradient's magnitude scaling opacity (`texture`).
    Texture,
    /// An iso-surface at `value` (`iso:VALUE`), in the data's own units (f64, so a wide
    /// sample's value is exact), opacity 0.9, 1.5 × the volume's smallest spacing thick.
    Iso { value: f64 },
}

impl ShadingSpec {
    /// Parses `--shading`: `emission`, `phong`, `texture` or `iso:VALUE` (VALUE finite).
    pub fn parse(s: &str) -> Result<ShadingSpec, CliError> {
        Ok(match s {
            "emission" => ShadingSpec::Emission,
            "phong" => ShadingSpec::Phong,
            "texture" => ShadingSpec::Texture,
            _ => match s.strip_prefix("iso:").map(|v| v.trim().parse::<f64>()) {
                Some(Ok(value)) if value.is_finite() && (value as f32).is_finite() => {
                    ShadingSpec::Iso { value }
                }
                _ => {
                    return Err(CliError::input(format!(
                        "--shading '{s}': expected emission, phong, iso:VALUE or texture"
                    )))
                }
            },
        })
    }

    /// The core's shading for a volume whose smallest spacing is `min_spacing` (world units:
    /// an iso-surface is 1.5 × that thick); an iso value as f32, in the data's units (a wide
    /// volume's renderer values are `crate::pipeline::stages::window::values_shading`'s).
    pub fn at_spacing(self, min_spacing: f32) -> Shading {
        let phong = Phong::default();
        match self {
            ShadingSpec::Emission => Shading::Emission,
            ShadingSpec::Phong => Shading::Phong(phong),
            ShadingSpec::Texture => Shading::Texture(phong),
            ShadingSpec::Iso { value } => Shading::Iso {
                value: value as f32,
                opacity: 0.9,
                thickness: 1.5 * min_spacing,
                phong,
            },
        }
    }
}

impl std::fmt::Display for ShadingSpec {
    /// As `--shading` spells it (an iso value in Rust's shortest form: `iso:0.5`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ShadingSpec::Emission => f.write_str("emission"),
            ShadingSpec::Phong => f.write_str("phong"),
            ShadingSpec::Texture => f.write_str("texture"),
            ShadingSpec::Iso { value } => write!(f, "iso:{value}"),
        }
    }
}

/// The kernel and how its footprints are shaped: what `--kernel`, `--method paper`'s
/// `--paper-cheat`, `--min-radius` and `--table-file` resolve to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KernelModel {
    /// The reconstruction kernel at full resolution.
    pub kernel: Kernel,
    /// The ellipse-to-circle map and the smallest footprint semi-axis, pixels.
    pub options: FootprintOptions,
    /// The generic table is loaded from a file made for [`KernelModel::kernel`]
    /// (`--table-file`): coarser levels keep that kernel instead of narrowing it.
    pub table_from_file: bool,
}

/// What a render loads and how it sees it: the volume and its layout, classification, camera,
/// picture, kernel and continuous model. The pipeline prepares from a scene and a plan
/// (`crate::pipeline::prepare()`) and never reads the command-line struct.
///
/// Units and conventions: world = G·(i, j, k) with the volume's centre at the origin (G from
/// the file's spacing or directions, or [`Scene::spacing`] for raw files); `view` is VTK's
/// azimuth, elevation and roll, degrees; `size` is pixels, (width, height).
#[derive(Clone, Debug)]
pub struct Scene {
    /// A volume already in memory (set by a program, such as the Python package).
    pub memory: Option<crate::io::stream::InMemory>,
    /// What `--stream -` reads instead of standard input.
    pub stdin: Option<crate::io::stream::Pipe>,
    /// The volume file; `None`: the built-in scene.
    pub volume: Option<PathBuf>,
    /// `--stream FILE|-`.
    pub stream: Option<PathBuf>,
    /// Raw layout: `--dims`, `--type`, `--endian`, `--spacing`; `--array`.
    pub dims: Option<[usize; 3]>,
    pub sample_type: Option<crate::io::volume::SampleType>,
    pub big_endian: bool,
    pub spacing: [f32; 3],
    pub array: Option<String>,
    /// The built-in scene's grid, and its finer field's (`--reference field`).
    pub scene_size: usize,
    pub field_size: usize,
    /// Output size, pixels (width, height).
    pub size: (usize, usize),
    /// Camera: VTK's azimuth, elevation, roll (degrees), zoom, an explicit matrix, perspective.
    pub view: [f32; 3],
    pub zoom: f32,
    pub view_matrix: Option<[f32; 9]>,
    pub perspective: Option<f32>,
    pub eye_distance: Option<f32>,
    /// Classification: every `--tf` (a built-in name or a file, read when the volume is
    /// prepared; one per component of a multi-component volume; none: the default for the
    /// source), `--window` (data units), `--shading`.
    pub tfs: Vec<String>,
    pub window: Option<[f64; 2]>,
    pub shading: ShadingSpec,
    /// `--labels`: a label volume's table (samples classified by label instead of `tf`).
    pub labels: Option<crate::tf::labels::LabelTable>,
    /// Picture: background, gamma, PNG depth.
    pub background: Background,
    pub gamma: Gamma,
    pub depth: u8,
    /// The kernel and its footprints' shape.
    pub kernel: KernelModel,
    /// The continuous model every end composites.
    pub absorption: Absorption,
    /// `--crop`: only the voxels of this box are rendered (the rest are missing samples).
    pub crop: Option<Crop>,
    /// `--clip`: the half-spaces kept (every one of them), world units.
    pub clip: Vec<ClipPlane>,
}

/// `--clip NX,NY,NZ,D`: the world points x with n·x ≤ D are kept, in world units with the
/// volume's centre (the centre of its voxel-centre box) at the origin. The continuous model is
/// multiplied by the kept region's indicator; a kernel a plane crosses is cut where the plane
/// crosses each ray (`footprint::render::clip`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipPlane {
    /// n (any length but zero).
    pub normal: [f64; 3],
    /// D, world units times |n|.
    pub offset: f64,
}

impl ClipPlane {
    /// The plane n·x ≤ D, refused unless n is finite and not zero and D finite.
    pub fn new(normal: [f64; 3], offset: f64) -> Result<ClipPlane, String> {
        if !normal.iter().chain([&offset]).all(|x| x.is_finite()) {
            return Err(format!("{normal:?}, {offset}: every number must be finite"));
        }
        if normal.iter().all(|&x| x == 0.0) {
            return Err("the normal NX,NY,NZ is zero: it must give a direction".into());
        }
        Ok(ClipPlane { normal, offset })
    }

    /// The plane in `frame`'s grid (voxel index units): (m, e) with m·g ≤ e kept, m = Gᵀn and
    /// e = D + m·c (G grid to world, c the centre of the frame's voxel-centre box).
    pub fn in_grid(&self, frame: &footprint::frame::FrameSetup) -> ([f64; 3], f64) {
        let g = frame
            .grid_inverse_transpose
            .as_dmat3()
            .inverse()
            .transpose();
        let m = g.transpose() * glam::DVec3::from_array(self.normal);
        let c = glam::DVec3::from_array(frame.dims.map(|n| (n as f64 - 1.0) / 2.0));
        (m.to_array(), self.offset + m.dot(c))
    }

    /// The plane in `frame`'s screen space (pixels; z the depth along the view): [a, b, c, d]
    /// with a·x + b·y + c·z ≤ d kept, for `footprint::render::clip::ClipPlanes` (orthographic frames:
    /// screen = origin + M·g, so (a, b, c) = M⁻ᵀm and d = e + (a, b, c)·origin).
    pub fn in_screen(&self, frame: &footprint::frame::FrameSetup) -> [f32; 4] {
        let (m, e) = self.in_grid(frame);
        let inv_t = frame.grid_to_screen.as_dmat3().inverse().transpose();
        let n = inv_t * glam::DVec3::from_array(m);
        let d = e + n.dot(frame.origin.as_dvec3());
        [n.x as f32, n.y as f32, n.z as f32, d as f32]
    }
}

impl std::fmt::Display for ClipPlane {
    /// As `--clip` takes it: `NX,NY,NZ,D`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.normal;
        write!(f, "{x},{y},{z},{}", self.offset)
    }
}

/// `--crop X0:X1,Y0:Y1,Z0:Z1`: a box of voxel indices, inclusive at both ends, along i, j, k.
///
/// The cropped volume is the volume whose samples outside the box are missing (NaN: weight zero,
/// transparent), so the renderer splats only the box's voxels and the continuous model
/// (`crate::reference::continuous`) integrates only their kernels; the voxels keep their places
/// (the frame, the window and the default transfer function are the whole volume's). A kept
/// voxel next to the cut takes its gradient from its kept neighbours (a missing neighbour stands
/// in as the voxel's own value). Held in memory as a brick ([`crate::io::brick`]) of the box's
/// samples alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop(pub [[usize; 2]; 3]);

impl Crop {
    /// The box of inclusive ranges `ranges` (i, j, k), each `[first, last]` with first ≤ last
    /// (an empty range is refused: a crop keeping nothing is a mistake, not a picture).
    pub fn new(ranges: [[usize; 2]; 3]) -> Result<Crop, String> {
        for (c, [lo, hi]) in ranges.iter().enumerate() {
            if lo > hi {
                return Err(format!(
                    "{} range {lo}:{hi} is empty (give FIRST:LAST with FIRST <= LAST)",
                    ["X", "Y", "Z"][c]
                ));
            }
        }
        Ok(Crop(ranges))
    }

    /// The box as half-open indices, checked against a volume of `dims` voxels: every range
    /// must lie inside the volume.
    pub fn index_box(&self, dims: [usize; 3]) -> Result<crate::io::brick::IndexBox, CliError> {
        for (c, [lo, hi]) in self.0.iter().enumerate() {
            if *hi >= dims[c] {
                return Err(CliError::input(format!(
                    "--crop: {} range {lo}:{hi} reaches past the volume, whose {} voxels along {} \
                     are indexed 0:{}",
                    ["X", "Y", "Z"][c],
                    dims[c],
                    ["i", "j", "k"][c],
                    dims[c].saturating_sub(1)
                )));
            }
        }
        Ok(crate::io::brick::IndexBox {
            lo: self.0.map(|r| r[0]),
            hi: self.0.map(|r| r[1] + 1),
        })
    }
}

impl std::fmt::Display for Crop {
    /// As `--crop` takes it: `X0:X1,Y0:Y1,Z0:Z1`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.0;
        write!(f, "{}:{},{}:{},{}:{}", x[0], x[1], y[0], y[1], z[0], z[1])
    }
}

impl Scene {
    /// This scene turned `degrees` of azimuth further about the volume's vertical axis: the
    /// view's azimuth plus `degrees`, or a view matrix V as V · Ry(degrees) (the same turn); the
    /// rest unchanged. What `render --orbit` and `bench --orbit` step by.
    pub fn turned(&self, degrees: f32) -> Scene {
        let mut s = self.clone();
        s.view[0] += degrees;
        if let Some(m) = s.view_matrix {
            let v = glam::Mat3::from_cols_array(&m).transpose()
                * glam::Mat3::from_rotation_y(degrees.to_radians());
            s.view_matrix = Some(v.transpose().to_cols_array());
        }
        s
    }
}

impl Scene {
    /// The transfer function this scene renders with: the first `--tf`, else `density` for the
    /// built-in scene and `ct-bone-skin` for a user's volume (transparent below the default
    /// window's first 18 %: see `crate::pipeline::stages::window`).
    pub fn tf_name(&self) -> String {
        self.tfs.first().cloned().unwrap_or_else(|| {
            if self.volume.is_none() && self.stream.is_none() && self.memory.is_none() {
                "density"
            } else {
                "ct-bone-skin"
            }
            .into()
        })
    }
}

impl Default for Scene {
    /// The scene `footprint render` resolves with no flags: the built-in volume (64³), 512 × 512
    /// pixels seen from the front (VTK's azimuth, elevation and roll 0), zoom 1, orthographic,
    /// its default transfer function and window, emission shading, black background, linear
    /// 8-bit PNG, the paper's Gaussian (spread 1.6, 2.5 σ) with the robust map and the default
    /// minimum radius, the opacity model, uncropped and unclipped (`tests/door.rs` checks it against the command line's).
    fn default() -> Scene {
        Scene {
            memory: None,
            stdin: None,
            volume: None,
            stream: None,
            dims: None,
            sample_type: None,
            big_endian: false,
            spacing: [1.0; 3],
            array: None,
            scene_size: crate::builtin::SIDE,
            field_size: 128,
            size: (512, 512),
            view: [0.0; 3],
            zoom: 1.0,
            view_matrix: None,
            perspective: None,
            eye_distance: None,
            tfs: Vec::new(),
            window: None,
            shading: ShadingSpec::Emission,
            labels: None,
            background: Background::Black,
            gamma: Gamma::Linear,
            depth: 8,
            kernel: KernelModel {
                kernel: Kernel::parse(DEFAULT_KERNEL).expect("the default kernel parses"),
                options: FootprintOptions {
                    mapping: footprint::geometry::Mapping::Robust,
                    min_radius_px: footprint::geometry::DEFAULT_MIN_RADIUS_PX,
                },
                table_from_file: false,
            },
            absorption: Absorption::Opacity,
            crop: None,
            clip: Vec::new(),
        }
    }
}

/// The default kernel spec (`--kernel`'s default): the paper's Gaussian.
pub const DEFAULT_KERNEL: &str = "gaussian:spread=1.6,sigmas=2.5";
