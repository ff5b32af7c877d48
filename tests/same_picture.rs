//! Same evidence, same plan (issue 76): one volume renders the same picture, byte for byte, by
//! whatever carries it — a file, `--stream FILE`, standard input, an array in memory (what the
//! Python package's `render` passes) and a program's pipe (what its `render_stream` passes a
//! generator through) — with default flags, on a shared anisotropic volume (headsq, spacing
//! 3.2 : 3.2 : 1.5), at 128² and 512². A stream the default plan's pilot needs is held in memory
//! (`pipeline::stages::hold`, called by the pipeline's entry); flags that leave nothing to choose
//! keep it a stream.

use footprint_harness::args::parse_args;
use footprint_harness::io::formats::load_array;
use footprint_harness::io::stream::{InMemory, Pipe};
use footprint_suite::{path_str as s, tmpdir};
use std::io::Write;
use std::process::{Command, Stdio};
use std::sync::Arc;

const NHDR: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.nhdr"
);
const RAW: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.raw"
);
const RAW_FLAGS: [&str; 6] = [
    "--dims",
    "64,64,93",
    "--type",
    "i16",
    "--spacing",
    "3.2,3.2,1.5",
];
const SEP: char = '\u{1f}';

/// Not a test of its own: the child process that renders standard input.
#[test]
fn child() {
    if let Ok(args) = std::env::var("FOOTPRINT_SAME_PICTURE_CHILD") {
        let args = std::iter::once("footprint").chain(args.split(SEP));
        std::process::exit(footprint_harness::run(args));
    }
}

/// `footprint render` of `source` with `flags` and `--size size`: the PNG's bytes and the JSON.
fn cli(source: &[&str], flags: &[&str], size: &str, stdin: Option<&[u8]>) -> (Vec<u8>, String) {
    let d = tmpdir("same-picture");
    let (out, json) = (d.join("o.png"), d.join("o.json"));
    let mut a = vec!["render"];
    a.extend_from_slice(source);
    a.extend_from_slice(flags);
    a.extend_from_slice(&["--size", size, "--out", s(&out), "--json", s(&json)]);
    match stdin {
        None => {
            let mut v = vec!["footprint"];
            v.extend_from_slice(&a);
            assert_eq!(footprint_harness::run(v), 0, "{a:?}");
        }
        Some(bytes) => {
            let mut child = Command::new(std::env::current_exe().unwrap())
                .args(["same_picture::child", "--exact", "--test-threads=1"])
                .env("FOOTPRINT_SAME_PICTURE_CHILD", a.join(&SEP.to_string()))
                .stdin(Stdio::piped())
                .stdout(Stdio::null())
                .spawn()
                .unwrap();
            child.stdin.take().unwrap().write_all(bytes).unwrap();
            assert!(child.wait().unwrap().success(), "{a:?}");
        }
    }
    let got = (
        std::fs::read(&out).unwrap(),
        std::fs::read_to_string(&json).unwrap(),
    );
    std::fs::remove_dir_all(&d).unwrap();
    got
}

/// What the Python package does: the flags parsed, the volume in memory or a program's pipe set,
/// the frame rendered (premultiplied RGBA, f32; the pipeline's entry holds the stream).
fn library(flags: &[&str], size: &str, memory: Option<InMemory>, pipe: Option<Pipe>) -> Vec<f32> {
    let mut all = flags.to_vec();
    all.extend_from_slice(&["--size", size]);
    let mut args = parse_args(&all).unwrap();
    args.memory = memory;
    args.stdin = pipe;
    let asked = footprint_harness::args::plan(&args).unwrap();
    let inputs = footprint_harness::args::scene(&args).unwrap();
    let (image, _, _) =
        footprint_harness::commands::render::single(&args, &inputs, &asked).unwrap();
    image.into_iter().flatten().collect()
}

#[test]
fn every_carrier_of_a_volume_renders_the_files_picture() {
    let bytes = std::fs::read(RAW).unwrap();
    let volume = Arc::new(load_array(std::path::Path::new(NHDR), None, None).unwrap());
    let stdin = [&["--stream", "-"][..], &RAW_FLAGS].concat();
    for size in ["128x128", "512x512"] {
        for window in [&[][..], &["--window", "600,2400"]] {
            let flags = [&["--view", "30,20,0"][..], window].concat();
            let (file, json) = cli(&[NHDR], &flags, size, None);
            // The default plan measured its choice: not the stream's old object slicing.
            assert!(json.contains("\"quality\""), "{size} {window:?}: {json}");
            let stream = cli(&["--stream", NHDR], &flags, size, None).0;
            assert!(stream == file, "{size} {window:?}: --stream FILE differs");
            let raw = [&["--stream", RAW][..], &RAW_FLAGS].concat();
            assert!(
                cli(&raw, &flags, size, None).0 == file,
                "{size}: raw stream"
            );
            let piped = cli(&stdin, &flags, size, Some(&bytes)).0;
            assert!(piped == file, "{size} {window:?}: standard input differs");
            // The library's carriers against the library's own render of the file.
            let of_file = library(&[&[NHDR][..], &flags].concat(), size, None, None);
            let memory = InMemory {
                volume: Arc::clone(&volume),
                name: "array".into(),
            };
            let array = library(&flags, size, Some(memory), None);
            assert!(array == of_file, "{size} {window:?}: array differs");
            let pipe = Pipe::new(std::io::Cursor::new(bytes.clone()));
            let generator = library(&[&stdin[..], &flags].concat(), size, None, Some(pipe));
            assert!(generator == of_file, "{size} {window:?}: pipe differs");
        }
    }
}

/// Flags that leave the pilot nothing to choose keep a stream a stream (three sheets, not the
/// volume): no note that it was held, object slicing, and the loaded file's picture with the same
/// flags.
#[test]
fn a_stream_with_nothing_to_choose_stays_a_stream() {
    let flags = ["--view", "30,20,0", "--slicing", "object", "--lod", "0"];
    let file = cli(&[NHDR], &flags, "128x128", None).0;
    let (stream, json) = cli(&["--stream", NHDR], &flags, "128x128", None);
    assert!(stream == file);
    assert!(!json.contains("\"quality\""), "{json}");
    let args = parse_args(&[&["--stream", NHDR][..], &flags].concat()).unwrap();
    let inputs = footprint_harness::args::scene(&args).unwrap();
    let plan = footprint_harness::args::plan(&args).unwrap();
    assert!(
        footprint_harness::pipeline::stages::hold::held(&inputs, &plan)
            .unwrap()
            .is_none()
    );
    assert!(footprint_harness::pipeline::prepare(&args)
        .unwrap()
        .volume()
        .is_none());
}
