//! The command's outputs: checked before any rendering, written all together or not at all, and
//! only in the format their extension names; messages that name the flag or the cause.

use footprint_harness::io::outputs::{self, Planned};
use footprint_harness::pipeline::stages::prepare::outside_data_warnings;
use footprint_harness::scene::ShadingSpec;
use std::path::Path;

fn tmpdir(name: &str) -> footprint_suite::TestDir {
    footprint_suite::tmpdir(&format!("out-{name}"))
}

use footprint_suite::run_cli as run;

/// Files in `d` (temporaries included).
fn listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_failed_output_means_no_outputs() {
    let d = tmpdir("none");
    let png = d.join("x.png");
    let p = png.to_str().unwrap();
    // The case: a JSON path that cannot be written leaves no image.
    for args in [
        vec![
            "render",
            "--size",
            "32x32",
            "--json",
            "/nonexistent/x.json",
            "--out",
            p,
        ],
        vec![
            "verify",
            "--size",
            "32x32",
            "--json",
            "/nonexistent/x.json",
            "--out",
            p,
        ],
        vec![
            "bench",
            "--size",
            "32x32",
            "--frames",
            "1",
            "--json",
            "/nonexistent/x.json",
            "--out",
            p,
        ],
        vec![
            "render",
            "--size",
            "32x32",
            "--out",
            "/nonexistent/dir/x.png",
        ],
        vec!["render", "--size", "32x32", "--out", p, "--json", p],
        vec!["render", "--size", "32x32", "--out", d.to_str().unwrap()],
        vec!["splat", "--out", "/nonexistent/dir/x.pfm"],
        vec!["tables", "--size", "9", "--out", "/nonexistent/dir/t.bin"],
    ] {
        assert_eq!(run(&args), 2, "{args:?}");
        assert!(listing(&d).is_empty(), "{args:?} left {:?}", listing(&d));
    }
    // The writer itself: the second file cannot be written, so the first is not either, and no
    // temporary stays behind.
    let good = d.join("a.json");
    let err = outputs::write_all(&[
        (good.as_path(), b"{}"),
        (Path::new("/nonexistent/dir/b.json"), b"{}"),
    ])
    .unwrap_err();
    assert!(err.message.contains("no output written"), "{}", err.message);
    assert!(listing(&d).is_empty(), "left {:?}", listing(&d));
    // Both written when both can be.
    let other = d.join("b.json");
    outputs::write_all(&[(good.as_path(), b"1"), (other.as_path(), b"2")]).unwrap();
    assert_eq!(listing(&d), ["a.json", "b.json"]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn an_extension_is_written_in_its_format_or_refused() {
    let d = tmpdir("ext");
    let jpg = d.join("x.jpg");
    assert_eq!(
        run(&["render", "--size", "16x16", "--out", jpg.to_str().unwrap()]),
        2
    );
    assert!(!jpg.exists(), "PNG bytes in a .jpg");
    let err = outputs::check(&[Planned {
        flag: "--out",
        path: &jpg,
        extensions: &["png", "pfm"],
    }])
    .unwrap_err();
    assert!(
        err.message.contains("--out") && err.message.contains(".jpg"),
        "{}",
        err.message
    );
    // .png is a PNG, .pfm a colour PFM of the same pixels (float, unclamped).
    let (png, pfm) = (d.join("x.png"), d.join("x.pfm"));
    for out in [&png, &pfm] {
        assert_eq!(
            run(&["render", "--size", "16x12", "--out", out.to_str().unwrap()]),
            0
        );
    }
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    let bytes = std::fs::read(&pfm).unwrap();
    assert!(bytes.starts_with(b"PF\n16 12\n-1.0\n"));
    assert_eq!(bytes.len(), "PF\n16 12\n-1.0\n".len() + 16 * 12 * 12);
    // Upper-case extensions are the same formats.
    let upper = d.join("y.PNG");
    assert_eq!(
        run(&["render", "--size", "8x8", "--out", upper.to_str().unwrap()]),
        0
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn messages_name_the_flag_or_the_cause() {
    let d = tmpdir("msg");
    // Values that clap used to take for unknown flags reach their parsers (exit 2, no output).
    let out = d.join("x.png");
    let o = out.to_str().unwrap();
    for bad in [
        vec!["--zoom", "0"],
        vec!["--zoom", "-1"],
        vec!["--min-radius", "-1"],
        vec!["--spacing", "-1,1,1"],
        vec!["--dims", "-64,64,64", "--type", "u8"],
    ] {
        let mut args = vec!["render", "--size", "16x16", "--out", o];
        args.extend(bad.iter().copied());
        assert_eq!(run(&args), 2, "{bad:?}");
        assert!(!out.exists());
    }
    let parsed = footprint_harness::args::parse_args(&["--zoom", "0"]).unwrap_err();
    assert!(parsed.message.contains("--zoom"), "{}", parsed.message);
    let parsed = footprint_harness::args::parse_args(&["--spacing", "-1,1,1"]).unwrap_err();
    assert!(parsed.message.contains("--spacing"), "{}", parsed.message);
    // A header format with the raw-file flags.
    let nhdr = d.join("v.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: v.raw\n",
    )
    .unwrap();
    std::fs::write(d.join("v.raw"), [0u8, 9, 9, 9, 9, 9, 9, 9]).unwrap();
    let args = footprint_harness::args::parse_args(&[
        nhdr.to_str().unwrap(),
        "--dims",
        "2,2,2",
        "--type",
        "u8",
    ])
    .unwrap();
    let msg = match footprint_harness::pipeline::prepare(&args) {
        Err(e) => e.message,
        Ok(_) => panic!("--dims with an .nhdr was accepted"),
    };
    assert!(
        msg.contains("headerless raw") && msg.contains("NRRD"),
        "{msg}"
    );
    // A directory as the volume.
    let args = footprint_harness::args::parse_args(&[d.to_str().unwrap()]).unwrap();
    let msg = match footprint_harness::pipeline::prepare(&args) {
        Err(e) => e.message,
        Ok(_) => panic!("a directory was accepted"),
    };
    assert!(msg.contains("is a directory"), "{msg}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn values_outside_the_data_are_warned_about() {
    let iso = |v: f32| {
        ShadingSpec::parse(&format!("iso:{v}"))
            .unwrap()
            .at_spacing(1.0)
    };
    let range = (0.0f32, 255.0f32);
    let w = outside_data_warnings(&iso(99999.0), None, range);
    assert_eq!(w.len(), 1);
    assert!(w[0].contains("99999") && w[0].contains("outside"), "{w:?}");
    assert!(outside_data_warnings(&iso(100.0), None, range).is_empty());
    let emission = ShadingSpec::parse("emission").unwrap().at_spacing(1.0);
    assert_eq!(
        outside_data_warnings(&emission, Some([300.0, 400.0]), range).len(),
        1
    );
    // A window wider than the data, or overlapping it, is legitimate.
    assert!(outside_data_warnings(&emission, Some([-100.0, 1000.0]), range).is_empty());
    assert!(outside_data_warnings(&emission, Some([200.0, 400.0]), range).is_empty());
}

/// What a SIGKILL between a temporary's creation and its rename leaves (`.NAME.tmp-PID` of a dead
/// process) is removed by the next run that writes NAME; a live process's temporary is kept.
#[test]
fn leftovers_of_killed_runs_are_removed() {
    let d = tmpdir("leftovers");
    let out = d.join("x.png");
    // PID 1 always runs; 4194304 is above Linux's largest PID.
    let dead = d.join(".x.png.tmp-4194304");
    let live = d.join(".x.png.tmp-1");
    let other = d.join(".y.png.tmp-4194304");
    for f in [&dead, &live, &other] {
        std::fs::write(f, b"partial").unwrap();
    }
    assert_eq!(
        run(&["render", "--size", "8x8", "--out", out.to_str().unwrap()]),
        0
    );
    assert!(out.exists());
    if std::path::Path::new("/proc/self").exists() {
        assert!(!dead.exists(), "a dead run's temporary stayed");
        assert!(live.exists(), "a live process's temporary was removed");
    }
    assert!(other.exists(), "another output's temporary was touched");
    std::fs::remove_dir_all(&d).unwrap();
}

/// A colour PFM's premultiplied RGB (rows top first).
fn read_pfm_rgb(path: &Path) -> Vec<[f32; 3]> {
    let bytes = std::fs::read(path).unwrap();
    let mut lines = 0;
    let mut at = 0;
    while lines < 3 {
        if bytes[at] == b'\n' {
            lines += 1;
        }
        at += 1;
    }
    let head = std::str::from_utf8(&bytes[..at]).unwrap();
    let dims: Vec<usize> = head
        .lines()
        .nth(1)
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    let px: Vec<[f32; 3]> = bytes[at..]
        .chunks_exact(12)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            [f(0), f(4), f(8)]
        })
        .collect();
    // PFM stores rows bottom to top.
    px.chunks(dims[0]).rev().flatten().copied().collect()
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// `--background transparent`, `--gamma srgb` and `--depth 16` write the same float render, each
/// within its format's rounding: checked against the `.pfm` of the same render (exact floats).
#[test]
fn png_options_encode_the_float_render() {
    let d = tmpdir("png-options");
    let path = |n: &str| d.join(n).to_str().unwrap().to_string();
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "render", "--size", "40x40", "--view", "30,20,0", "--out", out,
        ];
        args.extend_from_slice(extra);
        assert_eq!(run(&args), 0, "{args:?}");
        let bytes = std::fs::read(out).unwrap();
        (
            bytes.clone(),
            footprint_harness::io::image::decode_png_rgba(&bytes, out)
                .unwrap()
                .2,
        )
    };
    assert_eq!(
        run(&[
            "render",
            "--size",
            "40x40",
            "--view",
            "30,20,0",
            "--out",
            &path("f.pfm")
        ]),
        0
    );
    let exact = read_pfm_rgb(&d.join("f.pfm"));
    let clamp = |v: f32| v.clamp(0.0, 1.0);
    let worst = |png: &[[f32; 4]], linear: &dyn Fn(f32, f32) -> f32| -> f32 {
        png.iter()
            .zip(&exact)
            .flat_map(|(p, e)| (0..3).map(move |c| (linear(p[c], p[3]) - clamp(e[c])).abs()))
            .fold(0.0, f32::max)
    };
    // Plain 8-bit RGB: half a level.
    let (plain, px) = render(&path("plain.png"), &[]);
    assert!(worst(&px, &|v, _| v) <= 0.5 / 255.0 + 1e-6);
    // 16-bit RGB: half a 16-bit level.
    let (wide, px) = render(&path("wide.png"), &["--depth", "16"]);
    assert!(worst(&px, &|v, _| v) <= 0.5 / 65535.0 + 1e-6);
    assert_eq!(wide[24], 16, "bit depth byte of IHDR");
    // sRGB, 16-bit: the curve undone gives the linear values back; the file says it is sRGB.
    let (srgb, px) = render(&path("srgb.png"), &["--gamma", "srgb", "--depth", "16"]);
    assert!(
        worst(&px, &|v, _| srgb_to_linear(v)) <= 2e-5,
        "{}",
        worst(&px, &|v, _| srgb_to_linear(v))
    );
    assert!(srgb.windows(4).any(|w| w == b"sRGB") && !plain.windows(4).any(|w| w == b"sRGB"));
    // Transparent: RGBA (colour type 6) with straight alpha; premultiplied again (as the decoder
    // does) it is the black-background render, within the rounding of both channels.
    let (clear, px) = render(&path("clear.png"), &["--background", "transparent"]);
    assert_eq!(clear[25], 6, "colour type byte of IHDR");
    assert!(worst(&px, &|v, _| v) <= 1.0 / 255.0 + 1e-6);
    let alphas: Vec<f32> = px.iter().map(|p| p[3]).collect();
    assert_eq!(alphas[0], 0.0, "the corner is uncovered");
    assert!(
        alphas.iter().any(|&a| a > 0.0 && a < 1.0),
        "coverage is partial somewhere"
    );
    // Straight alpha: a covered pixel's stored colour is its premultiplied colour over alpha.
    let dim = px
        .iter()
        .zip(&exact)
        .find(|(p, _)| p[3] > 0.2 && p[3] < 0.8)
        .expect("a half-covered pixel");
    let straight = dim.1[0] / dim.0[3];
    assert!(
        (dim.0[0] / dim.0[3] - straight).abs() < 3.0 / 255.0,
        "{dim:?}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// Under `--gamma srgb`, a background PNG is read as sRGB: where the volume does not reach, the
/// output's pixels are the background's, unchanged (8 and 16 bits).
#[test]
fn an_srgb_background_comes_back_unchanged() {
    let d = tmpdir("srgb-background");
    let bg = d.join("bg.png");
    let out = d.join("o.png");
    // A horizontal ramp, opaque.
    let ramp: Vec<[f32; 4]> = (0..32 * 32)
        .map(|i| {
            let v = (i % 32) as f32 / 31.0;
            [v, 0.5 * v, 1.0 - v, 1.0]
        })
        .collect();
    std::fs::write(
        &bg,
        footprint_harness::io::image::encode_png_rgb(&ramp, 32, 32).unwrap(),
    )
    .unwrap();
    let (b, o) = (bg.to_str().unwrap(), out.to_str().unwrap());
    assert_eq!(
        run(&[
            "render",
            "--size",
            "32x32",
            "--zoom",
            "0.3",
            "--background",
            b,
            "--gamma",
            "srgb",
            "--out",
            o
        ]),
        0
    );
    let read = |p: &Path| {
        footprint_harness::io::image::decode_png_rgba(&std::fs::read(p).unwrap(), "x")
            .unwrap()
            .2
    };
    let (before, after) = (read(&bg), read(&out));
    // Row 0 is outside a volume zoomed to 0.3 of the fit.
    assert_eq!(&before[..32], &after[..32]);
    assert_ne!(before, after, "the volume shows in the middle");
    std::fs::remove_dir_all(&d).unwrap();
}

/// An output naming a device or a FIFO is written into it, never replaced by a regular file (a
/// rename over `--json /dev/null`, as root, once turned this machine's `/dev/null` into a file).
#[cfg(unix)]
#[test]
fn devices_and_fifos_are_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    assert!(outputs::is_special(Path::new("/dev/null")));
    let d = tmpdir("fifo");
    let fifo = d.join("summary.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable: skipped");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(&fifo).unwrap())
    };
    let png = d.join("x.png");
    let code = run(&[
        "render",
        "--size",
        "16x16",
        "--out",
        png.to_str().unwrap(),
        "--json",
        fifo.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    // Checked before joining: a replaced FIFO would leave the reader waiting forever.
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let json = String::from_utf8(reader.join().unwrap()).unwrap();
    assert!(json.contains("\"seconds\""), "{json}");
    assert!(png.is_file());
    assert_eq!(listing(&d), ["summary.json", "x.png"]);
}
