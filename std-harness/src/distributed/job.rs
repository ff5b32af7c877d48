//! One render split into bricks: what every brick shares ([`Job`]: the inputs, where the
//! samples come from, the split, the window), and one brick's frame ([`Job::render`]).

use super::BrickLayout;
use crate::args::Lod;
use crate::io::brick::{BrickPlace, IndexBox};
use crate::io::cut::{crop, read_brick};
use crate::io::stream::{InMemory, Layout};
use crate::io::volume::Volume;
use crate::pipeline::ends::run::end_frame;
use crate::pipeline::stages::decorators::{self, Resample};
use crate::pipeline::stages::visible::FrameCache;
use crate::pipeline::Renderer;
use crate::plan::{End, Plan};
use crate::scene::Scene;
use crate::{builtin, CliError};
use std::sync::Arc;
use std::time::Instant;

/// Where the bricks' samples come from.
pub enum Source {
    /// Raw samples at a known place in a file (a raw file with `--dims`, NRRD with raw
    /// encoding, uncompressed MetaImage): each brick reads only its own box, with positioned
    /// reads ([`crate::io::cut::read_box`]).
    Seekable {
        layout: Layout,
        spacing: [f32; 3],
        directions: [[f32; 3]; 3],
    },
    /// A volume loaded whole (a compressed file, a format without a raw layout, the built-in
    /// scene): bricks are cut from it; `bytes` is what loading it read. Under MPI only rank 0
    /// loads it, and sends each rank its brick.
    Whole { volume: Arc<Volume>, bytes: u64 },
    /// A volume another rank loads whole: this rank knows its grid and receives its brick.
    Elsewhere(Header),
}

/// What a rank that does not load a volume needs to know of it: its grid and sample type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    pub dims: [usize; 3],
    pub spacing: [f32; 3],
    pub directions: [[f32; 3]; 3],
    /// The sample type ([`crate::io::volume::SampleType`] order: u8, i8, u16, i16, u32, i32,
    /// f32, f64).
    pub ty: usize,
}

impl Header {
    /// The header of `v`.
    pub fn of(v: &Volume) -> Header {
        use crate::io::volume::Samples;
        Header {
            dims: v.dims,
            spacing: v.spacing,
            directions: v.directions,
            ty: match v.samples {
                Samples::U8(_) => 0,
                Samples::I8(_) => 1,
                Samples::U16(_) => 2,
                Samples::I16(_) => 3,
                Samples::U32(_) => 4,
                Samples::I32(_) => 5,
                Samples::F32(_) | Samples::Coloured(_) => 6,
                Samples::F64(_) => 7,
            },
        }
    }

    /// As 16 numbers (for a broadcast).
    pub fn to_f64s(&self) -> [f64; 16] {
        let mut out = [0.0; 16];
        for c in 0..3 {
            out[c] = self.dims[c] as f64;
            out[3 + c] = f64::from(self.spacing[c]);
            for r in 0..3 {
                out[6 + 3 * c + r] = f64::from(self.directions[c][r]);
            }
        }
        out[15] = self.ty as f64;
        out
    }

    /// From [`Header::to_f64s`].
    pub fn from_f64s(v: &[f64; 16]) -> Header {
        Header {
            dims: [0, 1, 2].map(|c| v[c] as usize),
            spacing: [0, 1, 2].map(|c| v[3 + c] as f32),
            directions: [0, 1, 2].map(|c| [0, 1, 2].map(|r| v[6 + 3 * c + r] as f32)),
            ty: v[15] as usize,
        }
    }
}

/// One render split into bricks: what every brick shares.
pub struct Job {
    /// The inputs each brick renders with (its volume and the window set per brick).
    pub inputs: Scene,
    pub plan: Plan,
    /// The volume's name in messages and the JSON.
    pub name: String,
    /// The whole volume's dims.
    pub dims: [usize; 3],
    pub source: Source,
    /// Whether the default window comes from the data's sample (a user's volume) or its range
    /// (the built-in scene), as in one process.
    sampled: bool,
}

impl Job {
    /// The job for `inputs` and `plan`, refused with a reason where bricks cannot honour them.
    /// Opens the source: a seekable file's header only; anything else is loaded whole.
    pub fn new(inputs: &Scene, plan: &Plan) -> Result<Job, CliError> {
        Job::open(inputs, plan, None)
    }

