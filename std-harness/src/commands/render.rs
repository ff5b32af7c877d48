//! `footprint render`: a volume (or the built-in scene) rendered by the core, sheet by sheet.
//!
//! View: `--view AZ,EL,ROLL` (degrees) builds V = zoom · Rz(roll) · Rx(el) · Ry(az): azimuth turns
//! the volume about the screen's vertical axis, elevation about its horizontal axis, roll about
//! the view direction. With AZ = EL = ROLL = 0 the viewer looks along +k with +i to the right and
//! +j down. The zoom that fits the volume's bounding box into 90 % of the image is multiplied by
//! `--zoom`. `--view-matrix` gives V (world → screen, pixels per world unit) explicitly instead.

use crate::cli::{parse_list, parse_size, AccumArg, FootprintArgs, MethodArg};
use crate::io::formats::{self, raw::RawOptions};
use crate::io::image::encode_png_rgb;
use crate::io::stream::{file_range, is_stdin, FileSource, Layout, MemorySource, PipeSource};
use crate::io::volume::{SampleType, Volume};
use crate::io::{self, json::Json};
use crate::reference::render::{render_reference, ReferenceScene};
use crate::{scene, tf, with_table_size, CliError};
use clap::{Args, ValueEnum};
use footprint::fixed::{self, FixedTable};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::render::{
    FixedPath, FloatPath, Precision, RenderBuffers, RenderStats, SheetRenderer, SheetRing,
};
use footprint::shade::{Phong, Shader, Shading, TransferFunction};
use footprint::source::{render_from, SheetSource};
use footprint::splat::Direct;
use footprint::{composite::RowSpan, Grid, Kernel, Lookup, View, ViewTable};
use glam::{Mat3, Vec3};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

/// Compositing direction on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OrderArg {
    /// Farthest sheet first, composited over (the paper's order).
    BackToFront,
    /// Nearest sheet first, composited under.
    FrontToBack,
}

impl From<OrderArg> for Order {
    fn from(o: OrderArg) -> Self {
        match o {
            OrderArg::BackToFront => Order::BackToFront,
            OrderArg::FrontToBack => Order::FrontToBack,
        }
    }
}

