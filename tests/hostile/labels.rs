//! Label maps (issue 77, `--labels`): tables that cannot classify (a label that is no integer,
//! one beyond ±2²⁴, one given twice, a colour outside [0, 1], no label, a file too large, not
//! JSON nor ITK-SNAP's format) and the flags that classify by value (each a one-line refusal);
//! voxels whose labels are beyond the table render a clear picture.

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
            args(&render(
                r#"{"100000": [1, 1, 1, 1], "-3": [1, 1, 1, 1]}"#,
                &["--size", "32x32"],
            )),
            Expect::Renders,
            vec![],
        )
        .checked(|dir| {
            let (_, _, px) = png(dir, "out.png")?;
            match px.iter().all(|p| p[..3] == [0.0; 3]) {
                true => Ok("out.png: clear".into()),
                false => Err("out.png: an unlisted label drew".into()),
            }
        }),
    );
    c
}