    /// Whether `inputs`' volume is loaded whole ([`Source::Whole`] from a file or the built-in
    /// scene, not a program's volume in memory): the same answer on every rank.
    pub fn loads_whole(inputs: &Scene) -> Result<bool, CliError> {
        let raw = crate::pipeline::stages::load::raw_options(inputs)?;
        Ok(match (&inputs.memory, &inputs.volume) {
            (Some(_), _) => false,
            (None, Some(path)) => {
                // A file this rank cannot read is its error, not a sign to load it whole.
                crate::io::regular_file_len(path)?;
                seekable(path, raw.as_ref())?.is_none()
            }
            (None, None) => true,
        })
    }

    /// [`Job::new`] on a rank that does not load a whole volume: `header` is what the loading
    /// rank says of it ([`Source::Elsewhere`]); a seekable file or a volume in memory is opened
    /// as by [`Job::new`].
    pub fn remote(inputs: &Scene, plan: &Plan, header: Header) -> Result<Job, CliError> {
        Job::open(inputs, plan, Some(header))
    }

    fn open(inputs: &Scene, plan: &Plan, remote: Option<Header>) -> Result<Job, CliError> {
        refuse(inputs, plan)?;
        let mut inputs = inputs.clone();
        let builtin = inputs.volume.is_none() && inputs.memory.is_none();
        // Bricks reach the pipeline as volumes in memory: the one-process choice, made here.
        // (Any further --tf stay, for the rule that a one-component volume takes one.)
        if inputs.tfs.is_empty() {
            inputs.tfs.push(inputs.tf_name());
        }
        let mut plan = plan.clone();
        if plan.lod == Lod::Auto {
            // A level of detail is built from the whole volume; bricks render level 0.
            plan.lod = Lod::Level(0);
        }
        let raw = crate::pipeline::stages::load::raw_options(&inputs)?;
        let (name, source) = match (&inputs.memory, &inputs.volume) {
            (Some(m), _) => (
                m.name.clone(),
                Source::Whole {
                    volume: Arc::clone(&m.volume),
                    bytes: 0,
                },
            ),
            (None, Some(path)) => (
                path.display().to_string(),
                match (seekable(path, raw.as_ref())?, remote) {
                    (Some(s), _) => s,
                    (None, Some(h)) => Source::Elsewhere(h),
                    (None, None) => {
                        let bytes = std::fs::metadata(path).map_or(0, |m| m.len());
                        let volume = crate::io::formats::load_array(
                            path,
                            raw.as_ref(),
                            inputs.array.as_deref(),
                        )?;
                        Source::Whole {
                            volume: Arc::new(volume),
                            bytes,
                        }
                    }
                },
            ),
            (None, None) => (
                crate::pipeline::stages::load::scene_name(inputs.scene_size),
                match remote {
                    Some(h) => Source::Elsewhere(h),
                    None => Source::Whole {
                        volume: Arc::new(builtin::volume(inputs.scene_size)?),
                        bytes: 0,
                    },
                },
            ),
        };
        let dims = match &source {
            Source::Seekable { layout, .. } => layout.dims,
            Source::Whole { volume, .. } => volume.dims,
            Source::Elsewhere(h) => h.dims,
        };
        inputs.memory = None;
        inputs.volume = None;
        inputs.dims = None;
        inputs.sample_type = None;
        Ok(Job {
            inputs,
            plan,
            name,
            dims,
            source,
            sampled: !builtin,
        })
    }

    /// The split into `n` bricks (`--bricks` when given: its product must be `n`).
    pub fn layout(&self, n: usize, bricks: Option<[usize; 3]>) -> Result<BrickLayout, CliError> {
        match bricks {
            Some(counts) => {
                let m: usize = counts.iter().product();
                if m != n {
                    return Err(CliError::input(format!(
                        "--bricks {},{},{} makes {m} bricks for {n} ranks: give as many bricks \
                         as ranks",
                        counts[0], counts[1], counts[2]
                    )));
                }
                BrickLayout::grid(self.dims, counts)
            }
            None => BrickLayout::balanced(self.dims, n, self.sheet_axis()?),
        }
    }