/// Every flag of `render` (and of `verify`, which takes them all).
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Volume: .nrrd/.nhdr, .vti, .vtk, .mhd/.mha, .nii/.nii.gz, or headerless raw with --dims and
    /// --type. Omitted: the built-in electron-density scene.
    pub volume: Option<PathBuf>,
    /// Image size, WxH pixels.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    pub size: (usize, usize),
    /// View angles AZ,EL,ROLL in degrees (see the module docs).
    #[arg(long, default_value = "0,0,0", value_parser = parse_list::<3>, allow_hyphen_values = true)]
    pub view: [f32; 3],
    /// Multiplies the zoom that fits the volume into the image.
    #[arg(long, default_value_t = 1.0)]
    pub zoom: f32,
    /// Explicit world-to-screen matrix, nine numbers row-major, pixels per world unit (overrides
    /// --view and --zoom).
    #[arg(long, value_parser = parse_list::<9>, allow_hyphen_values = true)]
    pub view_matrix: Option<[f32; 9]>,
    /// Kernel, tables, lookup, method (`reference` renders with the f64 reference) and minimum
    /// footprint radius.
    #[command(flatten)]
    pub footprint: FootprintArgs,
    /// Accumulation: float, or fixed (integer splat, accumulator and compositing; bit-exact).
    #[arg(long, value_enum, default_value_t = AccumArg::Float)]
    pub accum: AccumArg,
    /// Target PSNR against the f64 reference, dB: choose the cheapest table size, lookup, method
    /// and accumulation predicted to reach it for this scene and view (overrides those flags).
    #[arg(long, conflicts_with_all = ["table", "lookup", "method", "accum", "table_file"])]
    pub quality: Option<f64>,
    /// Transfer function: a preset (grey, ct-bone-skin, density) or a file of `t r g b a` lines.
    /// Default: density for the built-in scene, grey otherwise.
    #[arg(long)]
    pub tf: Option<String>,
    /// Value window LO,HI mapped onto the transfer function (default: the data's range).
    #[arg(long, value_parser = parse_list::<2>, allow_hyphen_values = true)]
    pub window: Option<[f32; 2]>,
    /// Shading: emission, phong, iso:VALUE (Levoy iso-surface at VALUE, data units), texture.
    #[arg(long, default_value = "emission")]
    pub shading: String,
    /// Starting working image (PNG of the output size), composited behind the volume.
    #[arg(long)]
    pub background: Option<PathBuf>,
    /// Compositing direction (default back-to-front; a pipe's views impose theirs).
    #[arg(long, value_enum)]
    pub order: Option<OrderArg>,
    /// Stream the volume a few sheets at a time instead of loading it: a raw file (with --dims and
    /// --type), an NRRD with raw encoding or an uncompressed MetaImage; `-` reads raw z-slices from
    /// standard input in file order (needs --dims and --type).
    #[arg(long)]
    pub stream: Option<PathBuf>,
    /// Write a JSON summary here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Raw volumes: dimensions X,Y,Z.
    #[arg(long, value_parser = parse_dims)]
    pub dims: Option<[usize; 3]>,
    /// Raw volumes: sample type (u8, i8, u16, i16, u32, i32, f32, f64).
    #[arg(long = "type")]
    pub sample_type: Option<String>,
    /// Raw volumes: byte order.
    #[arg(long, default_value = "little")]
    pub endian: String,
    /// Raw volumes: spacing X,Y,Z in world units.
    #[arg(long, default_value = "1,1,1", value_parser = parse_list::<3>)]
    pub spacing: [f32; 3],
    /// Output image (PNG). `render` defaults to footprint.png; `verify` writes one only if asked.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 3 {
        return Err("expected X,Y,Z".into());
    }
    let mut out = [0usize; 3];
    for (o, p) in out.iter_mut().zip(v) {
        *o = p
            .trim()
            .parse()
            .map_err(|_| format!("'{p}' is not a whole number"))?;
    }
    Ok(out)
}

/// `render`'s flags from a list of arguments (as on the command line after `render`), for
/// programs that drive the harness (benches, charts).
pub fn parse_args(args: &[&str]) -> Result<RenderArgs, CliError> {
    #[derive(clap::Parser)]
    struct Wrapper {
        #[command(flatten)]
        render: RenderArgs,
    }
    use clap::Parser as _;
    Wrapper::try_parse_from(std::iter::once("render").chain(args.iter().copied()))
        .map(|w| w.render)
        .map_err(|e| CliError::input(e.to_string()))
}

/// Parses `--shading`; iso-surfaces are `1.5 × min_spacing` thick (world units).
pub fn parse_shading(s: &str, min_spacing: f32) -> Result<Shading, CliError> {
    let phong = Phong::default();
    Ok(match s {
        "emission" => Shading::Emission,
        "phong" => Shading::Phong(phong),
        "texture" => Shading::Texture(phong),
        _ => match s.strip_prefix("iso:").map(str::parse::<f32>) {
            Some(Ok(value)) if value.is_finite() => Shading::Iso {
                value,
                opacity: 0.9,
                thickness: 1.5 * min_spacing,
                phong,
            },
            _ => {
                return Err(CliError::input(format!(
                    "--shading '{s}': expected emission, phong, iso:VALUE or texture"
                )))
            }
        },
    })
}

/// A render, set up and ready to run: the volume, the frame, the shading.
pub struct Prepared {
    pub voxels: Voxels,
    pub name: String,
    pub kernel: Kernel,
    pub frame: FrameSetup,
    pub lut: Vec<[f32; 4]>,
    pub window: [f32; 2],
    pub shading: Shading,
    pub tf_name: String,
    pub background: Option<Vec<[f32; 4]>>,
    pub order: Order,
    pub options: FootprintOptions,
}

