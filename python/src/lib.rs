//! `footprint._footprint`, the extension module the Python package `footprint` wraps: numpy
//! volumes rendered by the harness's pipeline without a copy, slices streamed from a Python
//! iterable, files loaded, and the commands (`verify`, `bench`, `tables`) run on arrays.
//!
//! **Zero copy.** A C- or Fortran-contiguous array is handed to the harness as shared samples
//! ([`Data::shared`]): a pointer and a length into the array's own buffer. That is sound because
//! (1) the array is borrowed read-only through numpy's borrow checker for the whole call (a
//! `PyReadonlyArray` held on this stack frame, so no Rust code writes it meanwhile), (2) the
//! array object is kept alive by that borrow, and numpy cannot resize or free a buffer another
//! reference holds, and (3) the volume holding the pointer is dropped before the call returns
//! (checked: the call owns the only reference when it ends). Python code in another thread may
//! still write the array while the GIL is released (as with any C extension that releases it):
//! the documented rule is not to.

// The one use of `unsafe`: reading a numpy array's buffer as a slice (see the module docs).
#![deny(unsafe_op_in_unsafe_fn)]

mod depth;
mod keywords;
use keywords::request;

use footprint_harness::args::RenderArgs;
use footprint_harness::io::stream::{InMemory, Pipe};
use footprint_harness::io::volume::{check_spacing, Data, Samples, Volume};
use footprint_harness::CliError;
use numpy::{
    Element, PyArray1, PyArray3, PyArrayDyn, PyArrayMethods, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyIterator};
use std::sync::Arc;

/// The Python exception for a harness error: `MemoryError` where memory refused, `OSError` where
/// a file could not be read or written, `ValueError` otherwise; the message is the harness's line.
fn py_err(e: CliError) -> PyErr {
    let m = e.message;
    if m.contains("cannot allocate") || m.contains("out of memory") {
        PyMemoryError::new_err(m)
    } else if m.contains("cannot read:") || m.contains("cannot write:") {
        PyOSError::new_err(m)
    } else {
        PyValueError::new_err(m)
    }
}

/// A numpy array's buffer, read in place (see the module docs for why this is sound).
struct Borrowed<T> {
    ptr: *const T,
    len: usize,
}

// SAFETY: the buffer is only read, and stays alive and unwritten by Rust while any `Borrowed`
// exists (module docs); `T` is a plain number type.
unsafe impl<T: Sync> Send for Borrowed<T> {}
// SAFETY: as above: shared reads only.
unsafe impl<T: Sync> Sync for Borrowed<T> {}