    /// The grid-to-screen map of the view the inputs ask for (at the output size).
    fn grid_to_screen(&self) -> Result<glam::Mat3, CliError> {
        let grid = footprint::geometry::Grid::from_matrix(self.grid())
            .map_err(|e| CliError::input(format!("{}: {e}", self.name)))?;
        let view = crate::pipeline::stages::prepare::view_for(&self.inputs, self.dims, &grid)?;
        Ok(view.grid_to_screen(&grid))
    }

    /// The view's ray direction in grid index units, away from the viewer (what orders the
    /// bricks; a supersampled or subsampled frame's map is this one scaled, so its rays run the
    /// same way).
    pub fn ray(&self) -> Result<[f32; 3], CliError> {
        Ok((self.grid_to_screen()?.inverse() * glam::Vec3::Z).to_array())
    }

    /// The sheet axis of the frame the inputs ask for (what the default split cuts across).
    fn sheet_axis(&self) -> Result<usize, CliError> {
        let kernel = self.inputs.kernel.kernel;
        let g2s = self.grid_to_screen()?;
        let options = self.inputs.kernel.options;
        let f = footprint::geometry::Footprint::new(&kernel, &g2s, options)
            .map_err(|e| CliError::input(format!("{}: {e}", self.name)))?;
        Ok(f.sheet_axis)
    }

    /// The grid and the sample type as every rank must see them (what
    /// `super::mpi::agree_frame` compares): dims, grid-to-world matrix and type, not where the
    /// samples are read from.
    pub fn grid_description(&self) -> String {
        let ty = match &self.source {
            Source::Seekable { layout, .. } => format!("{:?}/{}", layout.ty, layout.big_endian),
            Source::Whole { volume, .. } => format!("{}", Header::of(volume).ty),
            Source::Elsewhere(h) => format!("{}", h.ty),
        };
        format!("{:?} {:?} {ty}", self.dims, self.grid().to_cols_array())
    }

    /// The grid-to-world matrix.
    fn grid(&self) -> glam::Mat3 {
        match &self.source {
            Source::Seekable {
                spacing,
                directions,
                ..
            }
            | Source::Elsewhere(Header {
                spacing,
                directions,
                ..
            }) => {
                let col = |c: usize| glam::Vec3::from_array(directions[c]) * spacing[c];
                glam::Mat3::from_cols(col(0), col(1), col(2))
            }
            Source::Whole { volume, .. } => volume.grid_to_world(),
        }
    }

    /// The brick owning `owned` (with its ghost layer), and the bytes read for it.
    pub fn brick(&self, owned: IndexBox) -> Result<(Volume, u64), CliError> {
        let place = BrickPlace::around(owned, self.dims);
        match &self.source {
            Source::Seekable {
                layout,
                spacing,
                directions,
            } => read_brick(
                layout,
                place,
                (*spacing, *directions),
                // Wide samples get the map all bricks agree on (`agreed_values`).
                crate::io::volume::ValueMap::IDENTITY,
            ),
            Source::Whole { volume, bytes } => Ok((crop(volume, place)?, *bytes)),
            Source::Elsewhere(_) => Err(CliError::input(
                "this rank's brick comes from the rank that loads the volume",
            )),
        }
    }

    /// What a brick contributes to the default window: its stored samples' finite range, and
    /// (for a user's volume) its share of the whole volume's strided sample. `None` with
    /// `--window`.
    pub fn window_part(&self, brick: &Volume) -> Option<WindowPart> {
        self.inputs.window.is_none().then(|| WindowPart {
            range: brick.range(),
            sample: if self.sampled {
                brick.strided_sample()
            } else {
                Vec::new()
            },
        })
    }

    /// Whether the samples are wide (u32, i32, f64): their bricks must agree on one
    /// [`ValueMap`](crate::io::volume::ValueMap) ([`Job::agreed_values`]).
    pub fn is_wide(&self) -> bool {
        match &self.source {
            Source::Seekable { layout, .. } => crate::io::stream::is_wide(layout.ty),
            Source::Whole { volume, .. } => !volume.values.is_identity() || volume.is_wide(),
            Source::Elsewhere(h) => matches!(h.ty, 4 | 5 | 7),
        }
    }