impl Prepared {
    /// The shader over this render's lookup table.
    pub fn shader(&self) -> Shader<'_> {
        Shader {
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

/// Where the voxels come from.
pub enum Voxels {
    /// Loaded whole.
    Memory(Volume),
    /// Streamed from a seekable file.
    File(Layout),
    /// Streamed from standard input, z-slices in file order.
    Stdin {
        dims: [usize; 3],
        ty: SampleType,
        big_endian: bool,
    },
}

/// V for `--view`/`--zoom` (fitted to a volume of `dims` on grid `g`) or `--view-matrix`.
pub fn view_matrix(args: &RenderArgs, dims: [usize; 3], g: Mat3) -> Mat3 {
    if let Some(m) = args.view_matrix {
        return Mat3::from_cols_array(&m).transpose();
    }
    let [az, el, roll] = args.view.map(f32::to_radians);
    let r = Mat3::from_rotation_z(roll) * Mat3::from_rotation_x(el) * Mat3::from_rotation_y(az);
    // Half-extents on screen of the volume's box (voxel centres ± half a voxel), in world space
    // through its grid-to-world matrix.
    let half = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32) * 0.5;
    let mut ext = Vec3::ZERO;
    for corner in 0..8 {
        let c = Vec3::new(
            if corner & 1 == 0 { -half.x } else { half.x },
            if corner & 2 == 0 { -half.y } else { half.y },
            if corner & 4 == 0 { -half.z } else { half.z },
        );
        ext = ext.max((r * (g * c)).abs());
    }
    let (w, h) = (args.size.0 as f32, args.size.1 as f32);
    let fit = 0.9 * (w / (2.0 * ext.x)).min(h / (2.0 * ext.y));
    r * (fit * args.zoom)
}

/// The raw-file options from `--dims`, `--type`, `--endian`, `--spacing`, if `--dims` was given.
pub fn raw_options(args: &RenderArgs) -> Result<Option<RawOptions>, CliError> {
    let Some(dims) = args.dims else {
        return Ok(None);
    };
    let ty = args
        .sample_type
        .as_deref()
        .ok_or_else(|| CliError::input("raw volumes need --type"))?;
    let ty = SampleType::parse(ty).ok_or_else(|| {
        CliError::input(format!(
            "--type '{ty}' is not a sample type (u8, i8, u16, i16, u32, i32, f32, f64)"
        ))
    })?;
    let big_endian = match args.endian.as_str() {
        "little" => false,
        "big" => true,
        e => {
            return Err(CliError::input(format!(
                "--endian '{e}': expected little or big"
            )))
        }
    };
    Ok(Some(RawOptions {
        dims,
        ty,
        big_endian,
        spacing: args.spacing,
    }))
}

/// What `prepare` learns about the voxels before rendering.
struct Loaded {
    voxels: Voxels,
    name: String,
    dims: [usize; 3],
    grid: Mat3,
    /// The data's finite range, if it could be read without a second pass over a pipe.
    range: Option<(f32, f32)>,
}

fn load_voxels(args: &RenderArgs) -> Result<Loaded, CliError> {
    let raw = raw_options(args)?;
    let Some(stream) = &args.stream else {
        let (volume, name) = match &args.volume {
            Some(path) => (
                formats::load(path, raw.as_ref())?,
                path.display().to_string(),
            ),
            None => (
                scene::default_volume(),
                "built-in electron-density scene".to_string(),
            ),
        };
        let (dims, grid, range) = (volume.dims, volume.grid_to_world(), Some(volume.range()));
        return Ok(Loaded {
            voxels: Voxels::Memory(volume),
            name,
            dims,
            grid,
            range,
        });
    };
    if args.volume.is_some() {
        return Err(CliError::input(
            "give the volume either as VOLUME or with --stream, not both",
        ));
    }
    let name = stream.display().to_string();
    if is_stdin(stream) {
        let o = raw.ok_or_else(|| {
            CliError::input("--stream - (standard input) needs --dims and --type")
        })?;
        crate::io::volume::byte_len(o.dims, o.ty)
            .map_err(|e| CliError::input(format!("standard input: {e}")))?;
        crate::io::volume::check_spacing(o.spacing)
            .map_err(|e| CliError::input(format!("standard input: {e}")))?;
        let grid = Mat3::from_diagonal(Vec3::from_array(o.spacing));
        let voxels = Voxels::Stdin {
            dims: o.dims,
            ty: o.ty,
            big_endian: o.big_endian,
        };
        return Ok(Loaded {
            voxels,
            name: "standard input".into(),
            dims: o.dims,
            grid,
            range: None,
        });
    }
    let lower = name.to_ascii_lowercase();
    let (layout, spacing, directions) = if let Some(o) = &raw {
        let layout = Layout {
            path: stream.clone(),
            offset: 0,
            dims: o.dims,
            ty: o.ty,
            big_endian: o.big_endian,
        };
        crate::io::volume::check_spacing(o.spacing)
            .map_err(|e| crate::io::volume::at(stream, e))?;
        (layout, o.spacing, crate::io::volume::AXIS_ALIGNED)
    } else if lower.ends_with(".nrrd") || lower.ends_with(".nhdr") {
        let s = formats::nrrd::raw_layout(stream)?;
        (s.layout, s.spacing, s.directions)
    } else if lower.ends_with(".mha") || lower.ends_with(".mhd") {
        let s = formats::metaimage::raw_layout(stream)?;
        (s.layout, s.spacing, s.directions)
    } else {
        return Err(crate::io::volume::at(stream, "streaming reads raw files (with --dims and --type), NRRD with raw encoding, or uncompressed MetaImage"));
    };
    let file_len = std::fs::metadata(&layout.path)
        .map_err(|e| crate::io::volume::at(&layout.path, format!("cannot read: {e}")))?
        .len();
    let need = crate::io::volume::byte_len(layout.dims, layout.ty)
        .map_err(|e| crate::io::volume::at(&layout.path, e))? as u64;
    if raw.is_some() && file_len != need {
        return Err(crate::io::volume::at(
            &layout.path,
            format!("expected {need} bytes for --dims/--type, found {file_len}"),
        ));
    }
    let col = |c: usize| Vec3::from_array(directions[c]) * spacing[c];
    let grid = Mat3::from_cols(col(0), col(1), col(2));
    let range = if args.window.is_none() {
        Some(file_range(&layout)?)
    } else {
        None
    };
    Ok(Loaded {
        dims: layout.dims,
        voxels: Voxels::File(layout),
        name,
        grid,
        range,
    })
}

fn load_background(
    path: &std::path::Path,
    size: (usize, usize),
) -> Result<Vec<[f32; 4]>, CliError> {
    let bytes = io::read_file(path)?;
    let img = crate::io::image::decode_png_rgba(&bytes, &path.display().to_string())?;
    if (img.0, img.1) != size {
        return Err(CliError::input(format!(
            "{}: background is {}x{}, the image is {}x{}",
            path.display(),
            img.0,
            img.1,
            size.0,
            size.1
        )));
    }
    Ok(img.2)
}

/// Loads and sets up everything `args` describes.
pub fn prepare(args: &RenderArgs) -> Result<Prepared, CliError> {
    let kernel = args.footprint.kernel()?;
    let Loaded {
        voxels,
        name,
        dims,
        grid,
        range,
    } = load_voxels(args)?;
    let grid = Grid::from_matrix(grid).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    let view = View::new(view_matrix(args, dims, grid.to_world()))
        .map_err(|e| CliError::input(format!("view: {e}")))?;
    let mapping = args.footprint.mapping()?;
    let options = FootprintOptions {
        mapping,
        min_radius_px: args.footprint.min_radius,
    };
    let frame = FrameSetup::new(
        dims,
        &grid,
        &view,
        &kernel,
        options,
        [args.size.0, args.size.1],
    )?;
    let order = match &voxels {
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
            if let Some(asked) = args.order.map(Order::from) {
                if asked != needed {
                    return Err(CliError::input(format!(
                        "from a pipe this view composites {needed:?} (file order runs {} the viewer); drop --order",
                        if frame.ascending_recedes { "away from" } else { "toward" }
                    )));
                }
            }
            needed
        }
        _ => args.order.map_or(Order::BackToFront, Order::from),
    };
    let tf_name = args.tf.clone().unwrap_or_else(|| {
        if args.volume.is_none() && args.stream.is_none() {
            "density"
        } else {
            "grey"
        }
        .into()
    });
    let lut = tf::lut(&tf::load(&tf_name)?);
    let window = match args.window {
        Some(w) => w,
        None => {
            let (lo, hi) = match (range, &voxels) {
                (Some(r), _) => r,
                (
                    None,
                    Voxels::Stdin {
                        ty: SampleType::U8, ..
                    },
                ) => (0.0, 255.0),
                (
                    None,
                    Voxels::Stdin {
                        ty: SampleType::I8, ..
                    },
                ) => (-128.0, 127.0),
                (None, _) => {
                    return Err(CliError::input(
                        "standard input cannot be read twice: give --window LO,HI",
                    ))
                }
            };
            if !(hi > lo) {
                return Err(CliError::input(format!(
                    "{name}: the data are constant ({lo}); give --window"
                )));
            }
            [lo, hi]
        }
    };
    if !(window[1] > window[0]) {
        return Err(CliError::input(format!(
            "--window {},{}: HI must exceed LO",
            window[0], window[1]
        )));
    }
    let shading = parse_shading(
        &args.shading,
        frame.spacing.iter().copied().fold(f32::INFINITY, f32::min),
    )?;
    let background = args
        .background
        .as_ref()
        .map(|p| load_background(p, args.size))
        .transpose()?;
    Ok(Prepared {
        voxels,
        name,
        kernel,
        frame,
        lut,
        window,
        shading,
        tf_name,
        background,
        order,
        options,
    })
}

