//! The third hostile-input campaign (issue 79): each class's reproducer, as a case of the suite.
//! The MPI classes (a rank that cannot read, ranks that disagree) are in `.ci/mpi`, the Python
//! ones in `python/tests`.

use super::{args, not_black, untouched, Case, Expect, More, HEART};
use std::path::{Path, PathBuf};

/// The temporaries' old names for the next `count` PIDs: `.NAME.tmp-PID`, each a link to
/// `target`. A run that opened its temporary through one of them emptied `target`.
fn plant_links(dir: &Path, name: &str, target: &Path, count: u32) {
    let last: u32 = std::fs::read_to_string("/proc/sys/kernel/ns_last_pid")
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(1000);
    for pid in last + 1..=last + count {
        let link = dir.join(format!(".{name}.tmp-{pid}"));
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(target, &link).unwrap();
    }
}

/// Removes the links [`plant_links`] left (the suite checks no `.tmp-` file stays: the planted
/// ones are not the run's, but a check run later may count them).
fn unplant(name: &str) -> impl Fn(&Path) -> Result<String, String> {
    let prefix = format!(".{name}.tmp-");
    move |dir| {
        let mut n = 0;
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let file = e.file_name().to_string_lossy().into_owned();
            if file.starts_with(&prefix) && e.file_type().is_ok_and(|t| t.is_symlink()) {
                std::fs::remove_file(e.path()).unwrap();
                n += 1;
            }
        }
        Ok(format!("{n} planted links were not followed"))
    }
}

/// A case with the third campaign's additions.
fn case(name: &'static str, a: &[&str], expect: Expect, gone: Vec<PathBuf>, more: More) -> Case {
    let mut c = Case::new(name, args(a), expect, gone);
    c.more = more;
    c
}

/// Whether a temporary of `name` (`.NAME.tmp-…`, a regular file) is in the folder.
fn temporary_of(name: &'static str) -> impl Fn(&Path) -> bool {
    move |dir| {
        std::fs::read_dir(dir).is_ok_and(|d| {
            d.flatten().any(|e| {
                e.file_name()
                    .to_string_lossy()
                    .starts_with(&format!(".{name}.tmp-"))
                    && e.file_type().is_ok_and(|t| t.is_file())
            })
        })
    }
}

fn out_png_temporary(dir: &Path) -> bool {
    temporary_of("sig.png")(dir)
}

/// Whether 1.5 s have passed since the case's setup wrote `started` (mid-way through a chart's
/// sweep, which takes far longer).
fn chart_under_way(dir: &Path) -> bool {
    std::fs::metadata(dir.join("started"))
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|e| e.as_secs_f64() > 1.5)
}