impl<T> AsRef<[T]> for Borrowed<T> {
    fn as_ref(&self) -> &[T] {
        // SAFETY: `ptr` and `len` come from a contiguous array's `as_slice` on a read-only
        // borrow that outlives every use of this value (module docs).
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

/// The harness's sample storage for a slice of `T`.
trait SampleKind: Element + Copy + Sync + Send + 'static {
    fn samples(data: Data<Self>) -> Samples;
}

macro_rules! kinds {
    ($($t:ty => $v:ident),*) => {$(
        impl SampleKind for $t {
            fn samples(data: Data<Self>) -> Samples {
                Samples::$v(data)
            }
        }
    )*};
}
kinds!(u8 => U8, i8 => I8, u16 => U16, i16 => I16, u32 => U32, i32 => I32, f32 => F32, f64 => F64);

/// Calls `f` with a volume over `array`'s samples (x fastest: a C-order array is (z, y, x), a
/// Fortran-order one (x, y, z)), shared without a copy where the array is contiguous, copied into
/// C order otherwise; whether it was shared comes with it.
fn with_typed<T: SampleKind, R>(
    array: &Bound<'_, PyArrayDyn<T>>,
    spacing: [f32; 3],
    f: impl FnOnce(Volume, bool) -> PyResult<R>,
) -> PyResult<R> {
    let ro = array.readonly();
    let shape = ro.shape().to_vec();
    if shape.len() != 3 {
        return Err(PyValueError::new_err(format!(
            "the volume has {} dimensions, expected 3",
            shape.len()
        )));
    }
    if shape.contains(&0) {
        return Err(PyValueError::new_err(format!(
            "the volume {shape:?} is empty"
        )));
    }
    check_spacing(spacing).map_err(PyValueError::new_err)?;
    let xyz = is_xyz(
        ro.is_c_contiguous(),
        ro.is_fortran_contiguous(),
        ro.strides(),
    );
    let dims = if xyz {
        [shape[0], shape[1], shape[2]]
    } else {
        [shape[2], shape[1], shape[0]]
    };
    let (data, shared) = match ro.as_slice() {
        Ok(slice) => (
            Data::shared(Arc::new(Borrowed {
                ptr: slice.as_ptr(),
                len: slice.len(),
            })),
            true,
        ),
        // Strided: one copy, x fastest (for (x, y, z) the reversed axes' logical order).
        Err(_) => {
            let view = ro.as_array();
            let copy: Vec<T> = if xyz {
                view.reversed_axes().iter().copied().collect()
            } else {
                view.iter().copied().collect()
            };
            (Data::from(copy), false)
        }
    };
    let volume = Volume::new(dims, spacing, T::samples(data));
    // `ro` (the read-only borrow) lives until `f` returns, and `f` drops the volume.
    let out = f(volume, shared);
    drop(ro);
    out
}

/// Whether an array with these flags and `strides` (bytes per step along each axis) is indexed
/// (x, y, z): Fortran-contiguous, or a strided view whose first axis steps least in memory (a
/// view of a Fortran-order array keeps its strides, so it keeps that array's convention). A
/// C-contiguous array, and a view whose last axis steps least, is (z, y, x).
fn is_xyz(c_contiguous: bool, f_contiguous: bool, strides: &[isize]) -> bool {
    if c_contiguous {
        return false;
    }
    if f_contiguous {
        return true;
    }
    strides[0].unsigned_abs() < strides[2].unsigned_abs()
}

/// [`with_typed`] for whichever supported sample type `array` has.
fn with_volume<R>(
    array: &Bound<'_, PyAny>,
    spacing: [f32; 3],
    f: impl FnOnce(Volume, bool) -> PyResult<R>,
) -> PyResult<R> {
    macro_rules! try_type {
        ($($t:ty),*) => {$(
            if let Ok(a) = array.cast::<PyArrayDyn<$t>>() {
                return with_typed(a, spacing, f);
            }
        )*};
    }
    try_type!(u8, i8, u16, i16, u32, i32, f32, f64);
    let what = array
        .getattr("dtype")
        .map(|d| d.to_string())
        .unwrap_or_else(|_| array.get_type().to_string());
    Err(PyValueError::new_err(format!(
        "a volume of {what} cannot be rendered: give a numpy array of uint8, int8, uint16, int16, \
         uint32, int32, float32 or float64"
    )))
}

fn spacing3(spacing: (f64, f64, f64)) -> [f32; 3] {
    [spacing.0 as f32, spacing.1 as f32, spacing.2 as f32]
}

/// A rendered image: premultiplied RGBA, row-major, top row first, and its (width, height).
type Frame = (Vec<[f32; 4]>, (usize, usize));

/// Runs `work` on a thread of its own with the GIL released, while this thread waits for it and
/// every 50 ms runs Python's signal handlers (`PyErr_CheckSignals`: only the main thread's call
/// does anything). An exception they raise (Ctrl-C's `KeyboardInterrupt`) asks the harness to
/// stop (`footprint_harness::cancel`: renders end at their next sheet or slab), waits for `work`
/// to end, and is raised as itself. `work`'s own error comes back as the harness's
/// ([`py_err`]), or, where `raised` holds an exception Python code raised inside it (a stream's
/// generator), as that exception.
fn interruptible<R: Send>(
    py: Python<'_>,
    raised: Option<&Raised>,
    work: impl FnOnce() -> Result<R, CliError> + Send,
) -> PyResult<R> {
    let (out, interrupt) = py.detach(|| {
        std::thread::scope(|scope| {
            let (tx, rx) = std::sync::mpsc::channel();
            let worker = scope.spawn(move || {
                let out = work();
                let _ = tx.send(());
                out
            });
            let mut interrupt: Option<PyErr> = None;
            loop {
                match rx.recv_timeout(std::time::Duration::from_millis(50)) {
                    Ok(()) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) if interrupt.is_none() => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            footprint_harness::cancel::request();
                            interrupt = Some(e);
                        }
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                }
            }
            let out = worker
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            if interrupt.is_some() {
                footprint_harness::cancel::clear();
            }
            (out, interrupt)
        })
    });
    if let Some(e) = interrupt {
        return Err(e);
    }
    out.map_err(|e| match raised.and_then(Raised::take) {
        Some(err) => err,
        None => py_err(e),
    })
}