/// `args` with `--quality`'s choice applied (unchanged without `--quality`), and the choice.
pub fn apply_quality(
    p: &Prepared,
    args: &RenderArgs,
) -> Result<(RenderArgs, Option<crate::quality::Choice>), CliError> {
    let Some(q) = args.quality else {
        return Ok((args.clone(), None));
    };
    let choice = crate::quality::choose(p, q)?;
    let e = p.frame.footprint.half_extent;
    crate::say!("{}", choice.explain(2.0 * e[0].max(e[1])));
    let mut chosen = choice.config.apply(args);
    chosen.quality = None;
    Ok((chosen, Some(choice)))
}

/// The JSON record of a `--quality` choice.
pub fn quality_json(c: &crate::quality::Choice) -> Json {
    Json::object()
        .num("target_db", c.target_db)
        .num("predicted_db", c.predicted_db)
        .num("footprint_error", c.footprint_error)
        .num("k_db", crate::quality::K_DB)
        .str("chosen", &c.config.label())
}

/// Shows `sheet n/N` on stderr when it is a terminal.
pub fn progress(label: &'static str) -> impl FnMut(usize, usize) {
    let tty = std::io::stderr().is_terminal();
    move |n, total| {
        if tty {
            use std::io::Write as _;
            let end = if n == total { "\n" } else { "" };
            let _ = write!(
                std::io::stderr().lock(),
                "\r{label}: sheet {n}/{total}{end}"
            );
        }
    }
}

