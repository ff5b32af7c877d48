//! Multi-component volumes (issue 77, item 3, second half): a MetaImage or VTK XML image of 2 to
//! 4 components per voxel, each through its own transfer function (`--tf` repeated) or, with 4
//! components, as RGBA directly. Each voxel's colour and opacity are classified from its
//! components before reconstruction, into a palette the renderer reads as a label volume
//! (`pipeline::stages::components`); the continuous model is the pre-classified one of those
//! colours.

use crate::cut::frame;
use footprint_harness::args::{parse_args, plan, scene};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_ref};
use footprint_harness::plan::DEFAULT_TARGET_DB;
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{path_str as s, tmpdir};

const N: usize = 24;

/// Two overlapping balls as two components in [0, 1]: a tent of radius 8 voxels around x = ∓4.
fn balls() -> Vec<[f32; 2]> {
    let mut out = Vec::with_capacity(N * N * N);
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                let c = |x0: f32| {
                    let p = [i as f32 - x0, j as f32, k as f32].map(|x| x - (N as f32 - 1.0) / 2.0);
                    let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                    (1.0 - d / 8.0).max(0.0)
                };
                out.push([c(-4.0), c(4.0)]);
            }
        }
    }
    out
}

/// A MetaImage of `components` interleaved f32 or u8 samples.
fn metaimage(path: &std::path::Path, components: usize, ty: &str, data: &[u8]) {
    let head = format!(
        "ObjectType = Image\nNDims = 3\nDimSize = {N} {N} {N}\nElementType = {ty}\n\
         ElementNumberOfChannels = {components}\nElementSpacing = 1 1 2\nElementDataFile = LOCAL\n"
    );
    std::fs::write(path, [head.as_bytes(), data].concat()).unwrap();
}

/// Red and blue ramps for the two components.
fn tfs(dir: &std::path::Path) -> [String; 2] {
    let red = dir.join("red.tf");
    let blue = dir.join("blue.tf");
    std::fs::write(&red, "0 1 0 0 0\n1 1 0.2 0 0.6\n").unwrap();
    std::fs::write(&blue, "0 0 0 1 0\n1 0 0.4 1 0.6\n").unwrap();
    [s(&red).to_string(), s(&blue).to_string()]
}

/// Each component through its own transfer function meets the target against the model of the
/// classified colours, two views; the VTI and the MetaImage of the same samples render the same
/// picture, bit for bit; the two components mix where both balls are (violet) and stay pure
/// where one is.
#[test]
fn two_components_each_through_its_transfer_function() {
    let dir = tmpdir("components");
    let values = balls();
    let bytes: Vec<u8> = values
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let mha = dir.join("balls.mha");
    metaimage(&mha, 2, "MET_FLOAT", &bytes);
    let text: Vec<String> = values.iter().flatten().map(|v| format!("{v:?}")).collect();
    let vti = dir.join("balls.vti");
    std::fs::write(
        &vti,
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 {m} 0 {m} 0 {m}\" \
             Origin=\"0 0 0\" Spacing=\"1 1 2\">\n<Piece Extent=\"0 {m} 0 {m} 0 {m}\">\n\
             <PointData Scalars=\"c\"><DataArray type=\"Float32\" Name=\"c\" \
             NumberOfComponents=\"2\" format=\"ascii\">{}</DataArray></PointData>\n\
             </Piece></ImageData></VTKFile>\n",
            text.join(" "),
            m = N - 1
        ),
    )
    .unwrap();
    let [red, blue] = tfs(&dir);
    for view in ["0,0,0", "30,20,0"] {
        let flags = |v: &std::path::Path| {
            vec![
                s(v).to_string(),
                "--tf".into(),
                red.clone(),
                "--tf".into(),
                blue.clone(),
                "--window".into(),
                "0,1".into(),
                "--size".into(),
                "64x64".into(),
                "--view".into(),
                view.into(),
            ]
        };
        let a: Vec<String> = flags(&mha);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let args = parse_args(&a).unwrap();
        let (f, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
        let (truth, _) = render_continuous_ref(r.prepared(), Reconstruction::Kernel).unwrap();
        let db = compare(&f.image, &truth.image).1.psnr_db;
        assert!(
            db >= DEFAULT_TARGET_DB,
            "{view}: {db:.2} dB against the model"
        );
        let b: Vec<String> = flags(&vti);
        let b: Vec<&str> = b.iter().map(String::as_str).collect();
        assert!(
            frame(&b) == f.image,
            "{view}: the VTI renders the MetaImage's picture"
        );
        if view == "0,0,0" {
            // Middle row: red at the left ball's centre, blue at the right's, both between.
            let row = &f.image[32 * 64..33 * 64];
            let (left, right) = (row[32 - 12], row[32 + 12]);
            assert!(left[0] > 4.0 * left[2], "left {left:?} is red");
            assert!(right[2] > 4.0 * right[0], "right {right:?} is blue");
            let mid = row[32];
            assert!(
                mid[0] > 0.05 && mid[2] > 0.05,
                "the middle {mid:?} mixes both"
            );
        }
    }
}

/// Four components without `--tf` are RGBA: the picture is that of a label volume whose labels
/// carry those colours (the palette in order of first appearance), bit for bit.
#[test]
fn four_components_are_rgba() {
    let dir = tmpdir("rgba");
    let values = balls();
    let colour = |v: [f32; 2]| -> [u8; 4] {
        match (v[0] > 0.0, v[1] > 0.0) {
            (true, _) => [255, 51, 0, 120],
            (false, true) => [0, 102, 255, 60],
            _ => [0; 4],
        }
    };
    let rgba: Vec<u8> = values.iter().flat_map(|&v| colour(v)).collect();
    let mha = dir.join("rgba.mha");
    metaimage(&mha, 4, "MET_UCHAR", &rgba);
    let labels: Vec<u8> = values
        .iter()
        .map(|&v| match colour(v) {
            [0, 0, 0, 0] => 0,
            [255, ..] => 1,
            _ => 2,
        })
        .collect();
    // Red appears first (x-fastest, the left ball's voxels come first in its first row).
    let first = labels.iter().find(|&&l| l != 0).copied();
    assert_eq!(first, Some(1));
    let raw = dir.join("labels.raw");
    std::fs::write(&raw, &labels).unwrap();
    let c = |x: u8| f64::from(x) / 255.0;
    let table = format!(
        "{{\"1\": [{}, {}, {}, {}], \"2\": [{}, {}, {}, {}]}}",
        c(255),
        c(51),
        c(0),
        c(120),
        c(0),
        c(102),
        c(255),
        c(60)
    );
    let common = ["--size", "64x64", "--view", "30,20,0"];
    let mut a = vec![s(&mha)];
    a.extend_from_slice(&common);
    let direct = frame(&a);
    let dims = format!("{N},{N},{N}");
    let mut b = vec![
        s(&raw),
        "--dims",
        &dims,
        "--type",
        "u8",
        "--spacing",
        "1,1,2",
    ];
    b.extend_from_slice(&["--labels", &table]);
    b.extend_from_slice(&common);
    assert!(
        direct == frame(&b),
        "RGBA is the label volume of its colours"
    );
    assert!(direct.iter().any(|p| p[0] > 0.1) && direct.iter().any(|p| p[2] > 0.1));
}