/// The cases, in the order of the list.
pub fn cases(dir: &Path) -> Vec<Case> {
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(dir.join(name), bytes).unwrap();
        name.to_string()
    };
    let mut c = Vec::new();

    // 1. A link planted at the temporary's old, predictable name is never followed: the volume
    // it points at keeps its bytes, and the output is written. The same for info --json.
    let raw: Vec<u8> = (0..16u32 * 16 * 16).map(|i| (i * 7 % 251) as u8).collect();
    let vol = write("victim.raw", &raw);
    let victim = dir.join(&vol);
    let render = [
        "render", &vol, "--dims", "16,16,16", "--type", "u8", "--window", "0,255", "--size",
        "32x32", "-o", "o.png",
    ];
    let info = [
        "info", &vol, "--dims", "16,16,16", "--type", "u8", "--json", "i.json",
    ];
    for (name, a, out) in [
        (
            "a link at .o.png.tmp-<next PIDs> -> the volume: the volume keeps its bytes",
            &render[..],
            "o.png",
        ),
        (
            "a link at .i.json.tmp-<next PIDs> -> the volume (info --json)",
            &info[..],
            "i.json",
        ),
    ] {
        let victim = victim.clone();
        let (keep, unplant) = (untouched(dir.join(&vol), raw.clone()), unplant(out));
        let setup: super::Setup = Box::new(move |d: &Path| plant_links(d, out, &victim, 400));
        c.push(
            case(
                name,
                a,
                Expect::Renders,
                vec![],
                More {
                    setup: Some(setup),
                    ..More::default()
                },
            )
            .checked(move |d| Ok(format!("{}; {}", keep(d)?, unplant(d)?))),
        );
    }

    // 8. SIGTERM and SIGINT while an output is being written remove its temporary. The JSON goes
    // to a FIFO nobody reads: it is written after the image's temporary, so the run waits there
    // with the temporary on disk until the signal comes.
    for signal in [15, 2] {
        c.push(case(
            if signal == 15 {
                "SIGTERM while the outputs are written: no temporary, no output"
            } else {
                "SIGINT while the outputs are written: no temporary, no output"
            },
            &[
                "render", HEART, "--size", "64x64", "--out", "sig.png", "--json", "sig.fifo",
            ],
            Expect::Signalled,
            vec![dir.join("sig.png")],
            More {
                setup: Some(Box::new(|d: &Path| {
                    let fifo = d.join("sig.fifo");
                    let _ = std::fs::remove_file(&fifo);
                    assert!(super::mkfifo(&fifo), "mkfifo");
                })),
                signal: Some((signal, out_png_temporary)),
                ..More::default()
            },
        ));
    }
    // A chart interrupted mid-sweep leaves no folder at all (it writes its files all at once).
    c.push(case(
        "SIGINT during chart --out NEWDIR: no folder left",
        &[
            "chart",
            HEART,
            "--size",
            "32x32",
            "--runs",
            "1",
            "--out",
            "chartdir/new",
        ],
        Expect::Signalled,
        vec![dir.join("chartdir")],
        More {
            setup: Some(Box::new(|d: &Path| {
                std::fs::write(d.join("started"), b"").unwrap()
            })),
            signal: Some((2, chart_under_way)),
            ..More::default()
        },
    ));

    // 4. Post-classification under an address-space cap refuses (exit 2, one line) instead of
    // aborting: a random 512³ u8 under 768 MiB, where pre-classification renders.
    write(
        "n512.raw",
        &super::noise(512 * 512 * 512, 0x9e37_79b9_7f4a_7c15),
    );
    let n512 = [
        "render",
        "n512.raw",
        "--dims",
        "512,512,512",
        "--type",
        "u8",
        "--window",
        "0,255",
        "--size",
        "64x64",
        "--out",
        "out.png",
    ];
    let mut post = n512.to_vec();
    post.extend(["--classification", "post"]);
    c.push(
        case(
            "--classification post, random 512³ u8 under 768 MiB: refused, no abort",
            &post,
            Expect::Refused("--classification post keeps the"),
            vec![dir.join("out.png")],
            More::default(),
        )
        .ulimit("-v 786432")
        .release_only(),
    );

    // 5. Post-classification of a volume one voxel thick along an axis renders (it used to
    // render nothing and exit 0); slabs as deep as the volume are refused.
    let slice: Vec<u8> = (0..64u32 * 64).map(|i| (i * 37 % 256) as u8).collect();
    write("thin-slice.raw", &slice);
    write("thin-line.raw", &slice[..64]);
    write("thin-one.raw", &[255]);
    for (name, file, dims, png) in [
        (
            "post: a 64x64x1 slice renders",
            "thin-slice.raw",
            "64,64,1",
            "thin1.png",
        ),
        (
            "post: a 64x1x1 line renders",
            "thin-line.raw",
            "64,1,1",
            "thin2.png",
        ),
        (
            "post: one voxel renders",
            "thin-one.raw",
            "1,1,1",
            "thin3.png",
        ),
    ] {
        c.push(
            case(
                name,
                &[
                    "render",
                    file,
                    "--dims",
                    dims,
                    "--type",
                    "u8",
                    "--window",
                    "0,255",
                    "--view",
                    "30,20,0",
                    "--size",
                    "64x64",
                    "--classification",
                    "post",
                    "--out",
                    png,
                ],
                Expect::Renders,
                vec![],
                More::default(),
            )
            .checked(not_black(png)),
        );
    }
    c.push(case(
        "post: --slab-post deeper than the volume is refused",
        &[
            "render",
            HEART,
            "--size",
            "32x32",
            "--classification",
            "post",
            "--slab-post",
            "200",
            "--out",
            "out.png",
        ],
        Expect::Refused("at least as deep as the volume"),
        vec![dir.join("out.png")],
        More::default(),
    ));
    c.push(case(
        "slabs: more depth phases than a setup holds are refused",
        &[
            "render",
            HEART,
            "--size",
            "32x32",
            "--slicing",
            "image",
            "--depth-phases",
            "100000",
            "--out",
            "out.png",
        ],
        Expect::Refused("depth phases in 0..=256"),
        vec![dir.join("out.png")],
        More::default(),
    ));

    // 6. Wide samples keep their values: u32 4 294 967 290 … 295 are not one value, f64 past
    // f32's range is not missing.
    let mut u32s = Vec::new();
    let mut f64s = Vec::new();
    for z in 0..12i32 {
        for y in 0..12i32 {
            for x in 0..12i32 {
                let r2 = (x - 6).pow(2) + (y - 6).pow(2) + (z - 6).pow(2);
                let v = (5 - r2 / 6).max(0) as u32;
                u32s.extend((4_294_967_290 + v).to_le_bytes());
                f64s.extend((1e300 * (1.0 + f64::from(v))).to_le_bytes());
            }
        }
    }
    write("wide-u32.raw", &u32s);
    write("wide-f64.raw", &f64s);
    for (name, file, ty, png) in [
        (
            "u32 samples 4294967290..295 render (not one value)",
            "wide-u32.raw",
            "u32",
            "u32.png",
        ),
        (
            "f64 samples past 3.4e38 render (not missing)",
            "wide-f64.raw",
            "f64",
            "f64.png",
        ),
    ] {
        c.push(
            case(
                name,
                &[
                    "render", file, "--dims", "12,12,12", "--type", ty, "--size", "48x48", "--out",
                    png,
                ],
                Expect::Renders,
                vec![],
                More::default(),
            )
            .checked(not_black(png)),
        );
    }
    c.push(
        case(
            "u32 near 2^32 with --window 4294967290,4294967295 (f64 bounds)",
            &[
                "render",
                "wide-u32.raw",
                "--dims",
                "12,12,12",
                "--type",
                "u32",
                "--window",
                "4294967290,4294967295",
                "--size",
                "48x48",
                "--out",
                "u32w.png",
            ],
            Expect::Renders,
            vec![],
            More::default(),
        )
        .checked(not_black("u32w.png")),
    );
    c.push(
        case(
            "info of f64 past 3.4e38: no sample missing, the precision said",
            &[
                "info",
                "wide-f64.raw",
                "--dims",
                "12,12,12",
                "--type",
                "f64",
                "--json",
                "f64.json",
            ],
            Expect::Renders,
            vec![],
            More::default(),
        )
        .checked(|d| {
            let j = std::fs::read_to_string(d.join("f64.json")).map_err(|e| e.to_string())?;
            for key in [
                "\"not_finite\": 0",
                "\"held_exactly\": false",
                "\"precision\"",
            ] {
                if !j.contains(key) {
                    return Err(format!("f64.json lacks {key}: {j}"));
                }
            }
            Ok("not_finite 0, precision stated".into())
        }),
    );

    // 7. info names no window render refuses: it says render refuses, and why.
    write("nan3.raw", &[0xff; 32]);
    write("const3.raw", &[9; 8]);
    for (name, file, ty, why) in [
        (
            "info of all-NaN data: render refuses, said",
            "nan3.raw",
            "f32",
            "no sample is finite",
        ),
        (
            "info of constant data: render refuses, said",
            "const3.raw",
            "u8",
            "the data are constant",
        ),
    ] {
        c.push(
            case(
                name,
                &[
                    "info", file, "--dims", "2,2,2", "--type", ty, "--json", "w.json",
                ],
                Expect::Renders,
                vec![],
                More::default(),
            )
            .checked(move |d| {
                let j = std::fs::read_to_string(d.join("w.json")).map_err(|e| e.to_string())?;
                if j.contains("\"window\": null") && j.contains(why) {
                    Ok(format!("window null, refused: {why}"))
                } else {
                    Err(format!("w.json: {j}"))
                }
            }),
        );
    }

    // 10. Smaller: a report that cannot be written is an error; NaN thresholds; --bricks capped.
    c.push(case(
        "info > /dev/full: exit 2, not 0",
        &["info", HEART],
        Expect::Refused("standard output: cannot write"),
        vec![],
        More {
            stdout: Some(PathBuf::from("/dev/full")),
            ..More::default()
        },
    ));
    c.push(case(
        "verify --min-psnr nan",
        &["verify", HEART, "--size", "16x16", "--min-psnr", "nan"],
        Expect::Refused("'nan' is not finite"),
        vec![],
        More::default(),
    ));
    c.push(case(
        "render --bricks 16,16,16 in one process",
        &[
            "render", HEART, "--bricks", "16,16,16", "--size", "16x16", "--out", "out.png",
        ],
        Expect::Refused("at most 512"),
        vec![dir.join("out.png")],
        More::default(),
    ));
    c
}
