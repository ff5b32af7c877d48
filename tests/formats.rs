//! One volume saved in every supported format and encoding renders to the same image; streamed
//! renders (seekable file, pipe) equal in-memory ones.
//!
//! The writers here are minimal and independent of the readers: each follows its format's
//! documentation, so a reader that misreads a field shows up as a different image.

use base64::Engine as _;
use flate2::write::{GzEncoder, ZlibEncoder};
use flate2::Compression;
use footprint::source::SheetSource;
use footprint_harness::io::stream::{FileSource, Layout, PipeSource};
use footprint_harness::io::volume::SampleType;
use footprint_suite::tmpdir;
use std::io::Write;
use std::path::{Path, PathBuf};

const DIMS: [usize; 3] = [20, 16, 12];

/// A test volume of u16 samples: a blob with some structure.
fn samples() -> Vec<u16> {
    let mut v = Vec::new();
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let (x, y, z) = (
                    i as f32 - 9.5,
                    (j as f32 - 7.5) * 1.5,
                    (k as f32 - 5.5) * 2.5,
                );
                let r2 = x * x + y * y + z * z;
                v.push(
                    (4000.0 * (-r2 / 60.0).exp() + 300.0 * ((i + 2 * j + 3 * k) % 7) as f32) as u16,
                );
            }
        }
    }
    v
}

fn le(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn be(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_be_bytes()).collect()
}
fn gz(b: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::default());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}
fn zlib(b: &[u8]) -> Vec<u8> {
    let mut e = ZlibEncoder::new(Vec::new(), Compression::default());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}
