//! Where a render's voxels come from: a volume file loaded whole, a file streamed a few sheets at a
//! time, standard input, or the built-in scene; and the optional background image.

use crate::io::formats::{self, raw::RawOptions};
use crate::io::stream::{file_summary, is_stdin, Layout, Pipe};
use crate::io::volume::ValueMap;
use crate::io::volume::{SampleType, Volume};
use crate::scene::Scene;
use crate::{builtin, io, CliError};
use glam::{Mat3, Vec3};
use std::sync::Arc;

/// Where the voxels come from.
#[derive(Clone)]
pub enum Voxels {
    /// Loaded whole (shared: a prepared render's copies, such as a subsampled frame's, do not
    /// copy the samples).
    Memory(Arc<Volume>),
    /// Streamed from a seekable file.
    File(Layout),
    /// Streamed from standard input (or the program's own [`Pipe`]), z-slices in file order.
    Stdin {
        dims: [usize; 3],
        ty: SampleType,
        big_endian: bool,
        /// What to read instead of standard input (`Scene::stdin`).
        pipe: Option<Pipe>,
        /// How wide samples become values: from the window a pipe must be given
        /// ([`stream_values`]).
        values: ValueMap,
        /// `--crop`: the samples outside this box arrive and are made missing as they stream
        /// ([`footprint::source::Cropped`]).
        crop: Option<footprint::source::CropBox>,
    },
}

impl Voxels {
    /// The sample type of a pipe (`--stream -`), which cannot be read twice; `None` otherwise.
    pub fn piped(&self) -> Option<SampleType> {
        match self {
            Voxels::Stdin { ty, .. } => Some(*ty),
            _ => None,
        }
    }

    /// How the samples become the renderer's values ([`ValueMap`]), whatever carries them.
    pub fn values(&self) -> ValueMap {
        match self {
            Voxels::Memory(v) => v.values,
            Voxels::File(layout) => layout.values,
            Voxels::Stdin { values, .. } => *values,
        }
    }
}

/// The map of a stream of `ty` samples that is read once, without a range pass: the identity,
/// or for wide samples (u32, i32, f64) the one [`ValueMap::for_range`] gives the window `window`
/// (data units), so the window's arithmetic is kept in f64.
pub fn stream_values(ty: SampleType, window: Option<[f64; 2]>) -> ValueMap {
    match window {
        Some([lo, hi]) if crate::io::stream::is_wide(ty) => ValueMap::for_range(lo, hi),
        _ => ValueMap::IDENTITY,
    }
}

/// The raw-file options from `--dims`, `--type`, `--endian`, `--spacing`, if `--dims` was given.
pub fn raw_options(args: &Scene) -> Result<Option<RawOptions>, CliError> {
    let given = args.dims.is_some() || args.sample_type.is_some();
    let file = args.volume.as_ref().or(args.stream.as_ref());
    if let Some(format) = file.and_then(|f| crate::io::formats::header_format(f)) {
        if given {
            return Err(CliError::input(format!(
                "{}: --dims and --type are for headerless raw files; this {format} file's header \
                 gives its size and type (drop the flags)",
                file.map_or(String::new(), |f| f.display().to_string())
            )));
        }
    }
    let Some(dims) = args.dims else {
        if args.sample_type.is_some() {
            return Err(CliError::input(
                "--type is for headerless raw files, which also need --dims X,Y,Z",
            ));
        }
        return Ok(None);
    };
    let ty = args.sample_type.ok_or_else(|| {
        CliError::input("headerless raw files need --type as well as --dims (e.g. --type u8)")
    })?;
    let big_endian = args.big_endian;
    Ok(Some(RawOptions {
        dims,
        ty,
        big_endian,
        spacing: args.spacing,
    }))
}

/// What `prepare` learns about the voxels before rendering.
pub(crate) struct Loaded {
    pub(crate) voxels: Voxels,
    pub(crate) name: String,
    pub(crate) dims: [usize; 3],
    pub(crate) grid: Mat3,
    /// The data's finite range, if it could be read without a second pass over a pipe.
    pub(crate) range: Option<(f32, f32)>,
    /// A user's volume (not the built-in scene, not a pipe) with no `--window`: its strided
    /// sample, for the default window (`super::window`).
    pub(crate) sample: Option<Vec<f32>>,
    /// A multi-component volume's palette (`super::components`): the volume holds its indices.
    pub(crate) labels: Option<crate::tf::labels::LabelTable>,
}

