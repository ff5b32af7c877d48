//! Bad input never hurts: every malformed volume is a one-line error naming the file and what was
//! expected, exit code 2, no panic, and no output file left behind.

use footprint_harness::io::formats;
use footprint_suite::tmpdir;
use std::path::Path;

/// (file name, contents, a word the message must contain).
type Case = (&'static str, Vec<u8>, &'static str);

fn nrrd(fields: &str, data: &[u8]) -> Vec<u8> {
    [format!("NRRD0004\n{fields}\n").into_bytes(), data.to_vec()].concat()
}

const OK_NRRD: &str = "type: uint8\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n";

fn gz(b: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}

fn vti(attrs: &str, array: &str) -> Vec<u8> {
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\"{attrs}>\n<ImageData WholeExtent=\"0 3 0 2 0 1\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 3 0 2 0 1\"><PointData Scalars=\"s\">{array}</PointData></Piece></ImageData></VTKFile>\n"
    )
    .into_bytes()
}

fn vtk(mode: &str, dims: &str, points: &str, ty: &str, data: &[u8]) -> Vec<u8> {
    [
        format!("# vtk DataFile Version 3.0\nbad\n{mode}\nDATASET STRUCTURED_POINTS\nDIMENSIONS {dims}\nSPACING 1 1 1\nPOINT_DATA {points}\nSCALARS s {ty} 1\nLOOKUP_TABLE default\n").into_bytes(),
        data.to_vec(),
    ]
    .concat()
}

fn mha(fields: &str, data: &[u8]) -> Vec<u8> {
    [
        format!("ObjectType = Image\nNDims = 3\n{fields}ElementDataFile = LOCAL\n").into_bytes(),
        data.to_vec(),
    ]
    .concat()
}

fn nifti(datatype: i16, dims: [i16; 3], vox: f32, data_len: usize) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3i16, dims[0], dims[1], dims[2], 1, 1, 1, 1]
        .iter()
        .enumerate()
    {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&datatype.to_le_bytes());
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    for i in 0..4 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&vox.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h.extend(vec![7u8; data_len]);
    h
}

/// A NIfTI-2 header (540 bytes, little-endian) with `magic`, then 4 bytes of extension flag and
/// `data_len` bytes of samples.
fn nifti2(magic: &[u8; 4], datatype: i16, dims: [i64; 3], vox: i64, data_len: usize) -> Vec<u8> {
    let mut h = vec![0u8; 544];
    h[0..4].copy_from_slice(&540i32.to_le_bytes());
    h[4..8].copy_from_slice(magic);
    h[8..12].copy_from_slice(b"\r\n\x1a\n");
    h[12..14].copy_from_slice(&datatype.to_le_bytes());
    h[14..16].copy_from_slice(&8i16.to_le_bytes());
    for (i, d) in [3, dims[0], dims[1], dims[2], 1, 1, 1, 1]
        .iter()
        .enumerate()
    {
        h[16 + 8 * i..24 + 8 * i].copy_from_slice(&d.to_le_bytes());
    }
    for i in 0..4 {
        h[104 + 8 * i..112 + 8 * i].copy_from_slice(&1f64.to_le_bytes());
    }
    h[168..176].copy_from_slice(&vox.to_le_bytes());
    h.extend(vec![7u8; data_len]);
    h
}

/// A legacy VTK file of a 4×3×2 grid whose data sections are `data`.
fn legacy(data: &str) -> Vec<u8> {
    format!("# vtk DataFile Version 3.0\nbad\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3 2\n{data}")
        .into_bytes()
}

