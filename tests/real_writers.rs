//! Files written by the real writers users' volumes come from (VTK 9, SimpleITK, nibabel, pynrrd;
//! `tests/writers/make_fixtures.py`) load to exactly the original samples, grid and orientation,
//! and render exactly the image the raw original renders.
//!
//! The fixtures are read from `$FOOTPRINT_WRITER_FIXTURES` if set (CI writes them fresh there with
//! the current releases of the writers: `tests/writers/run.sh`), else from the copy committed in
//! `tests/data/writers` (so `cargo test` checks them without Python).
//!
//! Orientation: where a writer converts ITK's LPS directions to NIfTI's RAS (SimpleITK writing
//! NIfTI), the manifest says `ras`, and the test checks that the loaded grid has x and y negated
//! and renders the same as the raw original with that flip.

use footprint_harness::io::formats;
use footprint_harness::io::volume::Volume;
use std::path::{Path, PathBuf};

const DIMS: [usize; 3] = [12, 10, 8];
const SPACING: [f32; 3] = [1.0, 1.5, 2.0];

fn fixtures() -> PathBuf {
    match std::env::var_os("FOOTPRINT_WRITER_FIXTURES") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/writers"),
    }
}

struct Entry {
    file: String,
    writer: String,
    orientation: String,
    array: Option<String>,
}

fn manifest(dir: &Path) -> Vec<Entry> {
    let text = std::fs::read_to_string(dir.join("manifest.tsv"))
        .unwrap_or_else(|e| panic!("{}: {e}", dir.join("manifest.tsv").display()));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            assert_eq!(f.len(), 4, "manifest line '{l}'");
            Entry {
                file: f[0].into(),
                writer: f[1].into(),
                orientation: f[2].into(),
                array: (f[3] != "-").then(|| f[3].to_string()),
            }
        })
        .collect()
}

fn directions(orientation: &str) -> [[f32; 3]; 3] {
    match orientation {
        "identity" => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        "ras" => [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
        o => panic!("unknown orientation '{o}'"),
    }
}

fn original(dir: &Path) -> Vec<f32> {
    let raw = std::fs::read(dir.join("original.raw")).unwrap();
    assert_eq!(raw.len(), 2 * DIMS.iter().product::<usize>());
    raw.chunks(2)
        .map(|b| f32::from(i16::from_le_bytes([b[0], b[1]])))
        .collect()
}

/// The raw original as an NRRD whose `space directions` carry `orientation`.
fn reference_nrrd(dir: &Path, tmp: &Path, orientation: &str) -> PathBuf {
    let d = directions(orientation);
    let col = |c: usize| {
        format!(
            "({},{},{})",
            d[c][0] * SPACING[c],
            d[c][1] * SPACING[c],
            d[c][2] * SPACING[c]
        )
    };
    let path = tmp.join(format!("reference-{orientation}.nhdr"));
    std::fs::write(
        &path,
        format!(
            "NRRD0004\ntype: int16\ndimension: 3\nsizes: {} {} {}\nspace dimension: 3\n\
             space directions: {} {} {}\nendian: little\nencoding: raw\ndata file: {}\n",
            DIMS[0],
            DIMS[1],
            DIMS[2],
            col(0),
            col(1),
            col(2),
            dir.join("original.raw").display()
        ),
    )
    .unwrap();
    path
}

fn render(file: &Path, array: Option<&str>, out: &Path) -> Vec<u8> {
    let mut args = vec![
        "footprint".to_string(),
        "render".into(),
        file.display().to_string(),
        "--size".into(),
        "48x48".into(),
        "--view".into(),
        "30,20,0".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    if let Some(a) = array {
        args.extend(["--array".to_string(), a.to_string()]);
    }
    assert_eq!(footprint_harness::run(args), 0, "render {}", file.display());
    std::fs::read(out).unwrap()
}

fn check_grid(v: &Volume, e: &Entry) {
    assert_eq!(v.dims, DIMS, "{}: dims", e.file);
    for (got, want) in v.spacing.iter().zip(SPACING) {
        assert!(
            (got - want).abs() < 1e-5,
            "{}: spacing {:?}",
            e.file,
            v.spacing
        );
    }
    let want = directions(&e.orientation);
    for (c, col) in want.iter().enumerate() {
        for (got, want_r) in v.directions[c].iter().zip(col) {
            assert!(
                (got - want_r).abs() < 1e-5,
                "{} ({}): directions {:?}, expected {want:?} ({})",
                e.file,
                e.writer,
                v.directions,
                e.orientation
            );
        }
    }
}

#[test]
fn every_real_writer_file_loads_and_renders_as_the_raw_original() {
    let dir = fixtures();
    let entries = manifest(&dir);
    // Every category the issue names is present (a writer release that stops writing one shows).
    let names: Vec<&str> = entries.iter().map(|e| e.file.as_str()).collect();
    for mode in [
        "ascii-none",
        "binary-none",
        "binary-zlib",
        "binary-lz4",
        "binary-lzma",
        "appended-raw-none",
        "appended-raw-zlib",
        "appended-raw-lz4",
        "appended-raw-lzma",
        "appended-base64-none",
        "appended-base64-zlib",
        "appended-base64-lz4",
        "appended-base64-lzma",
    ] {
        for header in ["UInt32", "UInt64"] {
            let f = format!("vtk-xml-{mode}-{header}.vti");
            assert!(names.contains(&f.as_str()), "{f} missing");
        }
    }
    for f in [
        "vtk-legacy-binary.vtk",
        "vtk-legacy-ascii.vtk",
        "vtk-legacy-binary-arrays.vtk",
        "sitk.mha",
        "sitk.mhd",
        "sitk.nii",
        "sitk.nii.gz",
        "sitk.nrrd",
        "nib1.nii",
        "nib2.nii",
        "nib2.nii.gz",
        "nib1-pair.hdr",
        "nib1-pairgz.img.gz",
        "nib2-pair.img",
        "pynrrd-gzip.nrrd",
        "pynrrd-detached.nhdr",
    ] {
        assert!(names.contains(&f), "{f} missing");
    }

    let want = original(&dir);
    let tmp = footprint_suite::tmpdir("real-writers");
    let mut references = std::collections::HashMap::new();
    for e in &entries {
        let path = dir.join(&e.file);
        let v = formats::load_array(&path, None, e.array.as_deref())
            .unwrap_or_else(|err| panic!("{} ({}): {}", e.file, e.writer, err.message));
        check_grid(&v, e);
        let got: Vec<f32> = (0..v.len()).map(|n| v.value(n)).collect();
        assert!(
            got == want,
            "{} ({}): samples differ from the original",
            e.file,
            e.writer
        );
        let reference = references.entry(e.orientation.clone()).or_insert_with(|| {
            let nrrd = reference_nrrd(&dir, &tmp, &e.orientation);
            render(&nrrd, None, &tmp.join(format!("ref-{}.png", e.orientation)))
        });
        let image = render(&path, e.array.as_deref(), &tmp.join("file.png"));
        assert!(
            &image == reference,
            "{} ({}): renders differently from the raw original ({})",
            e.file,
            e.writer,
            e.orientation
        );
    }
    // The flip is real: the two orientations render different images.
    if let (Some(a), Some(b)) = (references.get("identity"), references.get("ras")) {
        assert_ne!(a, b, "the RAS flip should change the picture");
    }
    eprintln!(
        "{} files from {} matched the original",
        entries.len(),
        std::fs::read_to_string(dir.join("versions.txt"))
            .unwrap_or_default()
            .trim()
            .replace('\n', ", ")
    );
}