    /// The map every brick's values go through, from the whole volume's finite range in data
    /// units (the union of the bricks' [`Volume::sample_range`]): what the volume loaded whole
    /// gets ([`crate::io::volume::ValueMap::for_range`]).
    pub fn agreed_values(&self, lo: f64, hi: f64) -> crate::io::volume::ValueMap {
        if self.is_wide() {
            crate::io::volume::ValueMap::for_range(lo, hi)
        } else {
            crate::io::volume::ValueMap::IDENTITY
        }
    }

    /// The window every brick renders with, in the renderer's values (`values`, the map the
    /// bricks agreed): `--window`, or the default window of the whole volume from every
    /// brick's [`WindowPart`] (the same range and sample one process takes, so the same
    /// window).
    pub fn window(
        &self,
        parts: Vec<WindowPart>,
        values: crate::io::volume::ValueMap,
    ) -> Result<[f32; 2], CliError> {
        if let Some(w) = self.inputs.window {
            return crate::pipeline::stages::window::check_given(w, values);
        }
        let range = parts
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |r, p| {
                (r.0.min(p.range.0), r.1.max(p.range.1))
            });
        let mut sample: Vec<f32> = parts.into_iter().flat_map(|p| p.sample).collect();
        sample.sort_by(f32::total_cmp);
        crate::pipeline::stages::window::default_window(
            &self.name,
            Some(range),
            None,
            self.sampled.then_some(sample.as_slice()),
        )
    }

    /// Renders `brick` with `window`: its own voxels in the whole volume's frame, premultiplied
    /// RGBA at the frame's internal size (a supersampled frame's k× size, a subsampled frame's
    /// 1/s: the images are composited there, where one process composites its sheets, and
    /// brought to the output size after: [`BrickFrame::finish`]), over nothing (the background
    /// is composited once, under the finished image).
    ///
    /// A split render is one frame: object slicing classifies each sheet as it goes and keeps
    /// no visible-voxel lists (the same voxels, the same bits), so a rank holds its brick and
    /// its images, not lists; slabs keep their brick's lists, as they must.
    pub fn render(&self, brick: Volume, window: [f32; 2]) -> Result<BrickFrame, CliError> {
        let start = Instant::now();
        let mut inputs = self.inputs.clone();
        // The window in data units, as a command line gives it (prepare maps it back).
        inputs.window = Some(brick.values.window_to_data(window));
        inputs.memory = Some(InMemory {
            volume: Arc::new(brick),
            name: self.name.clone(),
        });
        // The door, opened as given: a brick's plan is the job's, every choice already made.
        let (mut p, _, _) = Renderer::prepare(&inputs, &self.plan)?.into_parts();
        let background = p.background_out.take();
        p.background = None;
        let out = p.out_size();
        // The door's own decorator, taken off here and put back once the bricks' images are
        // composited (`BrickFrame::finish`): compositing is not linear, so it must come first.
        let d = decorators::peel(&p, &self.plan)?;
        let mut cache = match d.plan.end {
            End::Sheets(_) => FrameCache::with_list_budget(0),
            _ => FrameCache::default(),
        };
        let frame = end_frame(&d.prepared, &d.plan, &mut cache)?;
        let (resample, threads) = (d.resample, d.plan.threads);
        Ok(BrickFrame {
            image: frame.image,
            size: out,
            resample,
            threads,
            voxels: frame.stats.voxels,
            seconds: start.elapsed().as_secs_f64(),
            background,
        })
    }
}

/// What a brick contributes to the default window ([`Job::window`]).
#[derive(Clone, Debug, Default)]
pub struct WindowPart {
    /// Smallest and largest finite stored sample.
    pub range: (f32, f32),
    /// Its owned share of the whole volume's strided sample.
    pub sample: Vec<f32>,
}

/// A brick's frame.
pub struct BrickFrame {
    /// Premultiplied RGBA, linear, at the frame's internal size ([`BrickFrame::resample`]
    /// brings it to `size`), over nothing.
    pub image: Vec<[f32; 4]>,
    /// The output's width and height, pixels.
    pub size: (usize, usize),
    /// How the composited image reaches `size`.
    pub resample: Resample,
    /// Threads the frame used (and the magnification uses).
    pub threads: usize,
    /// Voxels the brick splatted (its visible own voxels).
    pub voxels: u64,
    /// Seconds from the brick's set-up to its image.
    pub seconds: f64,
    /// The background image (`--background FILE`), composited under the composited image.
    pub background: Option<Arc<[[f32; 4]]>>,
}

