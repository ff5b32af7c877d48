//! Shared helpers for the integration tests and benches: brute-force integrals (no closed forms),
//! view construction, single-sample renders through the harness, and tolerance checks that say
//! what they found.

use footprint::Kernel;
use footprint_harness::args::{FootprintArgs, LookupArg, MethodArg};
use footprint_harness::io::image::GreyImage;
use footprint_harness::metrics::compare;
use footprint_harness::{args::SplatArgs, pipeline::ends::single::splat_image};
use glam::{DMat3, Mat3};
use std::path::PathBuf;

/// Runs the `footprint` command line `args` (without the program name) in-process, through
/// `footprint_harness::run`, the binary's own entry point; returns its exit code.
pub fn run_cli(args: &[&str]) -> i32 {
    footprint_harness::run(std::iter::once("footprint").chain(args.iter().copied()))
}

/// The number after the first `"key": ` in the JSON text `text` (a command's `--json`); panics,
/// naming the key, where there is none.
pub fn json_number(text: &str, key: &str) -> f64 {
    let at = text
        .find(&format!("\"{key}\": "))
        .unwrap_or_else(|| panic!("no {key} in {text}"));
    let rest = &text[at + key.len() + 4..];
    let end = rest.find([',', '\n', '}']).unwrap_or(rest.len());
    rest[..end]
        .trim()
        .parse()
        .unwrap_or_else(|e| panic!("{key}: {e} in {text}"))
}

/// The numbers of the first JSON array `key` in `text` (a flat array of numbers).
pub fn json_numbers(text: &str, key: &str) -> Vec<f64> {
    let at = text
        .find(&format!("\"{key}\""))
        .unwrap_or_else(|| panic!("no {key} in {text}"));
    let rest = &text[at..];
    let (open, close) = (rest.find('[').unwrap(), rest.find(']').unwrap());
    rest[open + 1..close]
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect()
}

/// A test path as the `&str` a command line takes.
pub fn path_str(p: &std::path::Path) -> &str {
    p.to_str().expect("a UTF-8 test path")
}

/// PSNR (dB, peak 1) of `a` against `b` over R, G and B together: the overall figure of the
/// harness's `metrics::compare` (what `verify` reports), for two f32 images.
pub fn rgb_psnr(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let b: Vec<[f64; 4]> = b.iter().map(|p| p.map(f64::from)).collect();
    compare(a, &b).1.psnr_db
}

/// The largest channel difference between two RGBA images of the same size.
pub fn max_abs_diff(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0f32, f32::max)
}

/// Composite Simpson's rule for ∫ₐᵇ f, with `steps` (even) intervals.
pub fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, steps: usize) -> f64 {
    let h = (b - a) / steps as f64;
    let inner: f64 = (1..steps)
        .map(|i| f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + inner + f(b)) * h / 3.0
}

/// Brute-force footprint of a radial 3D kernel: ∫ h(√(ρ² + s²)) ds over the chord through the
/// unit ball, by Simpson's rule with `steps` intervals. `h` takes r in unit coordinates.
pub fn line_integral(h: impl Fn(f64) -> f64, rho: f64, steps: usize) -> f64 {
    if rho >= 1.0 {
        return 0.0;
    }
    let half = (1.0 - rho * rho).sqrt();
    simpson(|s| h((rho * rho + s * s).sqrt()), -half, half, steps)
}

/// The truncated 3D Gaussian h(r) = e^(−r²·sigmas²/2) for r ≤ 1, in unit coordinates. The
/// support is closed so that Simpson's end points, which sit exactly on the sphere, take the
/// kernel's value there rather than zero (a rounding margin of 1e-12 keeps them inside).
pub fn gaussian_3d(sigmas: f64) -> impl Fn(f64) -> f64 {
    move |r| {
        if r <= 1.0 + 1e-12 {
            (-0.5 * r * r * sigmas * sigmas).exp()
        } else {
            0.0
        }
    }
}

