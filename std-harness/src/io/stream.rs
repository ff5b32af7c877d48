//! Sheet sources for the core's [`SheetSource`] interface: a volume in memory, a seekable file read
//! a few sheets at a time, and a pipe read in file order. File and pipe keep memory bounded by a
//! few sheets whatever the volume's size.

use crate::io::volume::{SampleType, ValueMap, Volume};
use crate::CliError;
use footprint::lod::Coloured;
use footprint::render::RenderError;
use footprint::source::SheetSource;
use std::io::Read;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

impl From<RenderError> for CliError {
    fn from(e: RenderError) -> Self {
        CliError::input(e.to_string())
    }
}

/// Decodes `bytes` (a whole number of samples of `ty`) into f32s, wide samples (u32, i32, f64)
/// through `values` ([`ValueMap`], in f64; the identity leaves every value as `as f32` makes it).
pub fn decode_into(
    bytes: &[u8],
    ty: SampleType,
    big_endian: bool,
    values: ValueMap,
    out: &mut [f32],
) {
    decode_with(bytes, ty, big_endian, out, |x| values.apply(x));
}

/// Decodes `bytes` (a whole number of samples of `ty`), each sample exactly as f64, into `out`
/// through `to`.
fn decode_with<O>(
    bytes: &[u8],
    ty: SampleType,
    big_endian: bool,
    out: &mut [O],
    to: impl Fn(f64) -> O,
) {
    macro_rules! conv {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            for (o, c) in out.iter_mut().zip(bytes.chunks_exact(N)) {
                let a: [u8; N] = c.try_into().expect("chunk of N bytes");
                *o = to(f64::from(if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }));
            }
        }};
    }
    match ty {
        SampleType::U8 => conv!(u8),
        SampleType::I8 => conv!(i8),
        SampleType::U16 => conv!(u16),
        SampleType::I16 => conv!(i16),
        SampleType::U32 => conv!(u32),
        SampleType::I32 => conv!(i32),
        SampleType::F32 => conv!(f32),
        SampleType::F64 => conv!(f64),
    }
}

/// Whether samples of `ty` may need a [`ValueMap`] other than the identity (f32 does not hold
/// every u32, i32 or f64).
pub fn is_wide(ty: SampleType) -> bool {
    matches!(ty, SampleType::U32 | SampleType::I32 | SampleType::F64)
}

/// A volume already in memory.
pub struct MemorySource<'a>(pub &'a Volume);

impl SheetSource for MemorySource<'_> {
    type Sample = f32;
    type Error = CliError;
    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [f32]) -> Result<(), CliError> {
        self.0.sheet_into(axis, index, out);
        Ok(())
    }
}

/// A volume in memory as a source of [`Coloured`] samples (the colours a level of detail carries;
/// `None` for plain data).
pub struct ColouredMemorySource<'a>(pub &'a Volume);

impl SheetSource for ColouredMemorySource<'_> {
    type Sample = Coloured;
    type Error = CliError;
    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [Coloured],
    ) -> Result<(), CliError> {
        self.0.coloured_sheet_into(axis, index, out);
        Ok(())
    }
}

/// Where a streamed file's samples are.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// The file holding the samples.
    pub path: PathBuf,
    /// Byte offset of sample (0, 0, 0).
    pub offset: u64,
    pub dims: [usize; 3],
    pub ty: SampleType,
    pub big_endian: bool,
    /// How the samples become the renderer's values ([`ValueMap`]; the identity but for wide
    /// samples, set from the range pass or the window: `pipeline::stages::load`).
    pub values: ValueMap,
}

/// Budget for the file source's sheet cache, bytes.
pub const CACHE_BYTES: usize = 8 << 20;

/// A seekable file read a few sheets at a time (positioned reads; no seeking state). Sheets along
/// z are contiguous; along y each sheet is one row per z-slice; along x one sample per row, so
/// sheets are read in chunks of consecutive indices (each z-slice read once per chunk) and cached.
pub struct FileSource {
    file: std::fs::File,
    layout: Layout,
    /// Cached sheets: axis, first index, count; data row-major per sheet.
    cache: Vec<f32>,
    cached: Option<(usize, usize, usize)>,
    bytes: Vec<u8>,
    last: Option<(usize, usize)>,
}