fn b64(b: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(b)
}
fn ascii(v: &[u16]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn nrrd(dir: &Path, v: &[u16]) -> Vec<PathBuf> {
    let head = |enc: &str, extra: &str| {
        format!("NRRD0004\n# written by tests/formats.rs\ntype: unsigned short\ndimension: 3\nsizes: 20 16 12\n{extra}encoding: {enc}\n")
    };
    let sp = "spacings: 1 1.5 2.5\nendian: little\n";
    let sd = "space: right-anterior-superior\nspace directions: (1,0,0) (0,1.5,0) (0,0,2.5)\nspace origin: (0,0,0)\nendian: big\n";
    write(dir, "v.raw", &le(v));
    vec![
        write(dir, "detached.nhdr", (head("raw", sp) + "data file: v.raw\n").as_bytes()),
        write(dir, "attached.nrrd", &[(head("raw", sp) + "\n").into_bytes(), le(v)].concat()),
        write(dir, "gzip.nrrd", &[(head("gzip", sp) + "\n").into_bytes(), gz(&le(v))].concat()),
        write(dir, "ascii.nrrd", (head("ascii", "spacings: 1 1.5 2.5\n") + "\n" + &ascii(v)).as_bytes()),
        write(dir, "directions-big.nrrd", &[(head("raw", sd) + "\n").into_bytes(), be(v)].concat()),
        write(dir, "old-spellings.nrrd", &[b"NRRD0001\ntype: ushort\ndimension: 3\nsizes: 20 16 12\nspacings: 1 1.5 2.5\nendian: little\nencoding: raw\nbyteskip: 4\n\n".to_vec(), vec![9; 4], le(v)].concat()),
    ]
}

fn vti(dir: &Path, v: &[u16]) -> Vec<PathBuf> {
    let head = |extra: &str| {
        format!("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\"{extra}>\n<ImageData WholeExtent=\"0 19 0 15 0 11\" Origin=\"0 0 0\" Spacing=\"1 1.5 2.5\" Direction=\"1 0 0 0 1 0 0 0 1\">\n<Piece Extent=\"0 19 0 15 0 11\">\n<PointData Scalars=\"density\">\n")
    };
    let tail = "</PointData>\n<CellData>\n</CellData>\n</Piece>\n</ImageData>\n";
    let data = le(v);
    let n = data.len() as u32;
    // Uncompressed inline binary: UInt32 byte count, then the data, one base64 stream.
    let plain = b64(&[n.to_le_bytes().to_vec(), data.clone()].concat());
    // zlib: blocks of 2048 bytes, header [nblocks, blocksize, lastsize, sizes...] encoded apart.
    let blocks: Vec<Vec<u8>> = data.chunks(2048).map(zlib).collect();
    let last = (data.len() % 2048) as u32;
    let mut header = vec![blocks.len() as u32, 2048, last];
    header.extend(blocks.iter().map(|b| b.len() as u32));
    let hbytes: Vec<u8> = header.iter().flat_map(|x| x.to_le_bytes()).collect();
    let compressed = b64(&hbytes) + &b64(&blocks.concat());
    let array = |fmt: &str, body: &str, extra: &str| {
        format!("<DataArray type=\"UInt16\" Name=\"density\" format=\"{fmt}\"{extra}>\n{body}\n</DataArray>\n")
    };
    let appended = [
        (head("")
            + &array("appended", "", " offset=\"0\"")
            + tail
            + "<AppendedData encoding=\"raw\">\n_")
            .into_bytes(),
        n.to_le_bytes().to_vec(),
        data.clone(),
        b"\n</AppendedData>\n</VTKFile>\n".to_vec(),
    ]
    .concat();
    vec![
        write(
            dir,
            "ascii.vti",
            (head("") + &array("ascii", &ascii(v), "") + tail + "</VTKFile>\n").as_bytes(),
        ),
        write(
            dir,
            "binary.vti",
            (head("") + &array("binary", &plain, "") + tail + "</VTKFile>\n").as_bytes(),
        ),
        write(
            dir,
            "zlib.vti",
            (head(" compressor=\"vtkZLibDataCompressor\"")
                + &array("binary", &compressed, "")
                + tail
                + "</VTKFile>\n")
                .as_bytes(),
        ),
        write(dir, "appended.vti", &appended),
        write(
            dir,
            "appended-base64.vti",
            (head("")
                + &array("appended", "", " offset=\"0\"")
                + tail
                + "<AppendedData encoding=\"base64\">\n_"
                + &plain
                + "\n</AppendedData>\n</VTKFile>\n")
                .as_bytes(),
        ),
    ]
}

fn vtk(dir: &Path, v: &[u16]) -> Vec<PathBuf> {
    let head = |mode: &str| {
        format!("# vtk DataFile Version 3.0\ntest volume\n{mode}\nDATASET STRUCTURED_POINTS\nDIMENSIONS 20 16 12\nORIGIN 0 0 0\nSPACING 1 1.5 2.5\nPOINT_DATA 3840\nSCALARS density unsigned_short 1\nLOOKUP_TABLE default\n")
    };
    vec![
        write(
            dir,
            "ascii.vtk",
            (head("ASCII") + &ascii(v) + "\n").as_bytes(),
        ),
        write(
            dir,
            "binary.vtk",
            &[head("BINARY").into_bytes(), be(v), b"\n".to_vec()].concat(),
        ),
        // As VTK 1.0 wrote it (a blank line after the title, ASPECT_RATIO, no component count),
        // with what later versions and hand edits add: keywords in lower case, comment lines,
        // cell data first, a FIELD and a METADATA block before the scalars, vectors after.
        write(
            dir,
            "version1.vtk",
            format!(
                "# vtk DataFile Version 1.0\nold volume\n\nASCII\n\ndataset structured_points\n\
                 # made by hand\ndimensions 20 16 12\naspect_ratio 1 1.5 2.5\norigin 0 0 0\n\n\
                 CELL_DATA 3135\nscalars cells float\nlookup_table default\n{}\n\
                 point_data 3840\nFIELD extra 2\nmask 1 3840 unsigned_char\n{}\n\
                 METADATA\nINFORMATION 0\n\nrgb 3 3840 float\n{}\n\
                 scalars density unsigned_short\nLOOKUP_TABLE default\n{}\n\
                 VECTORS flow float\n{}\n",
                "1 ".repeat(19 * 15 * 11),
                "0 ".repeat(3840),
                "0.5 ".repeat(3 * 3840),
                ascii(v),
                "0 ".repeat(3 * 3840),
            )
            .as_bytes(),
        ),
        // Binary, with a field array of another type before the scalars and one after.
        write(
            dir,
            "binary-field.vtk",
            &[
                b"# vtk DataFile Version 5.1\nt\nBINARY\nDATASET STRUCTURED_POINTS\n\
                  DIMENSIONS 20 16 12\nSPACING 1 1.5 2.5\nORIGIN 0 0 0\nPOINT_DATA 3840\n\
                  FIELD FieldData 1\ntemperature 1 3840 double\n"
                    .to_vec(),
                vec![0x40; 8 * 3840],
                b"\nSCALARS density unsigned_short 1\nLOOKUP_TABLE default\n".to_vec(),
                be(v),
                b"\nNORMALS n float\n".to_vec(),
                vec![0; 12 * 3840],
                b"\n".to_vec(),
            ]
            .concat(),
        ),
    ]
}

fn metaimage(dir: &Path, v: &[u16]) -> Vec<PathBuf> {
    let head = |extra: &str, file: &str| {
        format!("ObjectType = Image\nNDims = 3\nDimSize = 20 16 12\nElementType = MET_USHORT\nElementSpacing = 1 1.5 2.5\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n{extra}ElementDataFile = {file}\n")
    };
    let z = zlib(&le(v));
    write(dir, "meta.zraw", &z);
    vec![
        write(
            dir,
            "local.mha",
            &[
                head("ElementByteOrderMSB = False\n", "LOCAL").into_bytes(),
                le(v),
            ]
            .concat(),
        ),
        write(
            dir,
            "big.mha",
            &[
                head("BinaryDataByteOrderMSB = True\n", "LOCAL").into_bytes(),
                be(v),
            ]
            .concat(),
        ),
        write(dir, "detached.mhd", head("", "v.raw").as_bytes()),
        write(
            dir,
            "zlib.mhd",
            head(
                &format!("CompressedData = True\nCompressedDataSize = {}\n", z.len()),
                "meta.zraw",
            )
            .as_bytes(),
        ),
    ]
}

/// A NIfTI-1 header (little-endian), datatype 512 (u16), optional scaling.
fn nifti_header(slope: f32, inter: f32) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dims: [i16; 8] = [3, 20, 16, 12, 1, 1, 1, 1];
    for (i, d) in dims.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&512i16.to_le_bytes());
    h[72..74].copy_from_slice(&16i16.to_le_bytes());
    for (i, p) in [1.0f32, 1.0, 1.5, 2.5].iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&slope.to_le_bytes());
    h[116..120].copy_from_slice(&inter.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h
}

