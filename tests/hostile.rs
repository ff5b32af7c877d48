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
//! Cases marked release-only (two renders of a 600³ volume, hundreds of millions of voxels) run
//! only against `FOOTPRINT_BIN`; a debug child would not finish them in time.
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
    let release = std::env::var_os("FOOTPRINT_BIN").is_some();
    for case in &cases {
        if case.release_only && !release {
            println!(
                "skip  {}: runs against the release binary only (FOOTPRINT_BIN)",
                case.name
            );
            continue;
        }
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
    /// Ended by the case's signal (`More::signal`), leaving no output and no temporary.
    Signalled,
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
    /// Extra `ulimit` settings for this case (e.g. `-f 16`, or a lower `-v`), applied after the
    /// 4 GiB address-space limit.
    ulimit: &'static str,
    /// A check of what the run left in the case folder (the image right, an input untouched),
    /// run after the exit and outputs are checked.
    check: Option<Check>,
    /// Run only against the release binary (`FOOTPRINT_BIN`): the case renders hundreds of
    /// millions of voxels, which a debug build does not do within the time limit.
    release_only: bool,
    /// What the third campaign's cases add: links planted, standard output elsewhere, a signal.
    more: More,
}

/// The third campaign's additions to a [`Case`] (issue 79).
#[derive(Default)]
struct More {
    /// Run just before the process starts (plants links, makes FIFOs).
    setup: Option<Setup>,
    /// Standard output goes here instead of a pipe (`/dev/full`).
    stdout: Option<PathBuf>,
    /// Sent once `when` holds of the case folder (polled every millisecond): the case must then
    /// end by that signal, as a command does whose default action ends it.
    signal: Option<(i32, When)>,
}

/// What a case does to its folder before the run.
type Setup = Box<dyn Fn(&Path)>;

/// When a case's signal is sent: once this holds of the case folder.
type When = fn(&Path) -> bool;

type Check = Box<dyn Fn(&Path) -> Result<String, String>>;

impl Case {
    /// A case with no extra limit, check or file written before.
    fn new(name: &'static str, args: Vec<String>, expect: Expect, gone: Vec<PathBuf>) -> Case {
        Case {
            name,
            args,
            stdin: None,
            expect,
            gone,
            before: vec![],
            ulimit: "",
            check: None,
            release_only: false,
            more: More::default(),
        }
    }

    fn checked(mut self, check: impl Fn(&Path) -> Result<String, String> + 'static) -> Case {
        self.check = Some(Box::new(check));
        self
    }

    fn ulimit(mut self, extra: &'static str) -> Case {
        self.ulimit = extra;
        self
    }

    fn release_only(mut self) -> Case {
        self.release_only = true;
        self
    }
}