/// An exception raised by Python code the harness called (a stream's generator), kept to be
/// raised again as itself: not as the harness's `ValueError` (Ctrl-C stays `KeyboardInterrupt`,
/// `SystemExit` stays `SystemExit`).
#[derive(Clone, Default)]
struct Raised(Arc<std::sync::Mutex<Option<PyErr>>>);

impl Raised {
    fn keep(&self, e: PyErr) {
        let mut slot = self
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        slot.get_or_insert(e);
    }
    fn take(&self) -> Option<PyErr> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take()
    }
}

/// A loaded volume for Python: the array, its spacing (x, y, z) and its metadata.
type Loaded<'py> = (Bound<'py, PyAny>, (f32, f32, f32), Bound<'py, PyDict>);

/// The frame `args` describe, as `footprint render` renders it: premultiplied RGBA and its
/// (width, height); with `--out` or `--json` among the flags, the image and the summary are
/// written as `render` writes them (checked before rendering, all or nothing).
fn frame(args: &RenderArgs) -> Result<Frame, CliError> {
    use footprint_harness::commands::render::{single, write_files};
    footprint_harness::io::outputs::check_image_and_json(
        args.out.as_deref(),
        args.json.as_deref(),
    )?;
    let asked = footprint_harness::args::plan(args)?;
    let inputs = footprint_harness::args::scene(args)?;
    let (image, summary, _) = single(args, &inputs, &asked)?;
    if args.out.is_some() || args.json.is_some() {
        write_files(args, args.out.as_deref(), &image, summary)?;
    }
    Ok((image, args.size))
}

fn to_numpy<'py>(
    py: Python<'py>,
    image: Vec<[f32; 4]>,
    (w, h): (usize, usize),
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let flat: Vec<f32> = image.into_iter().flatten().collect();
    PyArray1::from_vec(py, flat).reshape([h, w, 4])
}

/// Renders `volume` (a 3-D numpy array) with `footprint render`'s flags as typed `keywords`,
/// releasing the GIL.
#[pyfunction]
fn render_array<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    spacing: (f64, f64, f64),
    keywords: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let coordinates = keywords::take_coordinates(keywords)?;
    let mut args: RenderArgs = request(keywords)?;
    let (image, size) = with_volume(volume, spacing3(spacing), |v, _| {
        let v = keywords::on_grid(v, coordinates)?;
        if args.window.is_none() {
            // A constant volume (np.zeros) has no range to map: it renders as the transfer
            // function's low end, where the command line asks for --window.
            let (lo, hi) = v.range();
            if lo == hi {
                let lo = v.values.to_data(lo);
                args.window = Some([lo, lo + lo.abs().max(1.0)]);
            }
        }
        let v = Arc::new(v);
        args.memory = Some(InMemory {
            volume: Arc::clone(&v),
            name: "array".into(),
        });
        let out = interruptible(py, None, || frame(&args));
        args.memory = None;
        debug_assert_eq!(Arc::strong_count(&v), 1, "the volume outlives the call");
        drop(v);
        out
    })?;
    to_numpy(py, image, size)
}

/// Whether an array's samples would be read in place (C- or Fortran-contiguous and of a
/// supported type), for tests and for users who care.
#[pyfunction]
fn shares_memory(volume: &Bound<'_, PyAny>) -> PyResult<bool> {
    with_volume(volume, [1.0; 3], |_, shared| Ok(shared))
}

/// Bytes pulled from a Python iterator of contiguous arrays, one z-slice each (the package
/// checks their shape and type): what `--stream -` reads instead of standard input. The GIL is
/// taken only to fetch the next slice.
struct Slices {
    iter: Py<PyIterator>,
    buf: Vec<u8>,
    at: usize,
    /// Where an exception the iterator raises is kept, to be raised again as itself.
    raised: Raised,
}