impl BrickFrame {
    /// The composited `image` (at this frame's internal size) at the output size, with the
    /// background under it.
    pub fn finish(&self, image: Vec<[f32; 4]>) -> Result<Vec<[f32; 4]>, CliError> {
        self.resample
            .finish(image, self.size, self.threads, self.background.as_deref())
    }
}

/// The flags bricks cannot honour, refused with the reason (the same on every rank).
pub fn check(inputs: &Scene, plan: &Plan) -> Result<(), CliError> {
    refuse(inputs, plan)
}

/// The flags bricks cannot honour, refused with the reason.
fn refuse(inputs: &Scene, plan: &Plan) -> Result<(), CliError> {
    let no = |what: &str, why: &str| {
        Err(CliError::input(format!(
            "{what} does not render in bricks: {why}"
        )))
    };
    let rectilinear = inputs
        .volume
        .as_deref()
        .is_some_and(crate::io::formats::is_rectilinear);
    if rectilinear {
        return no(
            "a rectilinear grid (.vtr)",
            "its samples' footprints are drawn by the refined renderer, which reads the whole grid",
        );
    }
    match plan.end {
        End::Sheets(_) | End::Slabs { .. } => {}
        End::Post { blend, .. } => {
            return no(
                if blend.projects() {
                    "--blend"
                } else {
                    "--classification post"
                },
                "its values are reconstructed across voxels before they are classified, so a \
                 brick's pixels need its neighbours' values, not their colours",
            )
        }
        End::Refined { .. } => {
            return no("--refine", "refinement interpolates across the whole grid")
        }
        End::Reference => {
            return no(
                "--method reference",
                "the f64 reference reads the whole volume",
            )
        }
    }
    if let Some(c) = inputs.crop {
        return no(
            &format!("--crop {c}"),
            "the bricks are cut from the whole volume; render the crop with one process",
        );
    }
    if !inputs.clip.is_empty() {
        return no(
            "--clip",
            "the bricks composite whole slabs of their own; render a clipped frame with one \
             process",
        );
    }
    if inputs.stream.is_some() {
        return no(
            "--stream",
            "each rank already reads only its brick from the file (give it as VOLUME)",
        );
    }
    if inputs.perspective.is_some() {
        return no(
            "--perspective",
            "the bricks' visibility order is the orthographic one",
        );
    }
    if matches!(plan.lod, Lod::Level(1..)) {
        return no(
            "--lod N",
            "a level averages voxel blocks across brick borders",
        );
    }
    if plan.quality.is_some() {
        return no("--quality", "its pilots would choose per brick; choose the plan with one process and pass its flags");
    }
    Ok(())
}

/// The raw layout of `path` when its samples sit uncompressed at a known offset (what
/// `--stream` reads: `pipeline::stages::load::raw_layout`); `None` for a file that must be loaded
/// whole. A raw file given with `--dims` that does not match them is an error, as for streaming.
fn seekable(
    path: &std::path::Path,
    raw: Option<&crate::io::formats::raw::RawOptions>,
) -> Result<Option<Source>, CliError> {
    match crate::pipeline::stages::load::raw_layout(path, raw) {
        Ok(s) => Ok(Some(Source::Seekable {
            layout: s.layout,
            spacing: s.spacing,
            directions: s.directions,
        })),
        Err(e) if raw.is_some() => Err(e),
        Err(_) => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header survives the broadcast's encoding (every field, every sample type).
    #[test]
    fn header_round_trips() {
        for ty in 0..8 {
            let h = Header {
                dims: [7, 300, 12_000],
                spacing: [0.5, 1.25, 3.0],
                directions: [[1.0, 0.0, 0.0], [0.0, 0.6, 0.8], [0.0, -0.8, 0.6]],
                ty,
            };
            assert_eq!(Header::from_f64s(&h.to_f64s()), h);
        }
    }
}