fn run_case(case: &Case, dir: &Path) -> Result<String, String> {
    for (path, bytes) in &case.before {
        std::fs::write(path, bytes).map_err(|e| e.to_string())?;
    }
    if let Some(setup) = &case.more.setup {
        setup(dir);
    }
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(if case.ulimit.is_empty() {
            format!("ulimit -v {LIMIT_KIB} && exec \"$@\"")
        } else {
            format!(
                "ulimit -v {LIMIT_KIB} && ulimit {} && exec \"$@\"",
                case.ulimit
            )
        })
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
    let stdout = match &case.more.stdout {
        Some(path) => Stdio::from(
            std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(|e| format!("{}: {e}", path.display()))?,
        ),
        None => Stdio::piped(),
    };
    cmd.current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(stdout)
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().map_err(|e| format!("cannot start: {e}"))?;
    let mut stdin = child.stdin.take().unwrap();
    let input = case.stdin.clone().unwrap_or_default();
    // A writer thread: the child may stop reading early (that is the point of some cases).
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let mut signalled = false;
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if let Some((signal, when)) = case.more.signal {
            if !signalled && when(dir) {
                // SAFETY: kill(2) on our own child's PID, which has not been reaped yet.
                unsafe { libc_kill(child.id() as i32, signal) };
                signalled = true;
            }
            std::thread::sleep(Duration::from_millis(1));
            continue;
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
    if let Expect::Signalled = case.expect {
        use std::os::unix::process::ExitStatusExt as _;
        let want = case.more.signal.map(|(sig, _)| sig);
        if !signalled {
            return Err(format!(
                "the signal was never sent: {status}; stderr: {stderr}"
            ));
        }
        if status.signal() != want {
            return Err(format!(
                "expected the end by signal {want:?}, got {status}; stderr: {stderr}"
            ));
        }
        check_nothing_left(case, dir)?;
        return Ok(format!(
            "{:.2} s: ended by signal {}",
            elapsed.as_secs_f64(),
            want.unwrap_or(0)
        ));
    }
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
    check_nothing_left(case, dir)?;
    let note = match &case.check {
        Some(check) => format!("{note}; {}", check(dir)?),
        None => note,
    };
    Ok(format!("{:.2} s: {note}", elapsed.as_secs_f64()))
}

/// No file the case names in `gone`, and no temporary (`.NAME.tmp-…`), is in `dir`.
fn check_nothing_left(case: &Case, dir: &Path) -> Result<(), String> {
    for f in &case.gone {
        if f.exists() {
            return Err(format!("{} was left behind", f.display()));
        }
    }
    // Regular files only: a link planted at a temporary's name is not the run's.
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    if !leftovers.is_empty() {
        return Err(format!("temporaries left: {leftovers:?}"));
    }
    Ok(())
}

extern "C" {
    #[link_name = "kill"]
    fn libc_kill(pid: i32, signal: i32) -> i32;
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
    });

    // An orbit of a pipe: every frame would read standard input again.
    c.push(Case {
        name: "render --orbit from standard input",
        args: args(&[
            "render",
            "--stream",
            "-",
            "--dims",
            "4,4,4",
            "--type",
            "u8",
            "--window",
            "0,255",
            "--orbit",
            "3",
            "--out",
            "orbit.png",
        ]),
        stdin: Some(vec![7; 64]),
        expect: Expect::Refused("standard input can be read once"),
        gone: vec![dir.join("orbit.png")],
        before: vec![],
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
    });
    c.push(refused(
        "compare --max-diff NaN",
        &["compare", &good, &good, "--max-diff", "NaN"],
        "'NaN' is not finite",
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
        ulimit: "",
        check: None,
        release_only: false,
        more: More::default(),
    });
    c.extend(second_campaign(dir));
    c.extend(third::cases(dir));
    c.extend(cut::cases(dir));
    c.extend(blend::cases(dir));
    c.extend(labels::cases(dir));
    c.extend(grid::cases(dir));
    c
}

#[path = "hostile/blend.rs"]
mod blend;
#[path = "hostile/cut.rs"]
mod cut;
#[path = "hostile/grid.rs"]
mod grid;
#[path = "hostile/labels.rs"]
mod labels;
#[path = "hostile/third.rs"]
mod third;

/// `n` bytes of xorshift64 noise from `seed` (the same bytes every run).
fn noise(n: usize, mut seed: u64) -> Vec<u8> {
    (0..n)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 56) as u8
        })
        .collect()
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

/// The heart volume shipped with the tests (32×32×12 f32, detached raw data).
const HEART: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.nhdr"
);
const HEART_RAW: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.raw"
);

/// A PNG the case left in `dir`: width, height, premultiplied RGBA.
fn png(dir: &Path, name: &str) -> Result<(usize, usize, Vec<[f32; 4]>), String> {
    let bytes = std::fs::read(dir.join(name)).map_err(|e| format!("{name}: {e}"))?;
    footprint_harness::io::image::decode_png_rgba(&bytes, name).map_err(|e| e.to_string())
}

/// A check that `name` is an image with something on it (mean opacity at least 1 %).
fn not_black(name: &'static str) -> impl Fn(&Path) -> Result<String, String> {
    move |dir| {
        let (_, _, px) = png(dir, name)?;
        let mean = px.iter().map(|p| f64::from(p[3])).sum::<f64>() / px.len().max(1) as f64;
        if mean >= 0.01 {
            Ok(format!("{name}: mean opacity {mean:.3}"))
        } else {
            Err(format!("{name} is black (mean opacity {mean:.5})"))
        }
    }
}