impl FileSource {
    /// Opens `layout.path`, checking that it holds the samples the layout describes.
    pub fn open(layout: Layout) -> Result<Self, CliError> {
        let err = |e: std::io::Error| {
            CliError::input(format!("{}: cannot read: {e}", layout.path.display()))
        };
        super::regular_file_len(&layout.path)?;
        let file = std::fs::File::open(&layout.path).map_err(err)?;
        let len = file.metadata().map_err(err)?.len();
        let need = crate::io::volume::byte_len(layout.dims, layout.ty)
            .map_err(|e| crate::io::volume::at(&layout.path, e))? as u64;
        if len < layout.offset + need {
            return Err(crate::io::volume::at(
                &layout.path,
                format!(
                    "holds {len} bytes, needs {} after offset {}",
                    need, layout.offset
                ),
            ));
        }
        Ok(FileSource {
            file,
            layout,
            cache: Vec::new(),
            cached: None,
            bytes: Vec::new(),
            last: None,
        })
    }

    fn read_at(&mut self, pos: u64, len: usize) -> Result<(), CliError> {
        super::try_resize(
            &mut self.bytes,
            len,
            0,
            "the bytes read from the volume file",
        )?;
        self.file
            .read_exact_at(&mut self.bytes, self.layout.offset + pos)
            .map_err(|e| {
                CliError::input(format!("{}: read failed: {e}", self.layout.path.display()))
            })
    }

    /// Loads sheets [first, first + count) of `axis` into the cache.
    fn fill(&mut self, axis: usize, first: usize, count: usize) -> Result<(), CliError> {
        let [nx, ny, nz] = self.layout.dims;
        let (ty, be, size, values) = (
            self.layout.ty,
            self.layout.big_endian,
            self.layout.ty.size(),
            self.layout.values,
        );
        let (a, b) = footprint::geometry::in_sheet_axes(axis);
        let (na, nb) = (self.layout.dims[a], self.layout.dims[b]);
        let len = na * nb;
        super::try_resize(&mut self.cache, count * len, 0.0, "the sheets read ahead")?;
        match axis {
            2 => {
                // z-slices are contiguous: one read for the chunk.
                self.read_at((first * nx * ny * size) as u64, count * nx * ny * size)?;
                let bytes = std::mem::take(&mut self.bytes);
                decode_into(&bytes, ty, be, values, &mut self.cache);
                self.bytes = bytes;
            }
            1 => {
                // Sheet y = j holds row j of every z-slice: per slice, rows first..first+count are
                // contiguous.
                let mut row = super::try_filled(count * nx, 0.0f32, "rows of the volume")?;
                for k in 0..nz {
                    self.read_at(((k * ny + first) * nx * size) as u64, count * nx * size)?;
                    decode_into(&self.bytes, ty, be, values, &mut row);
                    for s in 0..count {
                        self.cache[s * len + k * nx..s * len + (k + 1) * nx]
                            .copy_from_slice(&row[s * nx..(s + 1) * nx]);
                    }
                }
            }
            _ => {
                // Sheet x = i holds column i of every row: read each z-slice once per chunk and
                // keep the chunk's columns.
                let mut slice = super::try_filled(nx * ny, 0.0f32, "a z-slice of the volume")?;
                for k in 0..nz {
                    self.read_at((k * nx * ny * size) as u64, nx * ny * size)?;
                    decode_into(&self.bytes, ty, be, values, &mut slice);
                    for j in 0..ny {
                        for s in 0..count {
                            self.cache[s * len + k * ny + j] = slice[j * nx + first + s];
                        }
                    }
                }
            }
        }
        self.cached = Some((axis, first, count));
        Ok(())
    }
}