/// The core's render of `p` with `args`' table, method and accumulation: premultiplied RGBA
/// (fixed-point output converted exactly to f32), counts, seconds.
pub fn render_core(
    p: &Prepared,
    args: &RenderArgs,
) -> Result<(Vec<[f32; 4]>, RenderStats, f64), CliError> {
    render_core_with(p, args, args.accum)
}

/// [`render_core`] with the accumulation given explicitly.
pub fn render_core_with(
    p: &Prepared,
    args: &RenderArgs,
    accum: AccumArg,
) -> Result<(Vec<[f32; 4]>, RenderStats, f64), CliError> {
    let fa = &args.footprint;
    let lookup = Lookup::from(fa.lookup);
    let fixed_range =
        |e: fixed::FixedError| CliError::input(format!("{}: --accum fixed: {e}", p.name));
    with_table_size!(fa.table, N => {
        let generic = fa.generic_table::<N>(&p.kernel)?;
        let start = Instant::now();
        // Each path gets its own monomorphised sheet loop: no virtual call per pixel.
        let (image, stats) = match (accum, fa.method) {
            (AccumArg::Float, MethodArg::Direct) => {
                let sampler = Direct { footprint: p.frame.footprint, table: &*generic, lookup };
                run_sheets(p, FloatPath { sampler: &sampler }, p.background.as_deref())?
            }
            (AccumArg::Float, _) => {
                let table = Box::new(ViewTable::<N>::build(&p.frame.footprint, &generic, lookup, lookup));
                run_sheets(p, FloatPath { sampler: &*table }, p.background.as_deref())?
            }
            (AccumArg::Fixed, method) => {
                let mut table = Box::new(FixedTable::<N>::zeroed());
                match method {
                    MethodArg::Direct => table.build_direct(&p.frame, &generic, lookup),
                    _ => table.build_view(&p.frame, &generic, lookup, lookup),
                }
                .map_err(fixed_range)?;
                let path = FixedPath::new(&p.frame, &*table).map_err(fixed_range)?;
                let bg: Option<Vec<[u32; 4]>> =
                    p.background.as_ref().map(|b| b.iter().map(|&c| fixed::quantise(c)).collect());
                let (img, stats) = run_sheets(p, path, bg.as_deref())?;
                (img.into_iter().map(fixed::to_f32).collect(), stats)
            }
        };
        (image, stats, start.elapsed().as_secs_f64())
    })
}