/// A check that images `a` and `b` differ by at most `levels` of 255 in any channel.
fn same_image(
    a: &'static str,
    b: &'static str,
    levels: f32,
) -> impl Fn(&Path) -> Result<String, String> {
    move |dir| {
        let ((wa, ha, pa), (wb, hb, pb)) = (png(dir, a)?, png(dir, b)?);
        if (wa, ha) != (wb, hb) {
            return Err(format!("{a} is {wa}x{ha}, {b} {wb}x{hb}"));
        }
        let worst = pa
            .iter()
            .zip(&pb)
            .flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs()))
            .fold(0.0f32, f32::max);
        if worst * 255.0 <= levels {
            Ok(format!("{a} and {b} within {:.1} levels", worst * 255.0))
        } else {
            Err(format!("{a} and {b} differ by {:.1} levels", worst * 255.0))
        }
    }
}

/// A check that `path` still holds `bytes`.
fn untouched(path: PathBuf, bytes: Vec<u8>) -> impl Fn(&Path) -> Result<String, String> {
    move |_| match std::fs::read(&path) {
        Ok(b) if b == bytes => Ok(format!("{} untouched", path.display())),
        _ => Err(format!("{} was changed", path.display())),
    }
}

/// A NIfTI-1 (`.nii`) of an 8³ u8 volume with an asymmetric bright block, oriented by a qform
/// quaternion (b, c, d) written as given.
fn nifti_quaternion(b: f32, c: f32, d: f32) -> Vec<u8> {
    let mut h = nifti_header(352.0);
    h[252..254].copy_from_slice(&1i16.to_le_bytes());
    for (k, q) in [b, c, d].iter().enumerate() {
        h[256 + 4 * k..260 + 4 * k].copy_from_slice(&q.to_le_bytes());
    }
    for k in 0..8 {
        for j in 0..8 {
            for i in 0..8 {
                h.push(if i < 3 && j < 6 {
                    250
                } else {
                    (i + j + k) as u8 * 4
                });
            }
        }
    }
    h
}