fn nifti(dir: &Path, v: &[u16]) -> Vec<PathBuf> {
    let plain = [nifti_header(0.0, 0.0), le(v)].concat();
    // Stored values s with scl_slope 2, scl_inter −100 mean 2s − 100: store (v + 100)/2 for even v.
    let halves: Vec<u16> = v.iter().map(|&x| (x & !1).wrapping_add(100) / 2).collect();
    let scaled = [nifti_header(2.0, -100.0), le(&halves)].concat();
    vec![
        write(dir, "plain.nii", &plain),
        write(dir, "plain.nii.gz", &gz(&plain)),
        write(dir, "scaled.nii", &scaled),
    ]
}

fn render(args: &[&str], out: &Path) -> Vec<u8> {
    let mut v = vec![
        "footprint",
        "render",
        "--size",
        "64x64",
        "--window",
        "0,4500",
        "--shading",
        "phong",
    ];
    v.extend_from_slice(args);
    v.extend_from_slice(&["--out", out.to_str().unwrap()]);
    assert_eq!(footprint_harness::run(v.clone()), 0, "{v:?}");
    std::fs::read(out).unwrap()
}

#[test]
fn every_format_renders_the_same_image() {
    let d = tmpdir("formats");
    let v = samples();
    let out = d.join("out.png");
    let raw = write(&d, "volume.raw", &le(&v));
    let reference = render(
        &[
            raw.to_str().unwrap(),
            "--dims",
            "20,16,12",
            "--type",
            "u16",
            "--spacing",
            "1,1.5,2.5",
            "--view",
            "30,20,0",
        ],
        &out,
    );
    let mut files = nrrd(&d, &v);
    files.extend(vti(&d, &v));
    files.extend(vtk(&d, &v));
    files.extend(metaimage(&d, &v));
    files.extend(nifti(&d, &v));
    assert_eq!(files.len(), 22);
    for f in &files {
        let name = f.file_name().unwrap().to_str().unwrap();
        let img = render(&[f.to_str().unwrap(), "--view", "30,20,0"], &out);
        if name == "scaled.nii" {
            // Values rounded to even numbers by the writer: a close, not identical, image.
            let (w, h, a) = footprint_harness::io::image::decode_png_rgba(&img, "a").unwrap();
            let (_, _, b) = footprint_harness::io::image::decode_png_rgba(&reference, "b").unwrap();
            let worst = a
                .iter()
                .zip(&b)
                .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
                .fold(0.0f32, f32::max);
            assert!(worst <= 3.0 / 255.0, "{name}: differs by {worst} ({w}x{h})");
        } else {
            assert!(
                img == reference,
                "{name} renders differently from the raw volume"
            );
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn streamed_renders_equal_loaded_renders() {
    let d = tmpdir("stream");
    let v = samples();
    let out = d.join("out.png");
    let files = nrrd(&d, &v);
    let mhd = metaimage(&d, &v);
    let raw = d.join("v.raw");
    // Straight (sheets along z, the file's slice axis), and views whose sheets run along y and x.
    // With `--slicing object --lod 0` (nothing left to a pilot) the stream is read three sheets
    // at a time, not held (`tests/same_picture.rs` has the default flags).
    let fixed = ["--slicing", "object", "--lod", "0"];
    for view in ["30,20,0", "0,80,0", "80,0,0", "180,0,0"] {
        let loaded = render(
            &[&[files[0].to_str().unwrap(), "--view", view][..], &fixed].concat(),
            &out,
        );
        for (args, what) in [
            (
                vec!["--stream", files[0].to_str().unwrap()],
                "detached NRRD",
            ),
            (
                vec!["--stream", files[1].to_str().unwrap()],
                "attached NRRD",
            ),
            (vec!["--stream", mhd[0].to_str().unwrap()], "MetaImage"),
            (
                vec![
                    "--stream",
                    raw.to_str().unwrap(),
                    "--dims",
                    "20,16,12",
                    "--type",
                    "u16",
                    "--spacing",
                    "1,1.5,2.5",
                ],
                "raw",
            ),
        ] {
            let mut a = args.clone();
            a.extend_from_slice(&["--view", view]);
            a.extend_from_slice(&fixed);
            assert!(
                render(&a, &out) == loaded,
                "{what} streamed at view {view} differs from loaded"
            );
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// The pipe source delivers what the file source does, z-slice by z-slice, and refuses anything else.
#[test]
fn pipe_source_reads_file_order_only() {
    let d = tmpdir("pipe");
    let v = samples();
    let raw = write(&d, "v.raw", &le(&v));
    let layout = Layout {
        path: raw,
        offset: 0,
        dims: DIMS,
        ty: SampleType::U16,
        big_endian: false,
        values: footprint_harness::io::volume::ValueMap::IDENTITY,
    };
    let mut file = FileSource::open(layout).unwrap();
    let bytes = le(&v);
    let mut pipe = PipeSource::new(
        std::io::Cursor::new(bytes.clone()),
        DIMS,
        SampleType::U16,
        false,
        "test pipe",
    );
    assert_eq!(pipe.sequential_axis(), Some(2));
    let (mut a, mut b) = (vec![0.0f32; 320], vec![0.0f32; 320]);
    for k in 0..DIMS[2] {
        file.read_sheet(2, k, &mut a).unwrap();
        pipe.read_sheet(2, k, &mut b).unwrap();
        assert_eq!(a, b, "slice {k}");
    }
    let mut pipe = PipeSource::new(
        std::io::Cursor::new(bytes.clone()),
        DIMS,
        SampleType::U16,
        false,
        "test pipe",
    );
    assert!(pipe.read_sheet(2, 1, &mut b).is_err(), "out of order");
    assert!(pipe.read_sheet(1, 0, &mut b).is_err(), "another axis");
    let mut short = PipeSource::new(
        std::io::Cursor::new(bytes[..1000].to_vec()),
        DIMS,
        SampleType::U16,
        false,
        "test pipe",
    );
    let err = short
        .read_sheet(2, 0, &mut b)
        .and_then(|_| short.read_sheet(2, 1, &mut b))
        .unwrap_err();
    assert!(err.message.contains("shorter than --dims"), "{err}");
    // Strided sheets from the file source match the volume read whole, along every axis.
    let vol = footprint_harness::io::formats::nrrd::load(&nrrd(&d, &v)[0]).unwrap();
    let layout = Layout {
        path: d.join("v.raw"),
        offset: 0,
        dims: DIMS,
        ty: SampleType::U16,
        big_endian: false,
        values: footprint_harness::io::volume::ValueMap::IDENTITY,
    };
    let mut file = FileSource::open(layout).unwrap();
    for (axis, &count) in DIMS.iter().enumerate() {
        let (x, y) = footprint::geometry::in_sheet_axes(axis);
        let len = DIMS[x] * DIMS[y];
        let (mut a, mut b) = (vec![0.0f32; len], vec![0.0f32; len]);
        for s in (0..count).rev().chain(0..count) {
            file.read_sheet(axis, s, &mut a).unwrap();
            vol.sheet_into(axis, s, &mut b);
            assert_eq!(a, b, "axis {axis} sheet {s}");
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// Orientation reaches the renderer the same way from every format that states it: the grid axes
/// permuted (i → world y, j → world z, k → world x) in NRRD `space directions`, VTI `Direction`
/// (row-major, columns are the axes), MetaImage `TransformMatrix` (row i is axis i) and a NIfTI
/// sform all give one image, and it differs from the axis-aligned one.
#[test]
fn orientation_is_honoured_by_every_format() {
    let d = tmpdir("orientation");
    let v = samples();
    let out = d.join("out.png");
    write(&d, "v.raw", &le(&v));
    let nrrd = write(&d, "o.nhdr", b"NRRD0005\ntype: uint16\ndimension: 3\nsizes: 20 16 12\nspace dimension: 3\nspace directions: (0,1,0) (0,0,1.5) (2.5,0,0)\nendian: little\nencoding: raw\ndata file: v.raw\n");
    let data = le(&v);
    let plain = b64(&[(data.len() as u32).to_le_bytes().to_vec(), data.clone()].concat());
    let vti = write(&d, "o.vti", format!("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n<ImageData WholeExtent=\"0 19 0 15 0 11\" Spacing=\"1 1.5 2.5\" Direction=\"0 0 1 1 0 0 0 1 0\">\n<Piece Extent=\"0 19 0 15 0 11\"><PointData Scalars=\"s\"><DataArray type=\"UInt16\" Name=\"s\" format=\"binary\">{plain}</DataArray></PointData></Piece></ImageData></VTKFile>\n").as_bytes());
    let mha = write(&d, "o.mha", &[b"ObjectType = Image\nNDims = 3\nDimSize = 20 16 12\nElementType = MET_USHORT\nElementSpacing = 1 1.5 2.5\nTransformMatrix = 0 1 0 0 0 1 1 0 0\nElementDataFile = LOCAL\n".to_vec(), data.clone()].concat());
    let mut h = nifti_header(0.0, 0.0);
    h[254..256].copy_from_slice(&1i16.to_le_bytes());
    // srow_x/y/z: world = S · (i, j, k); column j is axis j's step.
    let rows = [
        [0.0f32, 0.0, 2.5, 0.0],
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.5, 0.0, 0.0],
    ];
    for (r, row) in rows.iter().enumerate() {
        for (c, x) in row.iter().enumerate() {
            h[280 + 16 * r + 4 * c..284 + 16 * r + 4 * c].copy_from_slice(&x.to_le_bytes());
        }
    }
    let nii = write(&d, "o.nii", &[h, data].concat());
    let view = ["--view", "30,20,0"];
    let imgs: Vec<Vec<u8>> = [&nrrd, &vti, &mha, &nii]
        .iter()
        .map(|p| render(&[p.to_str().unwrap(), view[0], view[1]], &out))
        .collect();
    for (img, name) in imgs.iter().zip(["nhdr", "vti", "mha", "nii"]) {
        assert!(
            img == &imgs[0],
            "the oriented {name} renders differently from the NRRD"
        );
    }
    let aligned = render(
        &[nrrd::aligned(&d).to_str().unwrap(), view[0], view[1]],
        &out,
    );
    assert!(aligned != imgs[0], "orientation made no difference");
    std::fs::remove_dir_all(&d).unwrap();
}

mod nrrd {
    /// The same data with the same spacings but no orientation.
    pub fn aligned(d: &std::path::Path) -> std::path::PathBuf {
        super::write(d, "aligned.nhdr", b"NRRD0004\ntype: uint16\ndimension: 3\nsizes: 20 16 12\nspacings: 1 1.5 2.5\nendian: little\nencoding: raw\ndata file: v.raw\n")
    }
}

/// A data file is read for exactly the bytes its header declares: an endless device (`/dev/zero`)
/// and a file with trailing bytes load; `byte skip: -1` on a device (whose end is unknowable) is
/// an error; `--array` names a VTK file's array and lists them when the name is wrong.
#[test]
fn data_files_are_read_to_the_declared_size_only() {
    use footprint_harness::io::formats;
    let d = tmpdir("declared-size");
    if Path::new("/dev/zero").exists() {
        let nhdr = write(
            &d,
            "zero.nhdr",
            b"NRRD0004\ntype: uint16\ndimension: 3\nsizes: 64 64 64\nendian: little\n\
              encoding: raw\nbyte skip: 100\ndata file: /dev/zero\n",
        );
        let v = formats::load(&nhdr, None).unwrap();
        assert_eq!(
            (v.dims, v.value(0), v.value(v.len() - 1)),
            ([64; 3], 0.0, 0.0)
        );
        let mhd = write(
            &d,
            "zero.mhd",
            b"NDims = 3\nDimSize = 32 32 32\nElementType = MET_FLOAT\nElementDataFile = /dev/zero\n",
        );
        assert_eq!(formats::load(&mhd, None).unwrap().dims, [32; 3]);
        let tail = write(
            &d,
            "tail.nhdr",
            b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: raw\nbyte skip: -1\n\
              data file: /dev/zero\n",
        );
        let msg = formats::load(&tail, None).unwrap_err().message;
        assert!(msg.contains("regular file"), "{msg}");
        // The CLI renders it (a constant volume needs a window).
        let out = d.join("zero.png");
        let args = [
            "footprint",
            "render",
            nhdr.to_str().unwrap(),
            "--window",
            "0,1",
        ];
        let mut args: Vec<&str> = args.to_vec();
        args.extend(["--size", "32x32", "--out", out.to_str().unwrap()]);
        assert_eq!(footprint_harness::run(args), 0);
    }
    // Trailing bytes after attached and detached samples: read up to the samples, then stopped.
    let v = samples();
    let mut attached =
        b"NRRD0004\ntype: uint16\ndimension: 3\nsizes: 20 16 12\nendian: little\nencoding: raw\n\n"
            .to_vec();
    attached.extend(le(&v));
    attached.extend([9u8; 1000]);
    let a = write(&d, "trailing.nrrd", &attached);
    let loaded = formats::load(&a, None).unwrap();
    assert_eq!(loaded.value(3839), f32::from(v[3839]));
    // --array picks, and a wrong name lists the arrays.
    let files = vtk(&d, &v);
    let old = &files[2];
    let mask = formats::load_array(old, None, Some("mask")).unwrap();
    assert_eq!((mask.dims, mask.value(7)), (DIMS, 0.0));
    let msg = formats::load_array(old, None, Some("nope"))
        .unwrap_err()
        .message;
    for name in ["mask", "rgb", "density"] {
        assert!(msg.contains(name), "{msg}");
    }
    let msg = formats::load_array(old, None, Some("rgb"))
        .unwrap_err()
        .message;
    assert!(msg.contains("3 components"), "{msg}");
    let t = formats::load_array(&files[3], None, Some("temperature")).unwrap();
    assert_eq!(t.value(0), f64::from_be_bytes([0x40; 8]) as f32);
    let msg = formats::load_array(&a, None, Some("density"))
        .unwrap_err()
        .message;
    assert!(msg.contains("--array"), "{msg}");
    std::fs::remove_dir_all(&d).unwrap();
}