impl std::io::Read for Slices {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.at == self.buf.len() {
            let next = Python::attach(|py| -> PyResult<Option<Vec<u8>>> {
                let mut it = self.iter.bind(py).clone();
                match it.next() {
                    None => Ok(None),
                    Some(item) => {
                        let bytes = item?.call_method0("tobytes")?;
                        Ok(Some(bytes.extract::<Vec<u8>>()?))
                    }
                }
            });
            match next {
                Ok(Some(b)) => {
                    self.buf = b;
                    self.at = 0;
                }
                Ok(None) => return Ok(0),
                Err(e) => {
                    let text = e.to_string();
                    self.raised.keep(e);
                    return Err(std::io::Error::other(text));
                }
            }
        }
        let n = out.len().min(self.buf.len() - self.at);
        out[..n].copy_from_slice(&self.buf[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

/// Renders the z-slices `sheets` yields (contiguous arrays of `dtype`, (y, x) each, file order)
/// as `footprint render --stream - --dims ...` renders a pipe, releasing the GIL between slices.
#[pyfunction]
fn render_stream<'py>(
    py: Python<'py>,
    sheets: &Bound<'py, PyAny>,
    dims: (usize, usize, usize),
    dtype: &str,
    spacing: (f64, f64, f64),
    keywords: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    use footprint_harness::args::EndianArg;
    use footprint_harness::io::volume::SampleType;
    let sample_type = match dtype {
        "uint8" => SampleType::U8,
        "int8" => SampleType::I8,
        "uint16" => SampleType::U16,
        "int16" => SampleType::I16,
        "uint32" => SampleType::U32,
        "int32" => SampleType::I32,
        "float32" => SampleType::F32,
        "float64" => SampleType::F64,
        o => {
            return Err(PyValueError::new_err(format!(
                "dtype {o} is not a sample type"
            )))
        }
    };
    for own in [
        "volume",
        "stream",
        "dims",
        "type",
        "sample_type",
        "endian",
        "spacing",
    ] {
        if keywords.contains(own)? {
            return Err(PyValueError::new_err(format!(
                "{own}: render_stream sets it from its own arguments (dims, dtype, spacing)"
            )));
        }
    }
    let mut args: RenderArgs = request(keywords)?;
    // What `--stream - --dims X,Y,Z --type T --endian E --spacing X,Y,Z` would set, typed: the
    // slices arrive in this machine's byte order.
    args.stream = Some("-".into());
    args.dims = Some([dims.0, dims.1, dims.2]);
    args.sample_type = Some(sample_type);
    args.endian = if cfg!(target_endian = "big") {
        EndianArg::Big
    } else {
        EndianArg::Little
    };
    args.spacing = footprint_harness::args::spacing(spacing3(spacing))
        .map_err(|e| PyValueError::new_err(format!("spacing: {e}")))?;
    let raised = Raised::default();
    args.stdin = Some(Pipe::new(Slices {
        iter: PyIterator::from_object(sheets)?.unbind(),
        buf: Vec::new(),
        at: 0,
        raised: raised.clone(),
    }));
    let (image, size) = interruptible(py, Some(&raised), || frame(&args))?;
    to_numpy(py, image, size)
}

/// Loads a volume file: (array (z, y, x) of its sample type, spacing (x, y, z), metadata).
#[pyfunction]
fn load<'py>(py: Python<'py>, path: &str, keywords: &Bound<'py, PyDict>) -> PyResult<Loaded<'py>> {
    let mut args: RenderArgs = request(keywords)?;
    args.volume = Some(path.into());
    let inputs = footprint_harness::args::scene(&args).map_err(py_err)?;
    let raw = footprint_harness::pipeline::stages::load::raw_options(&inputs).map_err(py_err)?;
    let volume = py
        .detach(|| {
            footprint_harness::io::formats::load_array(
                std::path::Path::new(path),
                raw.as_ref(),
                args.array.as_deref(),
            )
        })
        .map_err(py_err)?;
    let [nx, ny, nz] = volume.dims;
    fn arr<'py, T: Element + Copy>(
        py: Python<'py>,
        v: &[T],
        s: [usize; 3],
    ) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_slice(py, v).reshape(s)?.into_any())
    }
    let s = [nz, ny, nx];
    let (array, ty) = match &volume.samples {
        Samples::U8(v) => (arr(py, v, s)?, "uint8"),
        Samples::I8(v) => (arr(py, v, s)?, "int8"),
        Samples::U16(v) => (arr(py, v, s)?, "uint16"),
        Samples::I16(v) => (arr(py, v, s)?, "int16"),
        Samples::U32(v) => (arr(py, v, s)?, "uint32"),
        Samples::I32(v) => (arr(py, v, s)?, "int32"),
        Samples::F32(v) => (arr(py, v, s)?, "float32"),
        Samples::F64(v) => (arr(py, v, s)?, "float64"),
        Samples::Coloured(_) => {
            return Err(PyValueError::new_err("a coloured level is not a file"))
        }
    };
    let meta = PyDict::new(py);
    meta.set_item("dims", (nx, ny, nz))?;
    meta.set_item("type", ty)?;
    meta.set_item("directions", volume.directions.to_vec())?;
    meta.set_item("path", path)?;
    let sp = volume.spacing;
    Ok((array, (sp[0], sp[1], sp[2]), meta))
}