fn cases() -> Vec<Case> {
    let data = vec![5u8; 24];
    vec![
        // NRRD
        ("truncated.nrrd", nrrd(OK_NRRD, &data[..23]), "24 bytes"),
        ("unknown-type.nrrd", nrrd(&OK_NRRD.replace("uint8", "complex"), &data), "type"),
        ("unknown-encoding.nrrd", nrrd(&OK_NRRD.replace("raw", "bzip2"), &data), "encoding"),
        ("corrupt-gzip.nrrd", nrrd(&OK_NRRD.replace("raw", "gzip"), &[0x1f, 0x8b, 8, 0, 1, 2, 3, 4, 5, 6, 7]), "gzip"),
        ("short-gzip.nrrd", nrrd(&OK_NRRD.replace("raw", "gzip"), &gz(&data[..10])), "expected 24"),
        ("non-numeric-sizes.nrrd", nrrd(&OK_NRRD.replace("4 3 2", "4 three 2"), &data), "sizes"),
        ("missing-type.nrrd", nrrd(&OK_NRRD.replace("type: uint8\n", ""), &data), "type"),
        ("zero-dims.nrrd", nrrd(&OK_NRRD.replace("4 3 2", "4 0 2"), &[]), "zero"),
        ("overflow-dims.nrrd", nrrd(&OK_NRRD.replace("4 3 2", "99999999999 99999999999 99999999999"), &[]), "voxels"),
        ("nan-spacing.nrrd", nrrd(&(OK_NRRD.to_string() + "spacings: 1 nan 1\n"), &data), "spacing"),
        ("bad-ascii.nrrd", nrrd(&OK_NRRD.replace("raw", "ascii"), b"1 2 3 x"), "not a number"),
        ("bad-magic.nrrd", b"NRRD0009\ntype: uint8\n\n".to_vec(), "magic"),
        // VTK XML
        ("bad-base64.vti", vti("", "<DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">@@@@!!!</DataArray>"), "base64"),
        ("corrupt-zlib.vti", vti(" header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"", "<DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">AQAAABgAAAAYAAAACgAAAA==AAECAwQFBgcICQ==</DataArray>"), "zlib"),
        ("wrong-count.vti", vti("", "<DataArray type=\"UInt8\" Name=\"s\" format=\"ascii\">1 2 3</DataArray>"), "expected 24"),
        ("unknown-type.vti", vti("", "<DataArray type=\"Int64\" Name=\"s\" format=\"ascii\">1</DataArray>"), "Int64"),
        ("not-xml.vti", b"<VTKFile type=\"ImageData\"><unclosed".to_vec(), "XML"),
        ("zstd.vti", vti(" compressor=\"vtkZstdDataCompressor\"", ""), "compressor"),
        ("corrupt-lz4.vti", vti(" header_type=\"UInt32\" compressor=\"vtkLZ4DataCompressor\"", "<DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">AQAAABgAAAAYAAAACgAAAA==Z2FyYmFnZSEhIQ==</DataArray>"), "LZ4"),
        ("corrupt-lzma.vti", vti(" header_type=\"UInt32\" compressor=\"vtkLZMADataCompressor\"", "<DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">AQAAABgAAAAYAAAABgAAAA==/Td6WFoA</DataArray>"), "LZMA"),
        // Legacy VTK
        ("truncated-binary.vtk", vtk("BINARY", "4 3 2", "24", "unsigned_char", &data[..20]), "truncated"),
        ("point-mismatch.vtk", vtk("ASCII", "4 3 2", "25", "unsigned_char", b"1"), "POINT_DATA"),
        ("unknown-type.vtk", vtk("ASCII", "4 3 2", "24", "quaternion", b"1"), "type"),
        ("negative-dims.vtk", vtk("ASCII", "4 -3 2", "24", "float", b"1"), "DIMENSIONS"),
        ("bad-mode.vtk", vtk("UTF8", "4 3 2", "24", "float", b"1"), "ASCII or BINARY"),
        ("short-field.vtk", legacy("POINT_DATA 24\nFIELD f 1\na 1 24 float\n1 2 3\n"), "found 3"),
        ("unknown-keyword.vtk", legacy("POINT_DATA 24\nSCALERS s float\n"), "not a legacy VTK keyword"),
        ("vectors-only.vtk", legacy(&format!("POINT_DATA 24\nVECTORS v float\n{}", "0 ".repeat(72))), "no single-component"),
        ("no-lookup-table.vtk", legacy("POINT_DATA 24\nSCALARS s float\n1 2 3\n"), "LOOKUP_TABLE"),
        ("huge-field.vtk", legacy("POINT_DATA 24\nFIELD f 1\na 99999999 99999999 double\n"), "values"),
        // MetaImage
        ("truncated.mha", mha("DimSize = 4 3 2\nElementType = MET_UCHAR\n", &data[..3]), "24 bytes"),
        ("unknown-type.mha", mha("DimSize = 4 3 2\nElementType = MET_LONG_LONG\n", &data), "ElementType"),
        ("corrupt-zlib.mha", mha("DimSize = 4 3 2\nElementType = MET_UCHAR\nCompressedData = True\n", b"not zlib at all"), "zlib"),
        ("missing-dimsize.mha", mha("ElementType = MET_UCHAR\n", &data), "DimSize"),
        // NIfTI
        ("truncated.nii", nifti(2, [4, 3, 2], 352.0, 10), "truncated"),
        ("bad-datatype.nii", nifti(1792, [4, 3, 2], 352.0, 24), "datatype"),
        ("zero-dim.nii", nifti(2, [4, 0, 2], 352.0, 24), "dim[2]"),
        ("bad-vox-offset.nii", nifti(2, [4, 3, 2], 10.0, 24), "vox_offset"),
        ("short-header.nii", vec![0u8; 100], "shorter"),
        ("corrupt.nii.gz", vec![0x1f, 0x8b, 8, 0, 9, 9, 9], "gzip"),
        ("n2-truncated.nii", nifti2(b"n+2\0", 2, [4, 3, 2], 544, 10), "truncated"),
        ("n2-bad-datatype.nii", nifti2(b"n+2\0", 1792, [4, 3, 2], 544, 24), "datatype"),
        ("n2-bad-vox-offset.nii", nifti2(b"n+2\0", 2, [4, 3, 2], 100, 24), "vox_offset"),
        ("n2-zero-dim.nii", nifti2(b"n+2\0", 2, [4, 3, 0], 544, 24), "dim[3]"),
        ("n2-short-header.nii", nifti2(b"n+2\0", 2, [4, 3, 2], 544, 0)[..400].to_vec(), "shorter"),
        ("n2-bad-magic.nii", nifti2(b"n+1\0", 2, [4, 3, 2], 544, 24), "magic"),
        ("pair-header-as-nii.nii", nifti2(b"ni2\0", 2, [4, 3, 2], 0, 0), ".img"),
        // Any format
        ("empty.nrrd", vec![], "magic"),
        ("empty.vti", vec![], "XML"),
        ("empty.vtk", vec![], "legacy VTK"),
        ("empty.mha", vec![], "NDims"),
        ("empty.nii", vec![], "shorter"),
        ("unknown.xyz", data.clone(), "unknown volume format"),
    ]
}

fn run(args: &[&str]) -> i32 {
    let mut v = vec!["footprint", "render"];
    v.extend_from_slice(args);
    footprint_harness::run(v)
}

#[test]
fn malformed_volumes_fail_cleanly() {
    let d = tmpdir("bad-input");
    let out = d.join("out.png");
    for (name, bytes, word) in cases() {
        let p = d.join(name);
        std::fs::write(&p, &bytes).unwrap();
        let err = formats::load(&p, None).expect_err(name).message;
        assert!(
            err.contains(name),
            "{name}: message does not name the file: {err}"
        );
        assert!(
            err.contains(word),
            "{name}: message should say '{word}': {err}"
        );
        assert!(
            !err.contains('\n'),
            "{name}: message is not one line: {err}"
        );
        assert_eq!(
            run(&[
                p.to_str().unwrap(),
                "--size",
                "16x16",
                "--out",
                out.to_str().unwrap()
            ]),
            2,
            "{name}"
        );
        assert!(!out.exists(), "{name} left an output");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_paths_and_sizes_fail_cleanly() {
    let d = tmpdir("bad-paths");
    let out = d.join("out.png");
    let o = out.to_str().unwrap();
    let dir = d.join("a-directory.nrrd");
    std::fs::create_dir_all(&dir).unwrap();
    let msg = formats::load(&dir, None).unwrap_err().message;
    assert!(msg.contains("is a directory"), "{msg}");
    let raw = d.join("v.raw");
    std::fs::write(&raw, [1u8; 24]).unwrap();
    let r = raw.to_str().unwrap();
    for args in [
        vec![dir.to_str().unwrap(), "--out", o],
        vec!["/no/such/volume.nhdr", "--out", o],
        vec![r, "--dims", "4,3,3", "--type", "u8", "--out", o],
        vec![r, "--dims", "4,3,0", "--type", "u8", "--out", o],
        vec![
            r,
            "--dims",
            "99999999999,99999999999,99999999999",
            "--type",
            "u8",
            "--out",
            o,
        ],
        vec![
            r,
            "--dims",
            "4,3,2",
            "--type",
            "u8",
            "--size",
            "100000x100000",
            "--out",
            o,
        ],
        vec![
            r, "--dims", "4,3,2", "--type", "u8", "--size", "0x5", "--out", o,
        ],
        vec![
            r,
            "--dims",
            "4,3,2",
            "--type",
            "u8",
            "--spacing",
            "1,-1,1",
            "--out",
            o,
        ],
        vec!["--stream", r, "--out", o],
        vec!["--stream", "-", "--out", o],
        vec!["--stream", r, "--dims", "4,3,3", "--type", "u8", "--out", o],
        vec![
            r, "--stream", r, "--dims", "4,3,2", "--type", "u8", "--out", o,
        ],
    ] {
        assert_eq!(run(&args), 2, "{args:?}");
        assert!(!out.exists(), "{args:?} left an output");
    }
    // Writing into a folder that does not exist fails without leaving a temporary file.
    let nowhere = d.join("missing-dir").join("x.png");
    assert_eq!(
        run(&[
            r,
            "--dims",
            "4,3,2",
            "--type",
            "u8",
            "--size",
            "8x8",
            "--out",
            nowhere.to_str().unwrap()
        ]),
        2
    );
    assert!(std::fs::read_dir(&d).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .contains(".tmp-")));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Non-finite samples are missing data: transparent, and in gradients they count as the centre's
/// value. A volume of NaN and ±∞ around a finite core renders exactly like the core alone under
/// emission, and under Phong no NaN reaches a normal.
#[test]
fn non_finite_samples_are_transparent() {
    let d = tmpdir("nonfinite");
    let mut with = Vec::new();
    let mut without = Vec::new();
    for n in 0..(8 * 8 * 8) {
        let (i, j, k) = (n % 8, (n / 8) % 8, n / 64);
        let core = (2..6).contains(&i) && (2..6).contains(&j) && (2..6).contains(&k);
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][n % 3];
        with.extend_from_slice(&(if core { 0.7f32 } else { bad }).to_le_bytes());
        without.extend_from_slice(&(if core { 0.7f32 } else { 0.0 }).to_le_bytes());
    }
    let (a, b) = (d.join("with.raw"), d.join("without.raw"));
    std::fs::write(&a, &with).unwrap();
    std::fs::write(&b, &without).unwrap();
    let render = |p: &Path, shading: &str, out: &Path| {
        let args = [
            p.to_str().unwrap(),
            "--dims",
            "8,8,8",
            "--type",
            "f32",
            "--window",
            "0,1",
            "--shading",
            shading,
            "--size",
            "48x48",
            "--out",
            out.to_str().unwrap(),
        ];
        assert_eq!(run(&args), 0);
        footprint_harness::io::image::decode_png_rgba(&std::fs::read(out).unwrap(), "png")
            .unwrap()
            .2
    };
    let (ea, eb) = (
        render(&a, "emission", &d.join("a.png")),
        render(&b, "emission", &d.join("b.png")),
    );
    assert!(ea == eb, "non-finite samples changed the emission image");
    // Phong: the core is constant and its missing neighbours count as the centre's value, so every
    // core gradient is zero and every voxel is lit by ambient + diffuse = 0.9 (the default Phong):
    // the Phong image is 0.9 × the emission image, to 8-bit rounding.
    let pa = render(&a, "phong", &d.join("pa.png"));
    let worst = pa
        .iter()
        .zip(&ea)
        .flat_map(|(p, e)| (0..3).map(move |ch| (p[ch] - 0.9 * e[ch]).abs()))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 1.0 / 255.0,
        "Phong next to missing data differs from 0.9 × emission by {worst}"
    );
    assert!(pa.iter().any(|p| p[0] > 0.1), "the core is visible");
    // Without --window the range ignores non-finite samples (all-finite part is constant 0.7 and
    // 0 in the second file, so its window is [0, 0.7]).
    let range = footprint_harness::io::formats::load(
        &b,
        Some(&footprint_harness::io::formats::raw::RawOptions {
            dims: [8, 8, 8],
            ty: footprint_harness::io::volume::SampleType::F32,
            big_endian: false,
            spacing: [1.0; 3],
        }),
    )
    .unwrap()
    .range();
    assert_eq!(range, (0.0, 0.7));
    std::fs::remove_dir_all(&d).unwrap();
}

/// `compare` cannot pass NaN: an image holding a non-finite value fails the check (exit 1) with or
/// without `--max-diff`, and a non-finite `--max-diff` is refused (exit 2).
#[test]
fn compare_fails_on_non_finite_images() {
    use footprint_harness::io::image::{encode_pfm, GreyImage};
    let d = tmpdir("compare-nan");
    let img = |v: Vec<f32>| {
        encode_pfm(&GreyImage {
            width: 2,
            height: 2,
            data: v,
        })
    };
    let (good, nan, inf) = (d.join("good.pfm"), d.join("nan.pfm"), d.join("inf.pfm"));
    std::fs::write(&good, img(vec![0.1, 0.2, 0.3, 0.4])).unwrap();
    std::fs::write(&nan, img(vec![0.1, f32::NAN, 0.3, 0.4])).unwrap();
    std::fs::write(&inf, img(vec![0.1, 0.2, f32::INFINITY, 0.4])).unwrap();
    let compare = |args: &[&str]| {
        footprint_harness::run(["footprint", "compare"].iter().chain(args).copied())
    };
    let (g, n, i) = (
        good.to_str().unwrap(),
        nan.to_str().unwrap(),
        inf.to_str().unwrap(),
    );
    assert_eq!(compare(&[g, g, "--max-diff", "0.1"]), 0);
    assert_eq!(compare(&[n, g, "--max-diff", "0.1"]), 1);
    assert_eq!(compare(&[g, n, "--max-diff", "0.1"]), 1);
    assert_eq!(compare(&[i, g]), 1);
    assert_eq!(compare(&[n, g]), 1);
    assert_eq!(compare(&[g, g, "--max-diff", "nan"]), 2);
    assert_eq!(compare(&[g, g, "--max-diff", "-1"]), 2);
    let a = GreyImage {
        width: 1,
        height: 1,
        data: vec![f32::NAN],
    };
    let b = GreyImage {
        width: 1,
        height: 1,
        data: vec![1.0],
    };
    assert!(footprint_harness::metrics::max_rel_diff(&a, &b)
        .unwrap()
        .is_nan());
    std::fs::remove_dir_all(&d).unwrap();
}

/// XML nested 20 000 deep is refused before the (recursive) parser sees it; real nesting, quoted
/// '>' in attributes, comments, CDATA and self-closing tags do not count against the limit.
#[test]
fn deeply_nested_xml_is_refused_without_recursion() {
    use footprint_harness::io::formats::vti::{check_depth, MAX_XML_DEPTH};
    let d = tmpdir("deep-xml");
    let n = 20_000;
    let deep = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\">{}{}</VTKFile>\n",
        "<a>".repeat(n),
        "</a>".repeat(n)
    );
    let path = d.join("deep.vti");
    std::fs::write(&path, &deep).unwrap();
    let out = d.join("out.png");
    assert_eq!(
        run(&[path.to_str().unwrap(), "--out", out.to_str().unwrap()]),
        2
    );
    assert!(!out.exists());
    let msg = formats::load(&path, None).unwrap_err().message;
    assert!(msg.contains("nested deeper"), "{msg}");
    let ok = "<a x=\"1>2\"><!-- <b><b><b> --><c/><d><![CDATA[<e><e>]]></d></a>";
    assert!(check_depth(ok, 2).is_ok());
    assert!(check_depth("<a><b><c></c></b></a>", 2).is_err());
    assert!(check_depth(&"<a>".repeat(MAX_XML_DEPTH), MAX_XML_DEPTH).is_ok());
    std::fs::remove_dir_all(&d).unwrap();
}

/// A 400 KB PNG declaring 12000×12000 as `--background` is refused from its header, before any
/// decoding (it would inflate to 432 MB).
#[test]
fn a_huge_png_background_is_refused_before_decoding() {
    use std::io::Write;
    let chunk = |t: &[u8], d: &[u8]| {
        let mut body = t.to_vec();
        body.extend_from_slice(d);
        let mut c = (d.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(&body);
        c.extend_from_slice(&footprint::table::crc32(&body).to_be_bytes());
        c
    };
    let (w, h) = (12_000u32, 12_000u32);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    let row = vec![0u8; 1 + 3 * w as usize];
    for _ in 0..h {
        z.write_all(&row).unwrap();
    }
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let png = [
        b"\x89PNG\r\n\x1a\n".to_vec(),
        chunk(b"IHDR", &ihdr),
        chunk(b"IDAT", &z.finish().unwrap()),
        chunk(b"IEND", &[]),
    ]
    .concat();
    let d = tmpdir("huge-png");
    let bg = d.join("bg.png");
    std::fs::write(&bg, &png).unwrap();
    let out = d.join("out.png");
    let start = std::time::Instant::now();
    assert_eq!(
        run(&[
            "--background",
            bg.to_str().unwrap(),
            "--size",
            "16x16",
            "--out",
            out.to_str().unwrap()
        ]),
        2
    );
    assert!(!out.exists());
    let msg = footprint_harness::io::image::decode_png_rgba_sized(
        &png,
        "bg",
        (16, 16),
        Default::default(),
    )
    .unwrap_err()
    .message;
    assert!(msg.contains("12000x12000"), "{msg}");
    eprintln!("refused in {:?}", start.elapsed());
    std::fs::remove_dir_all(&d).unwrap();
}

/// A FIFO (no writer) or a device as a volume, a detached data file or a background is refused
/// from `stat`, before anything opens it (opening a FIFO blocks until a writer comes).
#[cfg(unix)]
#[test]
fn special_files_are_refused_without_blocking() {
    let d = tmpdir("fifo");
    let fifo = d.join("fifo.raw");
    let ok = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !ok.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable: skipped");
        return;
    }
    let nhdr = d.join("v.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: fifo.raw\n",
    )
    .unwrap();
    let out = d.join("out.png");
    let o = out.to_str().unwrap();
    let f = fifo.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec![nhdr.to_str().unwrap(), "--out", o],
        vec![f, "--dims", "2,2,2", "--type", "u8", "--out", o],
        vec!["--stream", f, "--dims", "2,2,2", "--type", "u8", "--out", o],
        vec!["/dev/zero", "--dims", "2,2,2", "--type", "u8", "--out", o],
        vec!["--background", f, "--size", "8x8", "--out", o],
    ];
    for args in cases {
        let start = std::time::Instant::now();
        assert_eq!(run(&args), 2, "{args:?}");
        assert!(
            start.elapsed().as_secs() < 5,
            "{args:?} took {:?}",
            start.elapsed()
        );
        assert!(!out.exists());
    }
    let msg = footprint_harness::io::read_file(&fifo).unwrap_err().message;
    assert!(msg.contains("not a regular file"), "{msg}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Space is reserved only for what the data can fill: an ASCII NRRD declaring 1600³ floats and
/// holding three numbers is one error line, with no 16 GB reservation first; image buffers that
/// cannot be had are errors naming their size (`try_reserve`), not aborts.
#[test]
fn declared_sizes_do_not_reserve_memory_the_data_cannot_fill() {
    let d = tmpdir("declared");
    let nhdr = d.join("a.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 1600 1600 1600\nencoding: ascii\n\n1 2 3\n",
    )
    .unwrap();
    let msg = formats::load(&nhdr, None).unwrap_err().message;
    assert!(msg.contains("found 3"), "{msg}");
    let err = footprint_harness::io::try_filled(usize::MAX / 8, 0u64, "a test buffer").unwrap_err();
    assert!(err.message.contains("cannot allocate"), "{}", err.message);
    std::fs::remove_dir_all(&d).unwrap();
}

/// The output options (issue 14): a style the output type cannot hold, a bad value, and a
/// background that is not a usable PNG are each one line on stderr, exit 2, and no output file.
#[test]
fn output_options_fail_cleanly() {
    let d = tmpdir("output-options");
    let png = d.join("out.png");
    let pfm = d.join("out.pfm");
    let (p, f) = (png.to_str().unwrap(), pfm.to_str().unwrap());
    let bg16 = d.join("bg16.png");
    // A 16-bit RGBA background of the wrong size, and one cut short.
    let img = vec![[0.5f32, 0.25, 0.0, 1.0]; 12 * 12];
    let style = footprint_harness::io::image::PngStyle {
        alpha: true,
        sixteen: true,
        ..Default::default()
    };
    let bytes = footprint_harness::io::image::encode_png(&img, 12, 12, style).unwrap();
    std::fs::write(&bg16, &bytes).unwrap();
    let cut = d.join("cut.png");
    std::fs::write(&cut, &bytes[..bytes.len() - 20]).unwrap();
    let (b16, c) = (bg16.to_str().unwrap(), cut.to_str().unwrap());
    let r = d.join("ref.pfm");
    for (args, out) in [
        (vec!["--background", "transparent", "--out", f], f),
        (vec!["--gamma", "srgb", "--out", f], f),
        (vec!["--depth", "16", "--out", f], f),
        (vec!["--depth", "12", "--out", p], p),
        (vec!["--depth", "", "--out", p], p),
        (vec!["--gamma", "rec709", "--out", p], p),
        (vec!["--background", "", "--out", p], p),
        (vec!["--background", "Transparent.png", "--out", p], p),
        (vec!["--background", b16, "--size", "16x16", "--out", p], p),
        (vec!["--background", c, "--size", "12x12", "--out", p], p),
        (
            vec![
                "verify",
                "--gamma",
                "srgb",
                "--size",
                "12x12",
                "--reference-out",
                r.to_str().unwrap(),
            ],
            r.to_str().unwrap(),
        ),
        (
            vec!["bench", "--frames", "1", "--depth", "16", "--out", f],
            f,
        ),
    ] {
        let args: Vec<&str> = if matches!(args[0], "verify" | "bench") {
            args
        } else {
            [&["render"][..], &args].concat()
        };
        assert_eq!(
            footprint_harness::run(std::iter::once("footprint").chain(args.iter().copied())),
            2,
            "{args:?}"
        );
        assert!(!Path::new(out).exists(), "{args:?} left an output");
    }
    // The same 16-bit background at the right size is used.
    assert_eq!(
        run(&["--background", b16, "--size", "12x12", "--out", p]),
        0
    );
    std::fs::remove_dir_all(&d).unwrap();
}
