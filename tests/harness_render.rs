//! The `footprint` command's render, verify and loaders, end to end (in-process through
//! `footprint_harness::run`, the same entry point as the binary).

use footprint_harness::io::formats::nrrd::load as load_nrrd;
use footprint_harness::io::formats::raw::{load as raw_load, RawOptions};
use footprint_harness::io::volume::{SampleType, Samples};
use footprint_suite::tmpdir;
use std::path::{Path, PathBuf};

use footprint_suite::{path_str as s, run_cli as run};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn default_scene_renders_to_a_picture() {
    let d = tmpdir("default");
    let out = d.join("footprint.png");
    let json = d.join("r.json");
    assert_eq!(
        run(&[
            "render",
            "--size",
            "96x96",
            "--out",
            s(&out),
            "--json",
            s(&json)
        ]),
        0
    );
    let bytes = std::fs::read(&out).unwrap();
    let (w, h, px) = footprint_harness::io::image::decode_png_rgba(&bytes, "out").unwrap();
    assert_eq!((w, h), (96, 96));
    let lit = px.iter().filter(|p| p[0] + p[1] + p[2] > 0.1).count();
    assert!(lit > 96 * 96 / 10, "only {lit} pixels are lit");
    let j = std::fs::read_to_string(&json).unwrap();
    for key in [
        "\"voxels\"",
        "\"voxels_splatted\"",
        "\"pixel_updates\"",
        "\"pixels_composited\"",
        "\"sheets\"",
        "\"seconds\"",
        "\"kernel\"",
    ] {
        assert!(j.contains(key), "{key} missing from {j}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn verify_passes_and_fails_on_its_threshold() {
    let d = tmpdir("verify");
    let json = d.join("v.json");
    let heart = data("heart_32x32x12_float32_le.nhdr");
    // Object slicing: the sheets the f64 reference renders (the default plan takes slabs here).
    let common = [
        "--size",
        "128x128",
        "--table",
        "65",
        "--lookup",
        "bilinear",
        "--view",
        "30,20,0",
        "--slicing",
        "object",
    ];
    let mut args = vec!["verify", s(&heart)];
    args.extend_from_slice(&common);
    args.extend_from_slice(&["--shading", "phong", "--min-psnr", "40", "--json", s(&json)]);
    assert_eq!(run(&args), 0);
    let j = std::fs::read_to_string(&json).unwrap();
    assert!(
        j.contains("\"pass\": true") && j.contains("\"psnr_db\""),
        "{j}"
    );
    let mut strict = vec!["verify", s(&heart)];
    strict.extend_from_slice(&common);
    strict.extend_from_slice(&["--min-psnr", "500"]);
    assert_eq!(run(&strict), 1);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn verify_fixed_reports_against_reference_and_float() {
    let d = tmpdir("verify-fixed");
    let json = d.join("v.json");
    let heart = data("heart_32x32x12_float32_le.nhdr");
    let args = [
        "verify",
        s(&heart),
        "--accum",
        "fixed",
        "--size",
        "96x96",
        "--table",
        "33",
        "--view",
        "30,20,0",
        "--min-psnr",
        "40",
        "--json",
        s(&json),
    ];
    assert_eq!(run(&args), 0);
    let j = std::fs::read_to_string(&json).unwrap();
    for key in [
        "\"accum\": \"fixed\"",
        "\"fixed_vs_float\"",
        "\"pass\": true",
    ] {
        assert!(j.contains(key), "{key} missing from {j}");
    }
    // A view that puts the volume's ends beyond the fixed-point range (2³⁰ px) while the
    // geometry still accepts its footprints is a typed error (exit 2), and writes nothing.
    let raw = d.join("line.raw");
    std::fs::write(
        &raw,
        (0..2048u32).map(|i| (i % 251) as u8).collect::<Vec<_>>(),
    )
    .unwrap();
    let out = d.join("far.png");
    let far = [
        "render",
        s(&raw),
        "--dims",
        "2048,1,1",
        "--type",
        "u8",
        "--accum",
        "fixed",
        "--size",
        "32x32",
        "--view-matrix",
        "1.5e6,0,0,0,1.5e6,0,0,0,1.5e6",
        "--out",
        s(&out),
    ];
    assert_eq!(run(&far), 2);
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn quality_chooses_records_and_meets_its_target() {
    let d = tmpdir("quality");
    let json = d.join("q.json");
    let heart = data("heart_32x32x12_float32_le.nhdr");
    let out = d.join("q.png");
    let args = [
        "render",
        s(&heart),
        "--quality",
        "40",
        "--size",
        "96x96",
        "--view",
        "30,20,0",
        "--json",
        s(&json),
        "--out",
        s(&out),
    ];
    assert_eq!(run(&args), 0);
    let j = std::fs::read_to_string(&json).unwrap();
    for key in [
        "\"quality\"",
        "\"target_db\": 40",
        "\"predicted_db\"",
        "\"chosen\": \"n=",
    ] {
        assert!(j.contains(key), "{key} missing from {j}");
    }
    // verify takes --quality too, and the achieved PSNR meets the request.
    for q in ["30", "40", "50"] {
        let verify = [
            "verify",
            s(&heart),
            "--quality",
            q,
            "--min-psnr",
            q,
            "--size",
            "96x96",
            "--view",
            "30,20,0",
        ];
        assert_eq!(run(&verify), 0, "--quality {q}");
    }
    // --quality replaces the table flags, so giving both is refused.
    let both = [
        "render",
        s(&heart),
        "--quality",
        "40",
        "--table",
        "65",
        "--out",
        s(&out),
    ];
    assert_eq!(run(&both), 2);
    std::fs::remove_dir_all(&d).unwrap();
}

fn write_nrrd(
    dir: &Path,
    name: &str,
    ty: &str,
    endian: Option<&str>,
    body: &[u8],
    attached: bool,
) -> PathBuf {
    let mut header = format!(
        "NRRD0004\n# a comment\ntype: {ty}\ndimension: 3\nsizes: 3 4 5\nspacings: 1 2 0.5\n"
    );
    if let Some(e) = endian {
        header += &format!("endian: {e}\n");
    }
    header += "encoding: raw\n";
    if attached {
        let p = dir.join(format!("{name}.nrrd"));
        let mut bytes = (header + "\n").into_bytes();
        bytes.extend_from_slice(body);
        std::fs::write(&p, bytes).unwrap();
        p
    } else {
        std::fs::write(dir.join(format!("{name}.raw")), body).unwrap();
        let p = dir.join(format!("{name}.nhdr"));
        std::fs::write(&p, header + &format!("data file: {name}.raw\n")).unwrap();
        p
    }
}

#[test]
fn nrrd_and_raw_load_every_type_and_byte_order() {
    let d = tmpdir("nrrd");
    let values: Vec<f64> = (0..60).map(|i| f64::from(i * 3 % 17)).collect();
    for (ty, st) in [
        ("uchar", SampleType::U8),
        ("int8", SampleType::I8),
        ("uint16", SampleType::U16),
        ("short", SampleType::I16),
        ("uint", SampleType::U32),
        ("int32", SampleType::I32),
        ("float", SampleType::F32),
        ("double", SampleType::F64),
    ] {
        for big in [false, true] {
            let body: Vec<u8> = values
                .iter()
                .flat_map(|&v| {
                    let le: Vec<u8> = match st {
                        SampleType::U8 => vec![v as u8],
                        SampleType::I8 => vec![v as i8 as u8],
                        SampleType::U16 => (v as u16).to_le_bytes().to_vec(),
                        SampleType::I16 => (v as i16).to_le_bytes().to_vec(),
                        SampleType::U32 => (v as u32).to_le_bytes().to_vec(),
                        SampleType::I32 => (v as i32).to_le_bytes().to_vec(),
                        SampleType::F32 => (v as f32).to_le_bytes().to_vec(),
                        SampleType::F64 => v.to_le_bytes().to_vec(),
                    };
                    if big {
                        le.into_iter().rev().collect()
                    } else {
                        le
                    }
                })
                .collect();
            let endian = (st.size() > 1).then_some(if big { "big" } else { "little" });
            for attached in [false, true] {
                let p = write_nrrd(
                    &d,
                    &format!("{ty}-{big}-{attached}"),
                    ty,
                    endian,
                    &body,
                    attached,
                );
                let v = load_nrrd(&p)
                    .unwrap_or_else(|e| panic!("{ty} big={big} attached={attached}: {e}"));
                assert_eq!(v.dims, [3, 4, 5]);
                assert_eq!(v.spacing, [1.0, 2.0, 0.5]);
                for (n, want) in values.iter().enumerate() {
                    assert_eq!(
                        f64::from(v.value(n)),
                        *want,
                        "{ty} big={big} attached={attached} sample {n}"
                    );
                }
            }
            let raw = d.join(format!("{ty}-{big}.raw"));
            std::fs::write(&raw, &body).unwrap();
            let o = RawOptions {
                dims: [3, 4, 5],
                ty: st,
                big_endian: big,
                spacing: [1.0, 1.0, 1.0],
            };
            let v = raw_load(&raw, &o).unwrap();
            assert_eq!(f64::from(v.value(59)), values[59]);
        }
    }
    // The shipped header of the real data reads too.
    let h = load_nrrd(&data("headsq_64x64x93_int16_le.nhdr")).unwrap();
    assert_eq!((h.dims, h.spacing), ([64, 64, 93], [3.2, 3.2, 1.5]));
    assert!(matches!(h.samples, Samples::I16(_)));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Each bad input: exit code 2, a one-line message naming the file, no output left behind.
#[test]
fn bad_volumes_fail_cleanly() {
    let d = tmpdir("badvol");
    let out = d.join("out.png");
    let body = vec![0u8; 60];
    let ok_header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: raw\n";
    let cases: Vec<(&str, String, Vec<u8>)> = vec![
        ("truncated", ok_header.to_string(), body[..59].to_vec()),
        (
            "unknown-type",
            ok_header.replace("uchar", "quaternion"),
            body.clone(),
        ),
        (
            "gzip-not-yet",
            ok_header.replace("raw", "gzip"),
            body.clone(),
        ),
        (
            "missing-sizes",
            ok_header.replace("sizes: 3 4 5\n", ""),
            body.clone(),
        ),
        ("zero-dim", ok_header.replace("3 4 5", "3 0 5"), vec![]),
        (
            "overflow-dims",
            ok_header.replace("3 4 5", "4294967296 4294967296 4294967296"),
            vec![],
        ),
        (
            "words-for-sizes",
            ok_header.replace("3 4 5", "three four five"),
            body.clone(),
        ),
        (
            "2d",
            ok_header.replace("dimension: 3", "dimension: 2"),
            body.clone(),
        ),
        (
            "no-endian-16bit",
            ok_header.replace("uchar", "short"),
            vec![0u8; 120],
        ),
        (
            "bad-spacing",
            ok_header.replace("encoding", "spacings: 1 0 1\nencoding"),
            body.clone(),
        ),
    ];
    for (name, header, data) in &cases {
        let p = d.join(format!("{name}.nrrd"));
        let mut bytes = (header.clone() + "\n").into_bytes();
        bytes.extend_from_slice(data);
        std::fs::write(&p, bytes).unwrap();
        assert_eq!(
            run(&["render", s(&p), "--size", "32x32", "--out", s(&out)]),
            2,
            "{name}"
        );
        assert!(!out.exists(), "{name} left an output");
        assert!(
            load_nrrd(&p).unwrap_err().message.contains(name),
            "{name}: message names the file"
        );
    }
    let empty = d.join("empty.nhdr");
    std::fs::write(&empty, b"").unwrap();
    let missing_data = d.join("nodata.nhdr");
    std::fs::write(
        &missing_data,
        format!("{ok_header}data file: nowhere.raw\n"),
    )
    .unwrap();
    for p in [
        empty.as_path(),
        &*d,
        missing_data.as_path(),
        Path::new("/nonexistent/v.nhdr"),
    ] {
        assert_eq!(
            run(&["render", s(p), "--size", "32x32", "--out", s(&out)]),
            2,
            "{}",
            p.display()
        );
        assert!(!out.exists());
    }
    let raw = d.join("v.raw");
    std::fs::write(&raw, vec![0u8; 100]).unwrap();
    assert_eq!(
        run(&[
            "render",
            s(&raw),
            "--dims",
            "3,4,5",
            "--type",
            "u8",
            "--out",
            s(&out)
        ]),
        2,
        "raw size mismatch"
    );
    assert_eq!(
        run(&[
            "render",
            s(&raw),
            "--dims",
            "10,10,1",
            "--type",
            "q8",
            "--out",
            s(&out)
        ]),
        2,
        "raw type"
    );
    assert_eq!(
        run(&["render", s(&raw), "--out", s(&out)]),
        2,
        "raw without --dims"
    );
    assert_eq!(
        run(&[
            "render",
            "--shading",
            "lambert",
            "--size",
            "16x16",
            "--out",
            s(&out)
        ]),
        2,
        "bad shading"
    );
    assert_eq!(
        run(&[
            "render",
            "--tf",
            "nonsense",
            "--size",
            "16x16",
            "--out",
            s(&out)
        ]),
        2,
        "bad tf"
    );
    assert_eq!(
        run(&[
            "render",
            "--window",
            "5,1",
            "--size",
            "16x16",
            "--out",
            s(&out)
        ]),
        2,
        "bad window"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn tables_file_and_tf_file_are_used() {
    let d = tmpdir("tablefile");
    let t = d.join("g33.fpt");
    assert_eq!(
        run(&[
            "tables",
            "--kernel",
            "gaussian",
            "--size",
            "33",
            "--out",
            s(&t)
        ]),
        0
    );
    let (a, b) = (d.join("a.png"), d.join("b.png"));
    // Level 0: a coarser level narrows a built table's kernel, never a file's.
    let table_render = |extra: &[&str], out: &std::path::Path| {
        let mut args = vec!["render", "--size", "64x64", "--lod", "0", "--table", "33"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", s(out)]);
        run(&args)
    };
    assert_eq!(table_render(&[], &a), 0);
    assert_eq!(table_render(&["--table-file", s(&t)], &b), 0);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let tf = d.join("tf.txt");
    std::fs::write(&tf, "# t r g b a\n0 0 0 0 0\n0.5 1 0 0 0.2\n1 1 1 0 0.8\n").unwrap();
    assert_eq!(
        run(&[
            "render",
            "--size",
            "64x64",
            "--tf",
            s(&tf),
            "--shading",
            "iso:0.5",
            "--out",
            s(&a)
        ]),
        0
    );
    std::fs::write(&tf, "0 0 0 0 0\n0 1 1 1 1\n").unwrap();
    assert_eq!(
        run(&["render", "--size", "64x64", "--tf", s(&tf), "--out", s(&b)]),
        2,
        "non-increasing tf"
    );
    std::fs::remove_dir_all(&d).unwrap();
}