/// Runs `verify` or `bench` (`command`) built from typed `keywords` on `volume`: an array
/// (rendered in place of VOLUME), or None (a file path or the built-in scene: the `volume`
/// keyword). Nothing is printed (`json=` writes the summary); the GIL is released.
#[pyfunction]
#[pyo3(signature = (command, keywords, volume=None, spacing=None))]
fn run_measure(
    py: Python<'_>,
    command: &str,
    keywords: &Bound<'_, PyDict>,
    volume: Option<&Bound<'_, PyAny>>,
    spacing: Option<(f64, f64, f64)>,
) -> PyResult<()> {
    use footprint_harness::cli::Command;
    let command = match command {
        "verify" => Command::Verify(request(keywords)?),
        "bench" => Command::Bench(request(keywords)?),
        o => {
            return Err(PyValueError::new_err(format!(
                "{o}: verify or bench is measured"
            )))
        }
    };
    let run = move |memory: Option<InMemory>| {
        py.detach(|| footprint_harness::cli::run_command(command, memory))
            .map_err(py_err)
    };
    match volume {
        None => run(None),
        Some(v) => with_volume(v, spacing3(spacing.unwrap_or((1.0, 1.0, 1.0))), |v, _| {
            run(Some(InMemory {
                volume: Arc::new(v),
                name: "array".into(),
            }))
        }),
    }
}

/// Runs a `footprint` command line (without the program name): what the package uses for
/// `tables`. Nothing is printed; the GIL is released.
#[pyfunction]
fn run_command(py: Python<'_>, args: Vec<String>) -> PyResult<()> {
    let argv: Vec<String> = std::iter::once("footprint".to_string())
        .chain(args)
        .collect();
    py.detach(|| footprint_harness::run_with(argv, None))
        .map_err(py_err)
}

/// The generic table of `kernel` (a `--kernel` spec) at `size`² nodes, as an array.
#[pyfunction]
fn generic_table<'py>(py: Python<'py>, kernel: &str, size: usize) -> PyResult<Bound<'py, PyAny>> {
    let k = footprint::Kernel::parse(kernel)
        .map_err(|e| PyValueError::new_err(format!("--kernel '{kernel}': {e}")))?;
    struct Values(footprint::Kernel);
    impl footprint_harness::dispatch::TableSize for Values {
        type Output = Vec<f32>;
        fn run<const N: usize>(self) -> Result<Vec<f32>, CliError> {
            Ok(footprint::GenericTable::<N>::build(self.0)
                .as_slice()
                .to_vec())
        }
    }
    let values = footprint_harness::dispatch::with_size(size, Values(k)).map_err(py_err)?;
    Ok(PyArray1::from_vec(py, values)
        .reshape([size, size])?
        .into_any())
}

/// Premultiplied float RGBA as 8-bit RGBA (each channel clamped to [0, 1] and rounded), as the
/// command line's PNG holds it.
#[pyfunction]
fn to_rgba8<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<'py, f32>,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = image.shape().to_vec();
    let bytes: Vec<u8> = image
        .as_array()
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    Ok(PyArray1::from_vec(py, bytes)
        .reshape([shape[0], shape[1], shape[2]])?
        .into_any())
}

#[pymodule]
fn _footprint(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Results come back as values and files: the commands print nothing to stdout here.
    footprint_harness::QUIET.store(true, std::sync::atomic::Ordering::Relaxed);
    m.add_function(wrap_pyfunction!(render_array, m)?)?;
    m.add_function(wrap_pyfunction!(render_stream, m)?)?;
    m.add_function(wrap_pyfunction!(shares_memory, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(run_command, m)?)?;
    m.add_function(wrap_pyfunction!(run_measure, m)?)?;
    m.add_function(wrap_pyfunction!(depth::depth_array, m)?)?;
    m.add_function(wrap_pyfunction!(depth::probe_pixel, m)?)?;
    m.add_function(wrap_pyfunction!(generic_table, m)?)?;
    m.add_function(wrap_pyfunction!(to_rgba8, m)?)?;
    Ok(())
}