pub(crate) fn load_voxels(args: &Scene) -> Result<Loaded, CliError> {
    let raw = raw_options(args)?;
    if args.scene_size != builtin::SIDE && (args.volume.is_some() || args.stream.is_some()) {
        return Err(CliError::input(
            "--scene-size samples the built-in scene: give no volume with it",
        ));
    }
    if let Some(m) = &args.memory {
        if args.volume.is_some() || args.stream.is_some() {
            return Err(CliError::input(
                "a volume in memory renders alone: give no VOLUME or --stream with it",
            ));
        }
        let v = &m.volume;
        // A brick's range is its own, not the volume's: no warning compares the window with it.
        let range = v.brick.is_none().then(|| v.range());
        let (dims, grid) = (v.dims, v.grid_to_world());
        let sample = args.window.is_none().then(|| v.strided_sample());
        let cropped = match args.crop {
            Some(c) if v.brick.is_some() => {
                return Err(CliError::input(format!(
                    "--crop {c}: this volume is already a brick of a split render (crop the \
                     volume before splitting it)"
                )))
            }
            Some(c) => Arc::new(crop_volume(v, c)?),
            None => Arc::clone(v),
        };
        return Ok(Loaded {
            sample,
            voxels: Voxels::Memory(cropped),
            name: m.name.clone(),
            dims,
            grid,
            range,
            labels: None,
        });
    }
    let Some(stream) = &args.stream else {
        let (volume, name, labels) = match &args.volume {
            Some(path) => {
                let name = path.display().to_string();
                match formats::load_components(path, args.array.as_deref())? {
                    Some(parts) => {
                        let (v, table) = super::components::classify(&parts, args, &name)?;
                        (v, name, Some(table))
                    }
                    None => {
                        let v = formats::load_array(path, raw.as_ref(), args.array.as_deref())?;
                        (v, name, None)
                    }
                }
            }
            None => (
                builtin::volume(args.scene_size)?,
                scene_name(args.scene_size),
                None,
            ),
        };
        let (dims, grid, range) = (volume.dims, volume.grid_to_world(), Some(volume.range()));
        let sample =
            (args.window.is_none() && args.volume.is_some()).then(|| volume.strided_sample());
        // The window and its warnings are the whole volume's (taken above): a crop hides
        // voxels, it does not reclassify the rest.
        let volume = match args.crop {
            Some(c) => crop_volume(&volume, c)?,
            None => volume,
        };
        return Ok(Loaded {
            sample,
            voxels: Voxels::Memory(Arc::new(volume)),
            name,
            dims,
            grid,
            range,
            labels,
        });
    };
    load_stream(args, stream, raw)
}

/// `volume` cropped to `crop` ([`crate::scene::Crop`]): a brick owning and storing the box alone
/// (no ghost layer: the voxels outside are missing, for gradients too).
pub(crate) fn crop_volume(volume: &Volume, crop: crate::scene::Crop) -> Result<Volume, CliError> {
    let b = crop.index_box(volume.dims)?;
    io::cut::crop(
        volume,
        io::brick::BrickPlace {
            stored: b,
            owned: b,
        },
    )
}

/// The built-in scene's name in messages and the JSON's `volume`, sampled on an `n`³ grid.
pub(crate) fn scene_name(n: usize) -> String {
    match n {
        builtin::SIDE => "built-in electron-density scene".to_string(),
        n => format!("built-in electron-density scene, {n}^3"),
    }
}

