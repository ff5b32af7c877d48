//! Rectilinear grids (issue 77, item 5): a VTK XML `.vtr` whose samples stand at per-axis
//! coordinates. Each sample's kernel is scaled per side to its own spacings, and the continuous
//! model is the uniform grid's field composed with the piecewise-linear map from position to
//! sample index (`footprint::refine`, "Rectilinear grids"; `reference::warp`), so the field stays
//! the uniform lattice's partition of unity.

use crate::cut::frame;
use footprint_harness::args::{parse_args, plan, scene};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_ref};
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{json_numbers, max_abs_diff, path_str as s, rgb_psnr, run_cli, tmpdir};
use std::path::{Path, PathBuf};

const DIMS: [usize; 3] = [28, 24, 20];

/// Coordinates, world units: x even but for a ±30 % wave, y even, z geometric from 0.5 to 2
/// (a ratio of 4 from bottom to top, as an atmosphere's levels thin with height).
fn coordinates(even: bool) -> [Vec<f64>; 3] {
    let axis = |n: usize, gap: &dyn Fn(usize) -> f64| {
        let mut c = vec![0.0];
        for i in 0..n - 1 {
            c.push(c[i] + if even { 1.0 } else { gap(i) });
        }
        c
    };
    [
        axis(DIMS[0], &|i| 1.0 + 0.3 * (i as f64 * 0.45).sin()),
        axis(DIMS[1], &|_| 1.0),
        axis(DIMS[2], &|i| {
            0.5 * 4f64.powf(i as f64 / (DIMS[2] - 2) as f64)
        }),
    ]
}

/// Two Gaussian blobs in world coordinates at the samples of `c`, x fastest.
fn values(c: &[Vec<f64>; 3]) -> Vec<f32> {
    let centre = c.clone().map(|a| 0.5 * (a[0] + a[a.len() - 1]));
    let mut out = Vec::new();
    for &z in &c[2] {
        for &y in &c[1] {
            for &x in &c[0] {
                let d = |s: [f64; 3], o: [f64; 3]| {
                    let q = [
                        x - centre[0] - o[0],
                        y - centre[1] - o[1],
                        z - centre[2] - o[2],
                    ];
                    -(0..3).map(|a| (q[a] / s[a]).powi(2)).sum::<f64>()
                };
                let v = 100.0 * d([7.0, 6.0, 6.0], [0.0; 3]).exp()
                    + 80.0 * d([2.5, 2.5, 2.5], [4.0, -3.0, 4.0]).exp();
                out.push(v as f32);
            }
        }
    }
    out
}

/// Whitespace-separated numbers.
fn text<T: std::fmt::Debug>(v: &[T]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Writes `v` on coordinates `c` as a `.vtr` (ascii arrays).
fn vtr(path: &Path, c: &[Vec<f64>; 3], v: &[f32]) {
    let [nx, ny, nz] = c.clone().map(|a| a.len() - 1);
    let array = |name: &str, ty: &str, body: String| {
        format!("<DataArray type=\"{ty}\" Name=\"{name}\" format=\"ascii\">{body}</DataArray>")
    };
    std::fs::write(
        path,
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"RectilinearGrid\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n<RectilinearGrid WholeExtent=\"0 {nx} 0 {ny} 0 {nz}\">\n\
             <Piece Extent=\"0 {nx} 0 {ny} 0 {nz}\">\n<PointData Scalars=\"v\">{}</PointData>\n\
             <Coordinates>{}{}{}</Coordinates>\n</Piece></RectilinearGrid></VTKFile>\n",
            array("v", "Float32", text(v)),
            array("x", "Float64", text(&c[0])),
            array("y", "Float64", text(&c[1])),
            array("z", "Float64", text(&c[2])),
        ),
    )
    .unwrap();
}

/// Two blobs on the grid of [`coordinates`] written as `dir/name`: its path, coordinates and
/// values.
fn written(dir: &Path, name: &str, even: bool) -> (PathBuf, [Vec<f64>; 3], Vec<f32>) {
    let c = coordinates(even);
    let v = values(&c);
    let path = dir.join(name);
    vtr(&path, &c, &v);
    (path, c, v)
}

