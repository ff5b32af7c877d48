//! The hostile-input suite: every input a bad-input campaign found harmful, and more, each run as
//! its own `footprint` process under a 4 GiB address-space limit (`ulimit -v`) with a 30 s bound.
//! Each must end with exit 2 and exactly one line on stderr (or a documented success), leave no
//! output file and no temporary beside it, and never die of a signal (an abort on a failed
//! allocation, a stack overflow) or hang.
//!
//! The process is the released `footprint` when `FOOTPRINT_BIN` names it (CI does this), and
//! otherwise this test binary run again as a child that calls `footprint_harness::run` — the one
//! function `footprint`'s `main` calls — so `cargo test` alone runs the whole suite.
//!
//! A custom harness (`harness = false`): `main` is either the suite or, with `FOOTPRINT_CHILD`
//! set, the command line.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The address-space limit every case runs under, KiB (4 GiB).
const LIMIT_KIB: u64 = 4 << 20;
/// How long a case may take.
const TIME_LIMIT: Duration = Duration::from_secs(30);
/// Separates the child's arguments in `FOOTPRINT_CHILD`.
const SEP: char = '\u{1f}';

fn main() {
    if let Ok(args) = std::env::var("FOOTPRINT_CHILD") {
        let args = std::iter::once("footprint").chain(args.split(SEP).filter(|a| !a.is_empty()));
        std::process::exit(footprint_harness::run(args));
    }
    let dir = std::env::temp_dir().join(format!("fp-hostile-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cases = cases(&dir);
    let mut failed = 0;
    for case in &cases {
        match run_case(case, &dir) {
            Ok(note) => println!("ok    {}: {note}", case.name),
            Err(why) => {
                println!("FAIL  {}: {why}", case.name);
                failed += 1;
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    println!(
        "hostile input: {} cases, {failed} failed (4 GiB address space, {} s each)",
        cases.len(),
        TIME_LIMIT.as_secs()
    );
    if failed > 0 {
        std::process::exit(1);
    }
}

/// What a case must end with.
enum Expect {
    /// Exit 2, one line on stderr containing this text, no output.
    Refused(&'static str),
    /// Exit 1 (a check failed), one line on stderr containing this text, no output.
    CheckFails(&'static str),
    /// Exit 0 and the output written: the documented success.
    Renders,
}

struct Case {
    name: &'static str,
    args: Vec<String>,
    /// Bytes piped to standard input (none: stdin is empty).
    stdin: Option<Vec<u8>>,
    expect: Expect,
    /// Files that must not exist afterwards (the outputs, leftovers).
    gone: Vec<PathBuf>,
    /// Files written just before the run (name, bytes).
    before: Vec<(PathBuf, Vec<u8>)>,
}

fn run_case(case: &Case, dir: &Path) -> Result<String, String> {
    for (path, bytes) in &case.before {
        std::fs::write(path, bytes).map_err(|e| e.to_string())?;
    }
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(format!("ulimit -v {LIMIT_KIB} && exec \"$@\""))
        .arg("sh");
    match std::env::var_os("FOOTPRINT_BIN") {
        Some(bin) => {
            cmd.arg(bin).args(&case.args);
        }
        None => {
            cmd.arg(std::env::current_exe().unwrap());
            let joined: Vec<&str> = case.args.iter().map(String::as_str).collect();
            cmd.env("FOOTPRINT_CHILD", joined.join(&SEP.to_string()));
        }
    }
    cmd.current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().map_err(|e| format!("cannot start: {e}"))?;
    let mut stdin = child.stdin.take().unwrap();
    let input = case.stdin.clone().unwrap_or_default();
    // A writer thread: the child may stop reading early (that is the point of some cases).
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "still running after {} s: killed",
                TIME_LIMIT.as_secs()
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let elapsed = start.elapsed();
    let _ = writer.join();
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let lines: Vec<&str> = stderr.lines().collect();
    let code = status
        .code()
        .ok_or_else(|| format!("killed by a signal ({status}); stderr: {stderr}"))?;
    let one_line = |want: &str| -> Result<String, String> {
        match lines.as_slice() {
            [line] if line.starts_with("footprint: ") && line.contains(want) => {
                Ok(line.to_string())
            }
            _ => Err(format!(
                "expected one line containing {want:?} on stderr, got {stderr:?}"
            )),
        }
    };
    let note = match case.expect {
        Expect::Refused(want) if code == 2 => one_line(want)?,
        Expect::CheckFails(want) if code == 1 => one_line(want)?,
        Expect::Renders if code == 0 => String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .unwrap_or("")
            .to_string(),
        _ => return Err(format!("exit {code}; stderr: {stderr}")),
    };
    for f in &case.gone {
        if f.exists() {
            return Err(format!("{} was left behind", f.display()));
        }
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    if !leftovers.is_empty() {
        return Err(format!("temporaries left: {leftovers:?}"));
    }
    Ok(format!("{:.2} s: {note}", elapsed.as_secs_f64()))
}

fn s(v: &str) -> String {
    v.to_string()
}

fn args(v: &[&str]) -> Vec<String> {
    v.iter().map(|a| s(a)).collect()
}

fn refused(name: &'static str, a: &[&str], want: &'static str, dir: &Path) -> Case {
    Case {
        name,
        args: args(a),
        stdin: None,
        expect: Expect::Refused(want),
        gone: vec![dir.join("out.png")],
        before: vec![],
    }
}

fn cases(dir: &Path) -> Vec<Case> {
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(dir.join(name), bytes).unwrap();
        name.to_string()
    };
    let mut c = Vec::new();

    // ASCII data declaring 1600³ samples and holding 3.
    let nrrd = write(
        "ascii.nrrd",
        b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1600 1600 1600\nencoding: ascii\n\n1 2 3\n",
    );
    c.push(refused(
        "ASCII NRRD, 1600³ declared, 3 numbers",
        &["render", &nrrd, "--out", "out.png"],
        "expected 4096000000 values, found 3",
        dir,
    ));
    let vti = write(
        "ascii.vti",
        b"<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 1599 0 1599 0 1599\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 1599 0 1599 0 1599\"><PointData Scalars=\"s\"><DataArray type=\"Float32\" Name=\"s\" format=\"ascii\">1 2 3</DataArray></PointData></Piece></ImageData></VTKFile>\n",
    );
    c.push(refused(
        "ASCII VTI, 1600³ declared, 3 numbers",
        &["render", &vti, "--out", "out.png"],
        "found 3",
        dir,
    ));
    let vtk = write(
        "ascii.vtk",
        b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1600 1600 1600\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 4096000000\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3\n",
    );
    c.push(refused(
        "ASCII legacy VTK, 1600³ declared, 3 numbers",
        &["render", &vtk, "--out", "out.png"],
        "found 3",
        dir,
    ));

    // A pipe declaring 65536×65536 and delivering 1000 bytes.
    c.push(Case {
        name: "stdin: 1000 bytes for a 65536×65536 slice",
        args: args(&[
            "render",
            "--stream",
            "-",
            "--dims",
            "65536,65536,1",
            "--type",
            "u8",
            "--out",
            "out.png",
        ]),
        stdin: Some(vec![0; 1000]),
        expect: Expect::Refused("the stream ended after 1000 of its 4294967296 bytes"),
        gone: vec![dir.join("out.png")],
        before: vec![],
    });

    // XML nested 20 000 elements deep (140 KB).
    let deep = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\">{}{}</VTKFile>\n",
        "<a>".repeat(20_000),
        "</a>".repeat(20_000)
    );
    let deep = write("deep.vti", deep.as_bytes());
    c.push(refused(
        "VTI nested 20 000 deep",
        &["render", &deep, "--out", "out.png"],
        "nested",
        dir,
    ));

    // An NRRD whose detached data file is an endless stream (/dev/zero) for a 64³ volume: the
    // documented success — exactly the declared 256 KiB are read, never to the end.
    let endless = write(
        "endless.nhdr",
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 64 64 64\nencoding: raw\ndata file: /dev/zero\n",
    );
    c.push(Case {
        name: "NRRD with data file /dev/zero (endless): reads 64³ bytes and renders",
        args: args(&[
            "render",
            &endless,
            "--window",
            "0,1",
            "--size",
            "64x64",
            "--out",
            "endless.png",
        ]),
        stdin: None,
        expect: Expect::Renders,
        gone: vec![],
        before: vec![],
    });

    // A valid 8³ NIfTI followed by 3 GiB of zeros in the same gzip stream: the documented
    // success — trailing data are ignored and never inflated.
    let bomb = write("trailing.nii.gz", &nifti_gz_with_trailing_zeros(3 << 30));
    c.push(Case {
        name: ".nii.gz: 8³ volume then 3 GiB of zeros (trailing data ignored, not inflated)",
        args: args(&["render", &bomb, "--size", "64x64", "--out", "nii.png"]),
        stdin: None,
        expect: Expect::Renders,
        gone: vec![],
        before: vec![],
    });

    // A gzip NRRD declaring 8³ whose stream inflates to 3 GiB: cut off after 8³ + 1 bytes.
    let mut gz_nrrd =
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nencoding: gzip\n\n".to_vec();
    gz_nrrd.extend(gzip_of_zeros(&[], 3 << 30));
    let gz_nrrd = write("bomb.nrrd", &gz_nrrd);
    c.push(refused(
        "gzip NRRD: 8³ declared, 3 GiB inflated",
        &["render", &gz_nrrd, "--out", "out.png"],
        "more than 512 bytes",
        dir,
    ));

    // A 12000×12000 PNG (a few hundred KB) as the background of a 64×64 render.
    let png = write("huge.png", &png_of_zeros(12_000, 12_000));
    c.push(refused(
        "PNG background of 12000x12000",
        &[
            "render",
            "--background",
            &png,
            "--size",
            "64x64",
            "--out",
            "out.png",
        ],
        "background is 12000x12000",
        dir,
    ));

    // An image larger than the address space allows.
    c.push(refused(
        "render --size 16384x16384 under 4 GiB",
        &["render", "--size", "16384x16384", "--out", "out.png"],
        "cannot allocate",
        dir,
    ));

    // Special files: a FIFO with no writer as a detached data file, a volume and a stream.
    if mkfifo(&dir.join("fifo.raw")) {
        let nhdr = write("fifo.nhdr", b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: fifo.raw\n");
        c.push(refused(
            "FIFO as a detached data file",
            &["render", &nhdr, "--out", "out.png"],
            "FIFO or socket",
            dir,
        ));
        c.push(refused(
            "FIFO as a raw volume",
            &[
                "render", "fifo.raw", "--dims", "2,2,2", "--type", "u8", "--out", "out.png",
            ],
            "not a regular file",
            dir,
        ));
        c.push(refused(
            "FIFO as --stream",
            &[
                "render", "--stream", "fifo.raw", "--dims", "2,2,2", "--type", "u8", "--out",
                "out.png",
            ],
            "not a regular file",
            dir,
        ));
        c.push(refused(
            "FIFO as --tf",
            &["render", "--tf", "fifo.raw", "--out", "out.png"],
            "not a regular file",
            dir,
        ));
    }

    // compare: NaN fails the check; a NaN threshold is refused; a huge declared PFM costs nothing.
    let good = write("good.pfm", &pfm(&[0.5, 1.0, 0.25, 0.0]));
    let nan = write("nan.pfm", &pfm(&[0.5, f32::NAN, 0.25, 0.0]));
    c.push(Case {
        name: "compare with a NaN image",
        args: args(&["compare", &nan, &good, "--max-diff", "0.1"]),
        stdin: None,
        expect: Expect::CheckFails("non-finite value"),
        gone: vec![],
        before: vec![],
    });
    c.push(refused(
        "compare --max-diff NaN",
        &["compare", &good, &good, "--max-diff", "NaN"],
        "--max-diff NaN",
        dir,
    ));
    let big = write("big.pfm", b"Pf\n100000 100000\n-1.0\n\0\0\0\0");
    c.push(refused(
        "PFM declaring 100000x100000",
        &["compare", &big, &good],
        "for 100000x100000",
        dir,
    ));

    // Negative numbers reach the value parsers, which name the flag and the range.
    c.push(refused(
        "--zoom -1",
        &["render", "--zoom", "-1", "--out", "out.png"],
        "--zoom",
        dir,
    ));
    c.push(refused(
        "--min-radius -1",
        &["render", "--min-radius", "-1", "--out", "out.png"],
        "--min-radius",
        dir,
    ));
    c.push(refused(
        "--spacing -1,1,1",
        &["render", "--spacing", "-1,1,1", "--out", "out.png"],
        "--spacing",
        dir,
    ));
    c.push(refused(
        "--dims -64,64,64",
        &[
            "render",
            "raw.bin",
            "--dims",
            "-64,64,64",
            "--type",
            "u8",
            "--out",
            "out.png",
        ],
        "--dims <DIMS>': '-64' is not a whole number >= 1",
        dir,
    ));

    // More: raw dimensions past the limit, a NIfTI whose data lie past its end, a zlib VTI block
    // that inflates past its declared size.
    write("raw.bin", &[0; 64]);
    c.push(refused(
        "raw --dims 65536³",
        &[
            "render",
            "raw.bin",
            "--dims",
            "65536,65536,65536",
            "--type",
            "f64",
            "--out",
            "out.png",
        ],
        "voxels",
        dir,
    ));
    let far = write("far.nii", &nifti_header(1e8));
    c.push(refused(
        "NIfTI vox_offset 1e8 in a 352-byte file",
        &["render", &far, "--out", "out.png"],
        "truncated",
        dir,
    ));
    let zvti = write("zbomb.vti", &zlib_vti_bomb());
    c.push(refused(
        "zlib VTI block declaring 512 bytes, inflating to 1 GiB",
        &["render", &zvti, "--out", "out.png"],
        "more than 512 bytes",
        dir,
    ));

    // A volume without one finite sample.
    write("nan.raw", &[0xff; 32]);
    c.push(refused(
        "raw f32 volume of NaN only",
        &[
            "render", "nan.raw", "--dims", "2,2,2", "--type", "f32", "--out", "out.png",
        ],
        "no sample is finite",
        dir,
    ));

    // A temporary a killed run left beside the output is removed by the next run.
    let stale = dir.join(".out2.png.tmp-999999");
    c.push(Case {
        name: "leftover temporary from a killed run",
        args: args(&["render", "--size", "32x32", "--out", "out2.png"]),
        stdin: None,
        expect: Expect::Renders,
        gone: vec![stale.clone()],
        before: vec![(stale, b"half a PNG".to_vec())],
    });
    c
}

fn mkfifo(path: &Path) -> bool {
    Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success())
}

fn pfm(values: &[f32]) -> Vec<u8> {
    let mut b = format!("Pf\n{} 1\n-1.0\n", values.len()).into_bytes();
    for v in values {
        b.extend(v.to_le_bytes());
    }
    b
}

/// A 352-byte little-endian NIfTI-1 header of an 8³ u8 volume whose data start at `vox_offset`.
fn nifti_header(vox_offset: f32) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3i16, 8, 8, 8, 1, 1, 1, 1].iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes());
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    for i in 0..4 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&vox_offset.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h
}

fn nifti_gz_with_trailing_zeros(zeros: u64) -> Vec<u8> {
    let mut head = nifti_header(352.0);
    head.extend((0..512u32).map(|i| (i * 37 % 251) as u8));
    gzip_of_zeros(&head, zeros)
}

/// A gzip stream of `prefix` followed by `zeros` zero bytes, built in milliseconds: deflate blocks
/// of 1 MiB of zeros, each ending on a byte boundary (a sync flush), that refer back only to
/// zeros, so one such block repeated is a valid stream. The trailer's CRC and size are right.
fn gzip_of_zeros(prefix: &[u8], zeros: u64) -> Vec<u8> {
    use flate2::{Compress, Compression, Crc, FlushCompress};
    const CHUNK: usize = 1 << 20;
    let mut z = Compress::new(Compression::fast(), false);
    let mut deflate = |input: &[u8], flush| {
        let mut out = Vec::with_capacity(input.len() + 1024);
        let before = z.total_in();
        loop {
            let done = (z.total_in() - before) as usize;
            z.compress_vec(&input[done..], &mut out, flush).unwrap();
            if (z.total_in() - before) as usize == input.len() && out.len() < out.capacity() {
                break out;
            }
            out.reserve(1 << 16);
        }
    };
    let zero = vec![0u8; CHUNK];
    let mut crc = Crc::new();
    let mut body = deflate(prefix, FlushCompress::Sync);
    crc.update(prefix);
    // The first zero chunk fills the window with zeros; the second is the repeatable block.
    body.extend(deflate(&zero, FlushCompress::Sync));
    crc.update(&zero);
    let block = deflate(&zero, FlushCompress::Sync);
    let mut left = zeros - CHUNK as u64;
    while left >= CHUNK as u64 {
        body.extend_from_slice(&block);
        crc.update(&zero);
        left -= CHUNK as u64;
    }
    body.extend(deflate(&zero[..left as usize], FlushCompress::Finish));
    crc.update(&zero[..left as usize]);
    let mut gz = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 255];
    gz.extend(body);
    gz.extend(crc.sum().to_le_bytes());
    gz.extend(((prefix.len() as u64 + zeros) as u32).to_le_bytes());
    gz
}

/// A greyscale 8-bit PNG of `w × h` zeros (each row a filter byte and zeros), compressed.
fn png_of_zeros(w: u32, h: u32) -> Vec<u8> {
    use std::io::Write as _;
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend(kind);
        c.extend(data);
        c.extend(crc.sum().to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    let row = vec![0u8; w as usize + 1];
    for _ in 0..h {
        z.write_all(&row).unwrap();
    }
    let idat = z.finish().unwrap();
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &idat));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// A VTI whose one zlib block says it holds 512 bytes (an 8³ u8 extent) and inflates to 1 GiB.
fn zlib_vti_bomb() -> Vec<u8> {
    use base64::Engine as _;
    let gz = gzip_of_zeros(&[], 1 << 30);
    // The same deflate data, in a zlib wrapper (the adler checksum is never reached).
    let mut z = vec![0x78, 0x01];
    z.extend(&gz[10..gz.len() - 8]);
    z.extend([0, 0, 0, 0]);
    let mut head = Vec::new();
    for v in [1u32, 512, 512, z.len() as u32] {
        head.extend(v.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD;
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 7 0 7 0 7\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 7 0 7 0 7\"><PointData Scalars=\"s\"><DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">{}{}</DataArray></PointData></Piece></ImageData></VTKFile>\n",
        b64.encode(&head),
        b64.encode(&z)
    )
    .into_bytes()
}
