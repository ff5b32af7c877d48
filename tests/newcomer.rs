//! What a newcomer meets first (issue 48): the default window and transfer function on a volume
//! file, `info` agreeing with `render`, `--orbit`, `--colorbar`, shell completions and the short
//! flags.

use footprint_suite::tmpdir;
use std::path::Path;

const HEAD: &str = "tests/data/headsq_64x64x93_int16_le.nhdr";

use footprint_suite::{json_numbers, path_str as s, run_cli as run};

/// 8-bit RGB pixels and the frame count of a PNG (1 unless animated).
fn decode(path: &Path) -> (Vec<u8>, u32) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let frames = reader
        .info()
        .animation_control()
        .map_or(1, |a| a.num_frames);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (buf, frames)
}

/// With no `--window`, `render` uses the window `info` prints, away from the data's range (the
/// background maps below the transfer function's clear part), and the default transfer function
/// for a file is `ct-bone-skin`; an explicit `--window` wins in both.
#[test]
fn info_and_render_agree_on_the_default_window() {
    let dir = tmpdir("default-window");
    let (info, summary) = (dir.join("info.json"), dir.join("render.json"));
    assert_eq!(run(&["info", HEAD, "--json", s(&info)]), 0);
    let out = dir.join("head.png");
    let args = [
        "render",
        HEAD,
        "-s",
        "64x64",
        "-o",
        s(&out),
        "--json",
        s(&summary),
    ];
    assert_eq!(run(&args), 0);
    let (info, summary) = (
        std::fs::read_to_string(&info).unwrap(),
        std::fs::read_to_string(&summary).unwrap(),
    );
    let window = json_numbers(&info, "window");
    assert_eq!(window, json_numbers(&summary, "window"));
    let range = json_numbers(&info, "range");
    assert!(
        window[0] > range[0] && window[1] < range[1],
        "{window:?} inside {range:?}"
    );
    assert!(info.contains("Otsu"), "{info}");
    assert!(summary.contains("\"tf\": \"ct-bone-skin\""), "{summary}");
    let explicit = [
        "render",
        HEAD,
        "-s",
        "64x64",
        "--window",
        "100,2000",
        "-o",
        s(&out),
    ];
    assert_eq!(
        run(&[&explicit[..], &["--json", s(&dir.join("w.json"))]].concat()),
        0
    );
    let w = std::fs::read_to_string(dir.join("w.json")).unwrap();
    assert_eq!(json_numbers(&w, "window"), [100.0, 2000.0]);
}

/// The default picture of a CT head is not fog: most of the image is clear background and the
/// head is bright where it shows (before the default window and transfer function, a grey
/// ramp over the full range gave a dim haze over the whole head).
#[test]
fn a_ct_head_with_default_flags_shows_structure() {
    let dir = tmpdir("default-picture");
    let out = dir.join("head.png");
    assert_eq!(
        run(&[
            "render",
            HEAD,
            "-s",
            "128x128",
            "--view",
            "180,-90,0",
            "-o",
            s(&out)
        ]),
        0
    );
    let (rgb, _) = decode(&out);
    let lum: Vec<u8> = rgb.chunks(3).map(|p| *p.iter().max().unwrap()).collect();
    let dark = lum.iter().filter(|&&l| l < 8).count() as f64 / lum.len() as f64;
    let bright = lum.iter().filter(|&&l| l > 160).count();
    assert!(dark > 0.4, "background clear: {dark}");
    assert!(bright > 200, "the head shows: {bright} bright pixels");
}

/// `--orbit N` writes an N-frame animated PNG whose first frame is the plain render; the
/// legend changes the picture only inside its panel; a .pfm or a reference render is refused.
#[test]
fn orbit_and_colorbar() {
    let dir = tmpdir("orbit");
    let (plain, orbit, bar) = (dir.join("p.png"), dir.join("o.png"), dir.join("b.png"));
    let base = ["render", HEAD, "-s", "96x96", "--view", "30,20,0"];
    assert_eq!(run(&[&base[..], &["-o", s(&plain)]].concat()), 0);
    assert_eq!(
        run(&[&base[..], &["--orbit", "6", "-o", s(&orbit)]].concat()),
        0
    );
    assert_eq!(
        run(&[&base[..], &["--colorbar", "-o", s(&bar)]].concat()),
        0
    );
    let ((p, n), (o, m), (b, _)) = (decode(&plain), decode(&orbit), decode(&bar));
    assert_eq!((n, m), (1, 6));
    assert_eq!(p, o, "frame 1 of the orbit is the plain render");
    let changed: Vec<usize> = (0..96 * 96)
        .filter(|&i| p[3 * i..3 * i + 3] != b[3 * i..3 * i + 3])
        .collect();
    assert!(changed.len() > 200, "a legend was drawn");
    assert!(
        changed.iter().all(|&i| i % 96 >= 96 / 2),
        "only in the right half"
    );
    let pfm = dir.join("x.pfm");
    assert_eq!(
        run(&[&base[..], &["--orbit", "4", "-o", s(&pfm)]].concat()),
        2
    );
    assert!(!pfm.exists());
    let refd = dir.join("r.png");
    assert_eq!(
        run(&[
            &base[..],
            &["--orbit", "4", "--method", "reference", "-o", s(&refd)]
        ]
        .concat()),
        2
    );
    assert_eq!(
        run(&[&base[..], &["--orbit", "1", "-o", s(&refd)]].concat()),
        2
    );
    assert_eq!(
        run(&[&base[..], &["--orbit", "361", "-o", s(&refd)]].concat()),
        2
    );
    assert!(!refd.exists());
}

/// `footprint completions SHELL` prints a script naming the subcommands; an unknown shell is
/// refused.
#[test]
fn shell_completions() {
    // (`footprint completions SHELL` prints this script; printing it here would fill the log.)
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        assert!(
            footprint_harness::cli::completion_script(shell)
                .unwrap()
                .len()
                > 1000
        );
    }
    assert!(footprint_harness::cli::completion_script("tcsh").is_err());
    assert_eq!(run(&["completions", "tcsh"]), 2);
    let text =
        String::from_utf8(footprint_harness::cli::completion_script("bash").unwrap()).unwrap();
    for word in [
        "render",
        "verify",
        "info",
        "--orbit",
        "--colorbar",
        "completions",
    ] {
        assert!(
            text.contains(word),
            "{word} missing from the bash completions"
        );
    }
}
