//! Label maps (issue 77, `--labels`): tables that cannot classify (a label that is no integer,
//! one beyond ±2²⁴, one given twice, a colour outside [0, 1], no label, a file too large, not
//! JSON nor ITK-SNAP's format) and the flags that classify by value (each a one-line refusal);
//! voxels whose labels are beyond the table render a clear picture. Multi-component volumes:
//! more than 4 components, a short file, `--tf` counts that match no component count, lit
//! shading, streaming and `info` (each a one-line refusal).

use super::{args, png, refused, Case, Expect, HEART};
use std::path::Path;

pub(super) fn cases(dir: &Path) -> Vec<Case> {
    let mut c = Vec::new();
    let render = |table: &'static str, more: &[&'static str]| {
        let mut a = vec!["render", HEART, "--labels", table];
        a.extend_from_slice(more);
        a.extend_from_slice(&["--out", "out.png"]);
        a
    };
    for (name, table, want) in [
        (
            "--labels: a label that is no integer",
            r#"{"1.5": [1, 0, 0, 1]}"#,
            "is not an integer",
        ),
        (
            "--labels: a label beyond 2^24",
            r#"{"16777217": [1, 0, 0, 1]}"#,
            "is beyond",
        ),
        (
            "--labels: a label given twice",
            r#"{"1": [1, 0, 0, 1], "1": [0, 1, 0, 1]}"#,
            "given twice",
        ),
        (
            "--labels: a colour past 1",
            r#"{"1": [1, 0, 2, 1]}"#,
            "four numbers in [0, 1]",
        ),
        (
            "--labels: NaN opacity",
            r#"{"1": [1, 0, 0, NaN]}"#,
            "expected a JSON object",
        ),
        (
            "--labels: three channels",
            r#"{"1": [1, 0, 0]}"#,
            "four numbers",
        ),
        ("--labels: no label", "{}", "no label"),
        (
            "--labels: a missing file",
            "no-such-labels.json",
            "no-such-labels.json",
        ),
    ] {
        c.push(refused(name, &render(table, &[]), want, dir));
    }
    let big = dir.join("big-labels.txt");
    let mut case = refused(
        "--labels: a 2 MiB label file",
        &render("big-labels.txt", &[]),
        "a label table is at most",
        dir,
    );
    case.before = vec![(big, vec![b'#'; 2 << 20])];
    c.push(case);
    let garbage = dir.join("garbage-labels.txt");
    let mut case = refused(
        "--labels: a file that is neither format",
        &render("garbage-labels.txt", &[]),
        "ITK-SNAP",
        dir,
    );
    case.before = vec![(garbage, b"1 red\n".to_vec())];
    c.push(case);
    let ok = r#"{"1": [1, 0, 0, 1]}"#;
    for (name, more, want) in [
        ("--labels with --tf", &["--tf", "grey"][..], "drop --tf"),
        (
            "--labels with --window",
            &["--window", "0,9"],
            "drop --window",
        ),
        (
            "--labels with --shading phong",
            &["--shading", "phong"],
            "render unlit",
        ),
        (
            "--labels with --classification post",
            &["--classification", "post"],
            "before reconstruction",
        ),
        (
            "--labels with --blend mip",
            &["--blend", "mip"],
            "names neither",
        ),
        ("--labels with --lod 1", &["--lod", "1"], "names none"),
        (
            "--labels with --quality",
            &["--quality", "40"],
            "--quality chooses",
        ),
    ] {
        c.push(refused(name, &render(ok, more), want, dir));
    }
    c.push(
        Case::new(
            "--labels beyond the volume's values: a clear picture",
            args(&[
                "render",
                HEART,
                "--labels",
                r#"{"100000": [1, 1, 1, 1], "-3": [1, 1, 1, 1]}"#,
                "--size",
                "32x32",
                "--out",
                "clear.png",
            ]),
            Expect::Renders,
            vec![],
        )
        .checked(|dir| {
            let (_, _, px) = png(dir, "clear.png")?;
            match px.iter().all(|p| p[..3] == [0.0; 3]) {
                true => Ok("clear.png: clear".into()),
                false => Err("clear.png: an unlisted label drew".into()),
            }
        }),
    );
    c.extend(components(dir));
    c
}

/// A MetaImage of 8³ voxels of `channels` u8 components, `bytes` of data.
fn mha(channels: &str, bytes: usize) -> Vec<u8> {
    let head = format!(
        "ObjectType = Image\nNDims = 3\nDimSize = 8 8 8\nElementType = MET_UCHAR\n\
         ElementNumberOfChannels = {channels}\nElementDataFile = LOCAL\n"
    );
    let data = (0..bytes).map(|i| (i % 251) as u8);
    [head.into_bytes(), data.collect()].concat()
}

fn components(dir: &Path) -> Vec<Case> {
    let mut c = Vec::new();
    let two = || (dir.join("two.mha"), mha("2", 2 * 512));
    let with = |name: &'static str,
                a: &[&str],
                want: &'static str,
                file: (std::path::PathBuf, Vec<u8>)| {
        let mut case = refused(name, a, want, dir);
        case.before = vec![file];
        case
    };
    c.push(with(
        "MetaImage of 5 components",
        &["render", "five.mha", "--out", "out.png"],
        "1 to 4 components",
        (dir.join("five.mha"), mha("5", 5 * 512)),
    ));
    c.push(with(
        "VTI of 7 components",
        &["render", "seven.vti", "--out", "out.png"],
        "1 to 4 components",
        (
            dir.join("seven.vti"),
            b"<?xml version=\"1.0\"?><VTKFile type=\"ImageData\" version=\"0.1\"><ImageData \
              WholeExtent=\"0 1 0 1 0 1\" Origin=\"0 0 0\" Spacing=\"1 1 1\"><Piece \
              Extent=\"0 1 0 1 0 1\"><PointData><DataArray type=\"UInt8\" Name=\"c\" \
              NumberOfComponents=\"7\" format=\"ascii\">1</DataArray></PointData></Piece>\
              </ImageData></VTKFile>"
                .to_vec(),
        ),
    ));
    c.push(with(
        "MetaImage of 2 components, one component's bytes",
        &["render", "short.mha", "--out", "out.png"],
        "expected 1024 bytes",
        (dir.join("short.mha"), mha("2", 512)),
    ));
    c.push(with(
        "2 components, 3 --tf",
        &[
            "render", "two.mha", "--tf", "grey", "--tf", "grey", "--tf", "grey", "--out", "out.png",
        ],
        "give one per component",
        two(),
    ));
    c.push(refused(
        "one component, 2 --tf, in bricks",
        &[
            "render", HEART, "--tf", "grey", "--tf", "density", "--bricks", "2,1,1", "--out",
            "out.png",
        ],
        "this one has one component",
        dir,
    ));
    c.push(refused(
        "one component, 2 --tf",
        &[
            "render", HEART, "--tf", "grey", "--tf", "density", "--out", "out.png",
        ],
        "this one has one component",
        dir,
    ));
    c.push(with(
        "2 components with --shading phong",
        &[
            "render",
            "two.mha",
            "--shading",
            "phong",
            "--out",
            "out.png",
        ],
        "render unlit",
        two(),
    ));
    c.push(with(
        "2 components streamed",
        &["render", "--stream", "two.mha", "--out", "out.png"],
        "components per voxel",
        two(),
    ));
    let mut info = with(
        "info of 2 components",
        &["info", "two.mha"],
        "components per voxel",
        two(),
    );
    info.gone = vec![];
    c.push(info);
    c
}