/// Drives the core renderer through a [`SheetRing`], as a streaming source would.
fn run_sheets<P: Precision>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
) -> Result<(Vec<P::Pixel>, RenderStats), CliError> {
    let f = &p.frame;
    let n = f.image_len();
    let (mut accum, mut image, mut rows) = (
        vec![P::ACC_ZERO; n],
        vec![P::CLEAR; n],
        vec![RowSpan::EMPTY; f.size[1]],
    );
    let buffers = RenderBuffers {
        accumulator: &mut accum,
        image: &mut image,
        rows: &mut rows,
    };
    let mut renderer = SheetRenderer::with_path(f, path, p.shader(), p.order, buffers, background)?;
    let mut storage = vec![0.0f32; 3 * f.sheet_shape().0];
    let mut ring = SheetRing::new(&mut storage, f, p.order)?;
    let mut show = Progress {
        inner: progress("render"),
        count: f.sheet_count(),
        done: 0,
    };
    match &p.voxels {
        Voxels::Memory(v) => {
            render_from(&mut renderer, &mut ring, &mut show.wrap(MemorySource(v)))?
        }
        Voxels::File(layout) => render_from(
            &mut renderer,
            &mut ring,
            &mut show.wrap(FileSource::open(layout.clone())?),
        )?,
        Voxels::Stdin {
            dims,
            ty,
            big_endian,
        } => {
            let stdin = std::io::stdin().lock();
            let src = PipeSource::new(
                std::io::BufReader::with_capacity(1 << 20, stdin),
                *dims,
                *ty,
                *big_endian,
                "standard input",
            );
            render_from(&mut renderer, &mut ring, &mut show.wrap(src))?
        }
    }
    let stats = renderer.finish();
    Ok((image, stats))
}

/// Shows progress as a source delivers sheets.
struct Progress<F> {
    inner: F,
    count: usize,
    done: usize,
}

/// A source that reports each sheet read.
struct Reporting<'p, S, F> {
    source: S,
    progress: &'p mut Progress<F>,
}

impl<F: FnMut(usize, usize)> Progress<F> {
    fn wrap<S>(&mut self, source: S) -> Reporting<'_, S, F> {
        Reporting {
            source,
            progress: self,
        }
    }
}

impl<S: SheetSource<Sample = f32, Error = CliError>, F: FnMut(usize, usize)> SheetSource
    for Reporting<'_, S, F>
{
    type Sample = f32;
    type Error = CliError;
    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [f32]) -> Result<(), CliError> {
        self.source.read_sheet(axis, index, out)?;
        let p = &mut *self.progress;
        p.done += 1;
        (p.inner)(p.done, p.count);
        Ok(())
    }
    fn sequential_axis(&self) -> Option<usize> {
        self.source.sequential_axis()
    }
}