impl SheetSource for FileSource {
    type Sample = f32;
    type Error = CliError;

    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [f32]) -> Result<(), CliError> {
        let hit = self.cached.is_some_and(|(ax, first, count)| {
            ax == axis && index >= first && index < first + count
        });
        if !hit {
            let (a, b) = footprint::geometry::in_sheet_axes(axis);
            let len = self.layout.dims[a] * self.layout.dims[b];
            let n = self.layout.dims[axis];
            let count = (CACHE_BYTES / (4 * len)).clamp(1, n);
            // Read ahead in the direction the sheets are being requested.
            let descending = self
                .last
                .is_some_and(|(ax, prev)| ax == axis && prev == index + 1);
            let first = if descending {
                (index + 1).saturating_sub(count)
            } else {
                index.min(n - count)
            };
            self.fill(axis, first, count)?;
        }
        let (_, first, _) = self.cached.expect("filled above");
        let len = out.len();
        out.copy_from_slice(&self.cache[(index - first) * len..(index - first + 1) * len]);
        self.last = Some((axis, index));
        Ok(())
    }
}

/// A pipe (or any reader) delivering z-slices in file order.
///
/// Memory follows the data: the first z-slice's bytes are read into a buffer that grows as they
/// arrive ([`crate::io::read_growing`]), so a stream far shorter than `--dims` declare is refused
/// having cost what it delivered. [`PipeSource::prime`] does that read before the renderer
/// allocates its sheet buffers.
pub struct PipeSource<R: Read> {
    reader: R,
    dims: [usize; 3],
    ty: SampleType,
    big_endian: bool,
    values: ValueMap,
    next: usize,
    bytes: Vec<u8>,
    /// `bytes` hold z-slice `next`, read by [`PipeSource::prime`].
    primed: bool,
    name: String,
}

impl<R: Read> PipeSource<R> {
    /// A source of `dims` samples of `ty` read from `reader`, z-slice after z-slice (identity
    /// values: [`PipeSource::with_values`]).
    pub fn new(reader: R, dims: [usize; 3], ty: SampleType, big_endian: bool, name: &str) -> Self {
        PipeSource {
            reader,
            dims,
            ty,
            big_endian,
            values: ValueMap::IDENTITY,
            next: 0,
            bytes: Vec::new(),
            primed: false,
            name: name.into(),
        }
    }

    /// The same source with wide samples mapped through `values`.
    pub fn with_values(self, values: ValueMap) -> Self {
        PipeSource { values, ..self }
    }

    /// Reads the next z-slice's bytes now (before any sheet buffer exists): a stream that ends
    /// first is an error here, having cost only the bytes it delivered.
    pub fn prime(&mut self) -> Result<(), CliError> {
        if self.primed {
            return Ok(());
        }
        let len = self.dims[0]
            .saturating_mul(self.dims[1])
            .saturating_mul(self.ty.size());
        let short = |got: usize, s: &Self| {
            CliError::input(format!(
                "{}: z-slice {} of {}: the stream ended after {got} of its {len} bytes (the \
                 stream is shorter than --dims say)",
                s.name, s.next, s.dims[2]
            ))
        };
        if self.bytes.len() == len {
            // Later slices reuse the first one's buffer.
            let mut got = 0;
            while got < len {
                match self.reader.read(&mut self.bytes[got..]) {
                    Ok(0) => return Err(short(got, self)),
                    Ok(n) => got += n,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(e) => return Err(self.read_error(e)),
                }
            }
        } else {
            self.bytes = crate::io::read_growing(&mut self.reader, len as u64, "a z-slice")
                .map_err(|e| self.read_error(e))?;
            if self.bytes.len() < len {
                return Err(short(self.bytes.len(), self));
            }
        }
        self.primed = true;
        Ok(())
    }

    fn read_error(&self, e: std::io::Error) -> CliError {
        CliError::input(format!(
            "{}: z-slice {} of {}: {e}",
            self.name, self.next, self.dims[2]
        ))
    }
}

impl<R: Read> SheetSource for PipeSource<R> {
    type Sample = f32;
    type Error = CliError;

    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [f32]) -> Result<(), CliError> {
        if axis != 2 || index != self.next {
            return Err(CliError::input(format!(
                "{}: a pipe delivers z-slices in order; sheet {index} of axis {axis} was asked for",
                self.name
            )));
        }
        self.prime()?;
        decode_into(&self.bytes, self.ty, self.big_endian, self.values, out);
        self.primed = false;
        self.next += 1;
        Ok(())
    }

    fn sequential_axis(&self) -> Option<usize> {
        Some(2)
    }
}