/// ∫_ball h d³u by Simpson on the radial integral 4π∫r²h(r)dr.
pub fn ball_integral(h: impl Fn(f64) -> f64, steps: usize) -> f64 {
    4.0 * std::f64::consts::PI * simpson(|r| r * r * h(r), 0.0, 1.0, steps)
}

/// A world-to-screen matrix: rotation by Euler angles (degrees, applied x then y then z) times a
/// uniform zoom (pixels per world unit).
pub fn view(rx: f32, ry: f32, rz: f32, zoom: f32) -> Mat3 {
    Mat3::from_rotation_z(rz.to_radians())
        * Mat3::from_rotation_y(ry.to_radians())
        * Mat3::from_rotation_x(rx.to_radians())
        * zoom
}

/// Row-major nine numbers of a matrix, as `--view-matrix` takes them.
pub fn rows(m: &Mat3) -> [f32; 9] {
    m.transpose().to_cols_array()
}

/// Default `footprint splat` arguments (paper Gaussian, spacing 60,30,30, 256×256, table 65,
/// bilinear, robust) for tests to modify.
pub fn splat_args() -> SplatArgs {
    SplatArgs {
        footprint: FootprintArgs {
            kernel: "gaussian:spread=1.6,sigmas=2.5".into(),
            table: 65,
            table_file: None,
            lookup: LookupArg::Bilinear,
            method: MethodArg::Robust,
            min_radius: footprint::geometry::DEFAULT_MIN_RADIUS_PX,
            paper_cheat: 0.01,
        },
        spacing: [60.0, 30.0, 30.0],
        grid_matrix: None,
        view_matrix: None,
        rotate_x: 0.0,
        rotate_y: 0.0,
        rotate_z: 0.0,
        size: (256, 256),
        center: None,
        out: PathBuf::from("unused.pfm"),
    }
}

/// Renders `args` with its method and with `--method reference`; returns (core, reference).
pub fn with_reference(args: &SplatArgs) -> (GreyImage, GreyImage) {
    let core = splat_image(&footprint_harness::args::single(args).expect("resolved"))
        .expect("core splat")
        .0;
    let mut r = args.clone();
    r.footprint.method = MethodArg::Reference;
    let reference = footprint_harness::args::single(&r).expect("resolved");
    (core, splat_image(&reference).expect("reference splat").0)
}

/// max |a − b| / max(b): the footprint difference relative to the reference's peak.
pub fn max_rel_diff(a: &GreyImage, b: &GreyImage) -> f64 {
    footprint_harness::metrics::max_rel_diff(a, b).expect("comparable images")
}

/// Asserts `value <= bound`, printing both and the context.
#[track_caller]
pub fn assert_le(value: f64, bound: f64, what: &str) {
    assert!(
        value.is_finite() && value <= bound,
        "{what}: got {value:.6e}, bound {bound:.6e}"
    );
}

/// f64 copy of an f32 matrix.
pub fn dmat(m: &Mat3) -> DMat3 {
    m.as_dmat3()
}

/// The four kernels at their defaults, by spec.
pub fn default_kernels() -> [Kernel; 4] {
    ["gaussian", "cone", "sinc", "bilinear"].map(|s| Kernel::parse(s).expect("default spec"))
}

/// Proptest settings for this suite: `cases` random cases, no regression files (the suite's lib
/// lives at `tests/support/lib.rs`, where proptest cannot find a source root to store them; a
/// failure prints its minimal input, which a test can then pin).
pub fn proptest_config(cases: u32) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        failure_persistence: None,
        ..Default::default()
    }
}

/// One in value and opacity: the transfer function of [`render_with`] (pre-shaded sheets do not
/// use it, but the renderer checks one).
const UNIT_LUT: [[f32; 4]; 2] = [[0.0; 4], [1.0; 4]];

/// Renders pre-shaded sheets (`sheet(s)` gives sheet s's premultiplied RGBA) of frame `f` with
/// `path` in `order`, emission, caller-free buffers; returns the image.
pub fn render_with<P: footprint::render::Precision>(
    f: &footprint::frame::FrameSetup,
    path: P,
    order: footprint::frame::Order,
    sheet: &dyn Fn(usize) -> Vec<[f32; 4]>,
) -> Vec<P::Pixel> {
    try_render_with(f, path, order, sheet).unwrap()
}