/// The second hostile-input campaign (issue 43): each class's reproducers and the neighbours
/// found beside them.
fn second_campaign(dir: &Path) -> Vec<Case> {
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(dir.join(name), bytes).unwrap();
        name.to_string()
    };
    let out = || vec![dir.join("out.png"), dir.join("out.json")];
    let renders = |name, a: &[&str]| Case::new(name, args(a), Expect::Renders, vec![]);
    let refused = |name, a: &[&str], want| Case::new(name, args(a), Expect::Refused(want), out());
    let mut c = Vec::new();

    // Sizes a user controls: checked, bounded, allocated fallibly.
    c.push(refused(
        "bench --frames 1e11",
        &["bench", HEART, "--size", "8x8", "--frames", "100000000000"],
        "at most 100000 frames",
    ));
    c.push(refused(
        "bench --frames 2^64-1",
        &[
            "bench",
            HEART,
            "--size",
            "8x8",
            "--frames",
            "18446744073709551615",
        ],
        "at most 100000 frames",
    ));
    for accum in ["float", "fixed"] {
        c.push(renders(
            "--phases 2^64-1 (stencils cannot hold it: the table walk serves)",
            &[
                "render",
                HEART,
                "--phases",
                "18446744073709551615",
                "--accum",
                accum,
                "--size",
                "64x64",
                "--out",
                "phases.png",
            ],
        ));
    }
    c.push(
        renders(
            "--threads 2000 at 2048x2048 (threads the system refuses run on the caller's)",
            &[
                "render",
                HEART,
                "--threads",
                "2000",
                "--size",
                "2048x2048",
                "--out",
                "threads.png",
            ],
        )
        .checked(not_black("threads.png")),
    );
    c.push(
        refused(
            "--scene-size 512 under 384 MiB",
            &[
                "render",
                "--scene-size",
                "512",
                "--size",
                "64x64",
                "--out",
                "out.png",
            ],
            "cannot allocate",
        )
        .ulimit("-v 393216"),
    );
    // A 32768² slice (1 GiB, sparse) streamed without --window: the range pass reads chunks.
    std::fs::File::create(dir.join("slice.raw"))
        .unwrap()
        .set_len(1 << 30)
        .unwrap();
    c.push(refused(
        "--stream of a 32768x32768 slice without --window",
        &[
            "render",
            "--stream",
            "slice.raw",
            "--dims",
            "32768,32768,1",
            "--type",
            "u8",
            "--out",
            "out.png",
        ],
        "the data are constant",
    ));
    // 600³ u8 (216 MB) with Phong: the visible lists stay within their budget, past it the
    // bands classify as they go.
    let big = noise(600 * 600 * 600, 0x2545_f491_4f6c_dd1d);
    write("v600.raw", &big);
    drop(big);
    for (name, lod) in [
        ("600³ u8, --shading phong --lod 0 under 4 GiB", "0"),
        (
            "600³ u8, --shading phong (default level) under 4 GiB",
            "auto",
        ),
    ] {
        c.push(
            renders(
                name,
                &[
                    "render",
                    "v600.raw",
                    "--dims",
                    "600,600,600",
                    "--type",
                    "u8",
                    "--shading",
                    "phong",
                    "--lod",
                    lod,
                    "--out",
                    "v600.png",
                ],
            )
            .checked(not_black("v600.png"))
            .release_only(),
        );
    }

    // Memory that follows the header: a VTI whose LZ4 block declares 1.7 GB from 16 bytes.
    c.push(refused(
        "VTI with an LZ4 block declaring 1.7 GB",
        &[
            "render",
            &write("lz4.vti", &lz4_vti_bomb()),
            "--out",
            "out.png",
        ],
        "cannot decode",
    ));

    // Silently wrong images: windows and data whose range overflows f32.
    c.push(
        renders(
            "--window=-3.4e38,3.4e38",
            &[
                "render",
                HEART,
                "--window=-3.4e38,3.4e38",
                "--size",
                "64x64",
                "--out",
                "w1.png",
            ],
        )
        .checked(not_black("w1.png")),
    );
    c.push(
        renders(
            "--window 0,1e-45",
            &[
                "render", HEART, "--window", "0,1e-45", "--size", "64x64", "--out", "w2.png",
            ],
        )
        .checked(not_black("w2.png")),
    );
    let wide: Vec<u8> = (0..16 * 16 * 16)
        .flat_map(|n: i32| {
            let (i, j, k) = (n % 16 - 8, n / 16 % 16 - 8, n / 256 - 8);
            let v = if i * i + j * j + k * k < 25 {
                3.4e38f32
            } else {
                -3.4e38
            };
            v.to_le_bytes()
        })
        .collect();
    let wide = write("wide.raw", &wide);
    c.push(
        renders(
            "f32 data spanning +-3.4e38, default window",
            &[
                "render", &wide, "--dims", "16,16,16", "--type", "f32", "--size", "64x64", "--out",
                "w3.png",
            ],
        )
        .checked(not_black("w3.png")),
    );
    let preset = write(
        "wide.json",
        br#"[{"Name": "wide", "ColorSpace": "RGB", "RGBPoints": [-1e308, 0, 0, 0, 1e308, 1, 1, 1], "Points": [-1e308, 0, 0.5, 0, 1e308, 1, 0.5, 0]}]"#,
    );
    c.push(
        renders(
            "ParaView points spanning +-1e308",
            &[
                "render", HEART, "--tf", &preset, "--size", "64x64", "--out", "w4.png",
            ],
        )
        .checked(not_black("w4.png")),
    );
    let mut mha = b"ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\nElementNumberOfChannels = 3\nElementDataFile = LOCAL\n".to_vec();
    mha.extend([7u8; 192]);
    // Three components are read (docs/components.md), each through the transfer function over
    // its own window: constant data have none.
    c.push(refused(
        "MetaImage with ElementNumberOfChannels = 3, constant data",
        &["render", &write("rgb.mha", &mha), "--out", "out.png"],
        "component 0: the data are constant (7); give --window",
    ));
    // An NRRD whose header holds a 100 KiB comment before its fields: streamed equals loaded
    // (with `--slicing object --lod 0`, which leave a pilot nothing to choose, so the stream is
    // read three sheets at a time rather than held: `pipeline::stages::hold`).
    let comment = format!("# {}\n", "x".repeat(100 << 10));
    let long = format!(
        "NRRD0004\n{comment}type: float\ndimension: 3\nsizes: 32 32 12\nendian: little\nencoding: raw\ndata file: {HEART_RAW}\n"
    );
    let long = write("long.nhdr", long.as_bytes());
    c.push(renders(
        "NRRD with a 100 KiB header comment, loaded",
        &[
            "render",
            &long,
            "--slicing",
            "object",
            "--lod",
            "0",
            "--size",
            "64x64",
            "--out",
            "long-loaded.png",
        ],
    ));
    c.push(
        renders(
            "NRRD with a 100 KiB header comment, streamed",
            &[
                "render",
                "--stream",
                &long,
                "--slicing",
                "object",
                "--lod",
                "0",
                "--size",
                "64x64",
                "--out",
                "long-streamed.png",
            ],
        )
        .checked(same_image("long-loaded.png", "long-streamed.png", 0.0)),
    );
    // NIfTI qform: a quaternion written past unit length orients as nifti1_io's does. With
    // a = 0, an unnormalised (b, c, d) of length l scales the rotation by l² (uniformly, so a
    // view fitted to the volume would hide it): an explicit world-to-screen matrix shows it.
    let third = (1.0f32 / 3.0).sqrt();
    let unit = write("q-unit.nii", &nifti_quaternion(third, third, third));
    let over = write("q-over.nii", &nifti_quaternion(0.6, 0.6, 0.6));
    let view = [
        "--size",
        "64x64",
        "--window",
        "0,255",
        "--view-matrix",
        "3.5,0.9,0,-0.9,3.5,0.6,0.2,-0.6,3.6",
    ];
    let mut a = vec!["render", &unit, "--out", "q-unit.png"];
    a.extend(view);
    c.push(renders("NIfTI qform, unit quaternion", &a));
    let mut a = vec!["render", &over, "--out", "q-over.png"];
    a.extend(view);
    c.push(
        renders("NIfTI qform, quaternion of length 1.04 (normalised)", &a).checked(same_image(
            "q-unit.png",
            "q-over.png",
            1.0,
        )),
    );
    c.push(refused(
        "VTI WholeExtent near the ends of i64",
        &[
            "render",
            &write(
                "extent.vti",
                b"<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"-9223372036854775807 9223372036854775807 0 0 0 1\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 1 0 0 0 1\"><PointData Scalars=\"s\"><DataArray type=\"UInt8\" Name=\"s\" format=\"ascii\">1 2 3 4</DataArray></PointData></Piece></ImageData></VTKFile>\n",
            ),
            "--out",
            "out.png",
        ],
        "WholeExtent",
    ));
    // A spacing of 1e38 is the file's fault, not the flags'.
    let nhdr = write(
        "spacing.nhdr",
        format!(
            "NRRD0004\ntype: float\ndimension: 3\nsizes: 32 32 12\nspacings: 1e38 1 1\nendian: little\nencoding: raw\ndata file: {HEART_RAW}\n"
        )
        .as_bytes(),
    );
    c.push(refused(
        "NRRD spacing 1e38",
        &["render", &nhdr, "--out", "out.png"],
        "spacing",
    ));

    // Outputs: devices and pipes first, no output naming an input, any name, any file limit.
    c.push(refused(
        "--json /dev/full",
        &[
            "render",
            HEART,
            "--size",
            "32x32",
            "--out",
            "out.png",
            "--json",
            "/dev/full",
        ],
        "/dev/full",
    ));
    c.push(refused(
        "--out, a symbolic link to /dev/full",
        &[
            "render", HEART, "--size", "32x32", "--out", "full.png", "--json", "out.json",
        ],
        "full.png",
    ));
    let _ = std::os::unix::fs::symlink("/dev/full", dir.join("full.png"));
    // The shipped header names its data file beside it: both copied into the case folder.
    let mine_header = std::fs::read(HEART).unwrap();
    let mine = write("mine.nhdr", &mine_header);
    std::fs::copy(HEART_RAW, dir.join("heart_32x32x12_float32_le.raw")).unwrap();
    let raw = std::fs::read(HEART_RAW).unwrap();
    c.push(
        refused(
            "--json naming the volume",
            &[
                "render", &mine, "--size", "32x32", "--out", "out.png", "--json", &mine,
            ],
            "is an input",
        )
        .checked(untouched(dir.join("mine.nhdr"), mine_header.clone())),
    );
    c.push(
        refused(
            "--json naming the volume's detached data file",
            &[
                "render",
                &mine,
                "--size",
                "32x32",
                "--out",
                "out.png",
                "--json",
                "heart_32x32x12_float32_le.raw",
            ],
            "this command read",
        )
        .checked(untouched(dir.join("heart_32x32x12_float32_le.raw"), raw)),
    );
    let _ = std::os::unix::fs::symlink("mine.nhdr", dir.join("alias.json"));
    c.push(
        refused(
            "--json naming the volume through a symbolic link",
            &[
                "render",
                &mine,
                "--size",
                "32x32",
                "--out",
                "out.png",
                "--json",
                "alias.json",
            ],
            "is an input",
        )
        .checked(untouched(dir.join("mine.nhdr"), mine_header)),
    );
    let long_name: &'static str = Box::leak(format!("{}.png", "n".repeat(251)).into_boxed_str());
    c.push(
        renders(
            "an output name of 255 bytes",
            &["render", HEART, "--size", "32x32", "--out", long_name],
        )
        .checked(move |dir| {
            std::fs::remove_file(dir.join(long_name))
                .map(|()| "written".to_string())
                .map_err(|e| format!("not written: {e}"))
        }),
    );
    // The command line's own messages (issue 48): suggestions kept, negative numbers named,
    // `compare` reads the colour PFM `render` writes and refuses two of a different kind.
    c.push(refused(
        "a misspelt subcommand",
        &["rendr"],
        "a similar subcommand exists: 'render'",
    ));
    c.push(refused(
        "a misspelt flag",
        &["render", "--sise", "8x8"],
        "a similar argument exists: '--size'",
    ));
    c.push(refused(
        "--threads -2",
        &["render", "--threads", "-2", "--out", "out.png"],
        "is not a whole number of threads >= 0",
    ));
    c.push(renders(
        "render a colour PFM",
        &["render", HEART, "--size", "24x16", "--out", "colour.pfm"],
    ));
    c.push(renders(
        "compare reads render's colour PFM",
        &["compare", "colour.pfm", "colour.pfm", "--max-diff", "0"],
    ));
    c.push(renders(
        "a greyscale PFM",
        &["splat", "--size", "24x16", "--out", "grey.pfm"],
    ));
    c.push(refused(
        "compare a greyscale PFM with a colour one",
        &["compare", "grey.pfm", "colour.pfm"],
        "compare two of a kind",
    ));
    c.push(renders("bare footprint prints the help", &[]));
    c.push(
        renders(
            "footprint info with --json",
            &["info", HEART, "--json", "info.json"],
        )
        .checked(|dir| {
            let j = std::fs::read_to_string(dir.join("info.json")).map_err(|e| e.to_string())?;
            for key in [
                "\"dims\"",
                "\"type\": \"float32\"",
                "\"percentiles\"",
                "\"window\"",
            ] {
                if !j.contains(key) {
                    return Err(format!("info.json lacks {key}"));
                }
            }
            Ok("info.json has dims, type, percentiles, window".into())
        }),
    );
    c.push(refused(
        "footprint info without a volume",
        &["info"],
        "needs a VOLUME",
    ));
    c.push(
        refused(
            "ulimit -f 16 (a write past the file-size limit)",
            &["render", HEART, "--out", "out.png"],
            "File too large",
        )
        .ulimit("-f 16"),
    );
    c
}

/// A VTI whose one LZ4 block (16 bytes) declares 1 728 000 000 bytes, as its 1200³ u8 extent
/// needs.
fn lz4_vti_bomb() -> Vec<u8> {
    use base64::Engine as _;
    let need = 1200u32 * 1200 * 1200;
    let block = [
        0x1fu8, 0, 1, 0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0, 0, 0, 0,
    ];
    let mut head = Vec::new();
    for v in [1u32, need, need, block.len() as u32] {
        head.extend(v.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD;
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\" compressor=\"vtkLZ4DataCompressor\">\n<ImageData WholeExtent=\"0 1199 0 1199 0 1199\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 1199 0 1199 0 1199\"><PointData Scalars=\"s\"><DataArray type=\"UInt8\" Name=\"s\" format=\"binary\">{}{}</DataArray></PointData></Piece></ImageData></VTKFile>\n",
        b64.encode(&head),
        b64.encode(block)
    )
    .into_bytes()
}