/// The f64 reference render of `p` and its seconds (the volume must be in memory).
pub fn render_ref(p: &Prepared) -> Result<(Vec<[f64; 4]>, f64), CliError> {
    let volume = p.volume().ok_or_else(|| {
        CliError::input("the f64 reference needs the volume in memory: drop --stream")
    })?;
    let start = Instant::now();
    let scene = ReferenceScene {
        frame: &p.frame,
        kernel: &p.kernel,
        min_radius_px: p.options.min_radius_px,
        shader: p.shader(),
        order: p.order,
        background: p.background.as_deref(),
    };
    let axis = p.frame.sheet_axis;
    let img = render_reference(
        &scene,
        |s, out| volume.sheet_into(axis, s, out),
        progress("reference"),
    )?;
    Ok((img, start.elapsed().as_secs_f64()))
}

/// The JSON fields every render and verify summary share.
pub fn describe(p: &Prepared, args: &RenderArgs) -> Json {
    let f = &p.frame;
    Json::object()
        .str("volume", &p.name)
        .arr_usize("dims", &p.frame.dims)
        .arr_f64("spacing", &p.frame.spacing.map(f64::from))
        .arr_usize("size", &[args.size.0, args.size.1])
        .str("kernel", &p.kernel.to_string())
        .num("table", args.footprint.table as f64)
        .str(
            "lookup",
            &format!("{:?}", args.footprint.lookup).to_lowercase(),
        )
        .str(
            "method",
            &format!("{:?}", args.footprint.method).to_lowercase(),
        )
        .str("order", &format!("{:?}", p.order).to_lowercase())
        .str("accum", &format!("{:?}", args.accum).to_lowercase())
        .bool("streamed", p.volume().is_none())
        .str("shading", &args.shading)
        .str("tf", &p.tf_name)
        .arr_f64("window", &p.window.map(f64::from))
        .str("sheet_axis", ["i", "j", "k"][f.sheet_axis])
        .arr_f64(
            "footprint_half_extent_px",
            &f.footprint.half_extent.map(f64::from),
        )
}

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    let p = prepare(args)?;
    let (args, choice) = apply_quality(&p, args)?;
    let args = &args;
    let (rgb, summary) = if args.footprint.method == MethodArg::Reference {
        let (img, secs) = render_ref(&p)?;
        let rgb: Vec<[f32; 4]> = img.iter().map(|c| c.map(|x| x as f32)).collect();
        crate::say!("{}: f64 reference render in {:.3} s", p.name, secs);
        (rgb, describe(&p, args).num("seconds", secs))
    } else {
        let (img, stats, secs) = render_core(&p, args)?;
        crate::say!(
            "{}: {}x{} in {:.3} s; {} sheets along {}, {} voxels ({} splatted), {} pixel updates, {} composites",
            p.name,
            args.size.0,
            args.size.1,
            secs,
            stats.sheets,
            ["i", "j", "k"][p.frame.sheet_axis],
            stats.voxels,
            stats.voxels_splatted,
            stats.pixel_updates,
            stats.pixels_composited
        );
        let j = describe(&p, args)
            .num("seconds", secs)
            .num("voxels", stats.voxels as f64)
            .num("voxels_splatted", stats.voxels_splatted as f64)
            .num("pixel_updates", stats.pixel_updates as f64)
            .num("pixels_composited", stats.pixels_composited as f64);
        (img, j)
    };
    let summary = match &choice {
        Some(c) => summary.obj("quality", quality_json(c)),
        None => summary,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("footprint.png"));
    let png = encode_png_rgb(&rgb, args.size.0, args.size.1)?;
    io::write_atomic(&out, &png)?;
    if let Some(j) = &args.json {
        io::write_atomic(
            j,
            summary
                .str("out", &out.display().to_string())
                .finish()
                .as_bytes(),
        )?;
    }
    crate::say!("wrote {}", out.display());
    Ok(())
}