/// [`render_with`], returning the renderer's first error instead of panicking on it.
pub fn try_render_with<P: footprint::render::Precision>(
    f: &footprint::frame::FrameSetup,
    path: P,
    order: footprint::frame::Order,
    sheet: &dyn Fn(usize) -> Vec<[f32; 4]>,
) -> Result<Vec<P::Pixel>, footprint::render::RenderError> {
    use footprint::render::{RenderBuffers, SheetRenderer};
    use footprint::shade::{Shader, Shading, TransferFunction};
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: &UNIT_LUT,
            lo: 0.0,
            hi: 1.0,
        },
        shading: Shading::Emission,
    };
    let n = f.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![P::ACC_ZERO; n],
        vec![P::CLEAR; n],
        vec![footprint::composite::RowSpan::EMPTY; f.size[1]],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r = SheetRenderer::with_path(f, path, shader, order, buffers, None)?;
    for step in 0..f.sheet_count() {
        let s = f.sheet_at(order, step);
        r.render_shaded_sheet(s, &sheet(s))?;
    }
    r.finish();
    Ok(img)
}

/// An empty folder for one test, `fp-NAME-…` in the system's temporary folder, removed with
/// everything in it when the value is dropped (when the test ends, passed or failed).
pub fn tmpdir(name: &str) -> TestDir {
    TestDir(
        tempfile::Builder::new()
            .prefix(&format!("fp-{name}-"))
            .tempdir()
            .expect("a temporary folder for the test"),
    )
}

/// A test's folder (see [`tmpdir`]): a [`Path`](std::path::Path) while it lives.
pub struct TestDir(tempfile::TempDir);

impl std::ops::Deref for TestDir {
    type Target = std::path::Path;

    fn deref(&self) -> &std::path::Path {
        self.0.path()
    }
}

impl AsRef<std::path::Path> for TestDir {
    fn as_ref(&self) -> &std::path::Path {
        self.0.path()
    }
}

/// `--quality`'s choice for the flags `args`, as `footprint render` applies it: the prepared
/// render at the level chosen, the plan chosen (with no `quality`), and the choice.
pub fn apply_quality(
    p: footprint_harness::pipeline::Prepared,
    args: &footprint_harness::args::RenderArgs,
) -> Result<
    (
        footprint_harness::pipeline::Prepared,
        footprint_harness::plan::Plan,
        Option<footprint_harness::pipeline::quality::model::Choice>,
    ),
    footprint_harness::CliError,
> {
    let plan = footprint_harness::args::plan(args)?;
    let inputs = footprint_harness::args::scene(args)?;
    footprint_harness::pipeline::quality::choose::apply_quality(p, &inputs, &plan)
}

/// The pilot's choice against the continuous integral for the flags `args` (see
/// `pipeline::quality::pilot::choose_continuous`).
pub fn choose_continuous(
    p: &footprint_harness::pipeline::Prepared,
    args: &footprint_harness::args::RenderArgs,
    target_db: f64,
    reference: footprint_harness::args::QualityReferenceArg,
) -> Result<footprint_harness::pipeline::quality::model::Choice, footprint_harness::CliError> {
    let plan = footprint_harness::args::plan(args)?;
    let inputs = footprint_harness::args::scene(args)?;
    footprint_harness::pipeline::quality::pilot::choose_continuous(
        p,
        &inputs,
        &plan,
        target_db,
        reference.into(),
    )
}

/// The plan `args` describes with configuration `c` applied (what `--quality` and `chart`
/// render).
pub fn plan_with(
    args: &footprint_harness::args::RenderArgs,
    c: &footprint_harness::pipeline::quality::config::Config,
) -> footprint_harness::plan::Plan {
    c.plan(&footprint_harness::args::plan(args).unwrap())
}