/// `--stream FILE|-`: the layout a streamed volume is read through (standard input, a raw file,
/// NRRD or MetaImage with raw data), checked against the file, and, without `--window`, the
/// range and sample the default window needs (one pass over the file).
fn load_stream(
    args: &Scene,
    stream: &std::path::Path,
    raw: Option<RawOptions>,
) -> Result<Loaded, CliError> {
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
            pipe: args.stdin.clone(),
            values: stream_values(o.ty, args.window),
            crop: match args.crop {
                Some(c) => {
                    let b = c.index_box(o.dims)?;
                    Some(footprint::source::CropBox {
                        lo: b.lo,
                        hi: b.hi.map(|h| h - 1),
                    })
                }
                None => None,
            },
        };
        return Ok(Loaded {
            voxels,
            name: "standard input".into(),
            dims: o.dims,
            grid,
            range: None,
            sample: None,
            labels: None,
        });
    }
    let formats::Streamable {
        mut layout,
        spacing,
        directions,
    } = raw_layout(stream, raw.as_ref())?;
    let col = |c: usize| Vec3::from_array(directions[c]) * spacing[c];
    let grid = Mat3::from_cols(col(0), col(1), col(2));
    // Wide samples get the map the file loaded whole would get (from the range pass), or,
    // with --window (no range pass), the window's.
    let (range, sample) = if args.window.is_none() {
        let (range, sample, values) = file_summary(&layout)?;
        layout.values = values;
        (Some(range), Some(sample))
    } else {
        layout.values = stream_values(layout.ty, args.window);
        (None, None)
    };
    if let Some(c) = args.crop {
        // Only the box's samples are read (positioned reads) and held: the window above is the
        // whole file's.
        let b = c.index_box(layout.dims)?;
        let place = io::brick::BrickPlace {
            stored: b,
            owned: b,
        };
        let (volume, _) =
            io::cut::read_brick(&layout, place, (spacing, directions), layout.values)?;
        return Ok(Loaded {
            sample,
            dims: layout.dims,
            voxels: Voxels::Memory(Arc::new(volume)),
            name,
            grid,
            range,
            labels: None,
        });
    }
    Ok(Loaded {
        sample,
        dims: layout.dims,
        voxels: Voxels::File(layout),
        name,
        grid,
        range,
        labels: None,
    })
}

/// Where a file's raw samples are, and its grid: a raw file (`--dims` and `--type`, its length
/// checked), NRRD with raw encoding, or uncompressed MetaImage; an error for anything else.
/// What `--stream` reads and what a brick of a split render reads in part.
pub(crate) fn raw_layout(
    stream: &std::path::Path,
    raw: Option<&RawOptions>,
) -> Result<formats::Streamable, CliError> {
    let lower = stream.display().to_string().to_ascii_lowercase();
    let found = if let Some(o) = raw {
        crate::io::volume::check_spacing(o.spacing)
            .map_err(|e| crate::io::volume::at(stream, e))?;
        formats::Streamable {
            layout: Layout {
                path: stream.to_path_buf(),
                offset: 0,
                dims: o.dims,
                ty: o.ty,
                big_endian: o.big_endian,
                values: crate::io::volume::ValueMap::IDENTITY,
            },
            spacing: o.spacing,
            directions: crate::io::volume::AXIS_ALIGNED,
        }
    } else if lower.ends_with(".nrrd") || lower.ends_with(".nhdr") {
        formats::nrrd::raw_layout(stream)?
    } else if lower.ends_with(".mha") || lower.ends_with(".mhd") {
        formats::metaimage::raw_layout(stream)?
    } else {
        return Err(crate::io::volume::at(stream, "streaming reads raw files (with --dims and --type), NRRD with raw encoding, or uncompressed MetaImage"));
    };
    let layout = &found.layout;
    let file_len = crate::io::regular_file_len(&layout.path)?;
    let need = crate::io::volume::byte_len(layout.dims, layout.ty)
        .map_err(|e| crate::io::volume::at(&layout.path, e))? as u64;
    if raw.is_some() && file_len != need {
        return Err(crate::io::volume::at(
            &layout.path,
            format!("expected {need} bytes for --dims/--type, found {file_len}"),
        ));
    }
    Ok(found)
}

pub(crate) fn load_background(
    path: &std::path::Path,
    size: (usize, usize),
    gamma: crate::io::image::Gamma,
) -> Result<Vec<[f32; 4]>, CliError> {
    let bytes = io::read_file(path)?;
    let img =
        crate::io::image::decode_png_rgba_sized(&bytes, &path.display().to_string(), size, gamma)?;
    Ok(img.2)
}