/// Smallest and largest finite sample of a streamed file, read sequentially in chunks of at most
/// 4 MiB (however large a sheet is: a 32768² slice costs no more than a small one), as values
/// through `layout.values`.
pub fn file_range(layout: &Layout) -> Result<(f32, f32), CliError> {
    file_summary(layout).map(|(range, _, _)| range)
}

/// What [`file_summary`] finds: the finite range and the strided sample, as values, and the map
/// that makes them values.
pub type FileSummary = ((f32, f32), Vec<f32>, ValueMap);

/// [`file_range`] and, in the same pass, the finite values at every
/// [`sample_stride`](crate::io::volume::sample_stride)th index, ascending: the same sample as
/// [`Volume::strided_sample`](crate::io::volume::Volume::strided_sample) of the file loaded whole.
/// The pass is made in f64; the map wide samples need is decided from its range
/// ([`ValueMap::for_range`], what the file loaded whole would get) and returned third, and the
/// range and sample are given through it.
pub fn file_summary(layout: &Layout) -> Result<FileSummary, CliError> {
    let src = FileSource::open(layout.clone())?;
    let size = layout.ty.size();
    let total = crate::io::volume::byte_len(layout.dims, layout.ty)
        .map_err(|e| crate::io::volume::at(&layout.path, e))?;
    let per = (RANGE_CHUNK_BYTES / size).max(1);
    let mut bytes = super::try_filled(per * size, 0u8, "the range pass's chunk")?;
    let mut values = super::try_filled(per, 0.0f64, "the range pass's chunk")?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut done = 0usize;
    let step = crate::io::volume::sample_stride(total / size);
    let mut sample = Vec::new();
    while done < total {
        let n = (total - done).min(per * size);
        src.file
            .read_exact_at(&mut bytes[..n], layout.offset + done as u64)
            .map_err(|e| CliError::input(format!("{}: read failed: {e}", layout.path.display())))?;
        decode_with(
            &bytes[..n],
            layout.ty,
            layout.big_endian,
            &mut values[..n / size],
            |x| x,
        );
        let first = done / size;
        for (i, &v) in values[..n / size].iter().enumerate() {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
                if (first + i).is_multiple_of(step) {
                    sample.push(v);
                }
            }
        }
        done += n;
    }
    let map = if is_wide(layout.ty) {
        ValueMap::for_range(lo, hi)
    } else {
        ValueMap::IDENTITY
    };
    let mut sample: Vec<f32> = sample.into_iter().map(|v| map.apply(v)).collect();
    sample.sort_by(f32::total_cmp);
    let range = if lo <= hi {
        (map.apply(lo), map.apply(hi))
    } else {
        (f32::INFINITY, f32::NEG_INFINITY)
    };
    Ok((range, sample, map))
}

/// The most bytes [`file_range`] reads at a time (4 MiB).
const RANGE_CHUNK_BYTES: usize = 4 << 20;

/// What `--stream -` reads instead of standard input, for a program that feeds the renderer its
/// own bytes (the Python package's iterables of slices): z-slices in file order, exactly as a
/// pipe would deliver them. Taken once (a stream cannot be read twice).
#[derive(Clone)]
pub struct Pipe(std::sync::Arc<std::sync::Mutex<Option<Box<dyn Read + Send>>>>);

impl Pipe {
    /// A pipe reading from `reader`.
    pub fn new(reader: impl Read + Send + 'static) -> Self {
        Pipe(std::sync::Arc::new(std::sync::Mutex::new(Some(Box::new(
            reader,
        )))))
    }

    /// The reader, the first time; `None` once taken.
    pub fn take(&self) -> Option<Box<dyn Read + Send>> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take()
    }
}

impl std::fmt::Debug for Pipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Pipe")
    }
}

/// A volume a program already holds in memory (the Python package's arrays, shared without a
/// copy: [`crate::io::volume::Data::shared`]), rendered instead of a file, with the name messages
/// and summaries give it.
#[derive(Clone)]
pub struct InMemory {
    /// The volume.
    pub volume: std::sync::Arc<Volume>,
    /// Its name in messages and the JSON's `volume`.
    pub name: String,
}

impl std::fmt::Debug for InMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "InMemory({}, {:?})", self.name, self.volume.dims)
    }
}

/// Whether `path` means standard input.
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}