/// Writes `v` as a `.vti` of spacing `spacing`.
fn vti(path: &Path, spacing: [f64; 3], v: &[f32]) {
    let [nx, ny, nz] = DIMS.map(|n| n - 1);
    std::fs::write(
        path,
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 {nx} 0 {ny} 0 {nz}\" \
             Origin=\"0 0 0\" Spacing=\"{:?} {:?} {:?}\">\n<Piece Extent=\"0 {nx} 0 {ny} 0 {nz}\">\n\
             <PointData Scalars=\"v\"><DataArray type=\"Float32\" Name=\"v\" format=\"ascii\">{}\
             </DataArray></PointData>\n</Piece></ImageData></VTKFile>\n",
            spacing[0] as f32,
            spacing[1] as f32,
            spacing[2] as f32,
            text(v)
        ),
    )
    .unwrap();
}

fn flags<'a>(volume: &'a str, view: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let mut f = vec![
        volume, "--size", "96x96", "--view", view, "--window", "10,90",
    ];
    f.extend_from_slice(more);
    f
}

/// The target: at least 40 dB against the continuous model on the grid, two views, emission and
/// Phong; and the picture is visibly not that of the same values on a uniform grid of the mean
/// spacing.
#[test]
fn a_rectilinear_grid_meets_its_continuous_model() {
    let dir = tmpdir("rectilinear");
    let (path, c, v) = written(&dir, "blobs.vtr", false);
    let mean = c
        .clone()
        .map(|a| (a[a.len() - 1] - a[0]) / (a.len() - 1) as f64);
    let uniform = dir.join("blobs.vti");
    vti(&uniform, mean, &v);
    for view in ["0,0,0", "30,20,0", "120,-35,5"] {
        for shading in ["emission", "phong"] {
            let a = flags(s(&path), view, &["--shading", shading]);
            let args = parse_args(&a).unwrap();
            let (f, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
            let (truth, _) = render_continuous_ref(r.prepared(), Reconstruction::Kernel).unwrap();
            let db = compare(&f.image, &truth.image).1.psnr_db;
            assert!(db >= 40.0, "{view} {shading}: {db:.2} dB against the model");
            let flat = frame(&flags(
                s(&uniform),
                view,
                &["--shading", shading, "--slicing", "object"],
            ));
            let apart = rgb_psnr(&f.image, &flat);
            if view != "0,0,0" {
                assert!(
                    apart < 30.0,
                    "{view} {shading}: the uniform grid's picture is {apart:.1} dB away"
                );
            }
        }
    }
}

/// Coordinates one step apart are the uniform grid: the `.vtr` renders the `.vti`'s sheets
/// (within the table walk's rounding: the rectilinear samples read their footprints at scaled
/// coordinates), and `info` reports the grid.
#[test]
fn even_coordinates_render_the_uniform_picture_and_info_knows_the_grid() {
    let dir = tmpdir("rectilinear-even");
    let (path, _, v) = written(&dir, "even.vtr", true);
    let uniform = dir.join("even.vti");
    vti(&uniform, [1.0; 3], &v);
    for view in ["30,20,0", "120,-35,5"] {
        let a = frame(&flags(s(&path), view, &[]));
        let b = frame(&flags(s(&uniform), view, &["--slicing", "object"]));
        let d = max_abs_diff(&a, &b);
        assert!(d < 2e-3, "{view}: {d}");
    }
    let (uneven, _, _) = written(&dir, "uneven.vtr", false);
    let json = dir.join("info.json");
    assert_eq!(run_cli(&["info", s(&uneven), "--json", s(&json)]), 0);
    let text = std::fs::read_to_string(&json).unwrap();
    let z = json_numbers(&text, "z");
    assert_eq!(z.len(), 4, "first, last, least and greatest gap: {z:?}");
    assert!(
        (z[2] - 0.5).abs() < 1e-9 && (z[3] - 2.0).abs() < 1e-9,
        "{z:?}"
    );
    let mean = json_numbers(&text, "spacing");
    assert!(
        (f64::from(mean[2] as f32) - (z[1] - z[0]) / 19.0).abs() < 1e-5,
        "{mean:?}"
    );
}
