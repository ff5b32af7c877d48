//! Crop boxes (issue 77): outside the volume, empty, malformed, past any index, and where a crop
//! cannot be honoured (bricks, the built-in field's finer grid): each a
//! one-line refusal. A box of one voxel renders that voxel's splat alone.

use super::{args, png, refused, Case, Expect, HEART};
use std::path::Path;

pub(super) fn cases(dir: &Path) -> Vec<Case> {
    let mut c = Vec::new();
    let out = ["--out", "out.png"];
    let render = |crop: &'static str, more: &[&'static str]| {
        let mut a = vec!["render", HEART, "--crop", crop];
        a.extend_from_slice(more);
        a.extend_from_slice(&out);
        a
    };
    c.push(refused(
        "--crop past the volume (j 0:40 of 32)",
        &render("0:31,0:40,0:11", &[]),
        "reaches past the volume",
        dir,
    ));
    c.push(refused(
        "--crop wholly outside the volume",
        &render("100:200,0:31,0:11", &[]),
        "reaches past the volume",
        dir,
    ));
    c.push(refused(
        "--crop empty (5:4)",
        &render("5:4,0:31,0:11", &[]),
        "is empty",
        dir,
    ));
    c.push(refused(
        "--crop malformed",
        &render("1:2,3", &[]),
        "expected X0:X1,Y0:Y1,Z0:Z1",
        dir,
    ));
    c.push(refused(
        "--crop past any index (2^70)",
        &render("0:1180591620717411303424,0:1,0:1", &[]),
        "too large",
        dir,
    ));
    c.push(refused(
        "--crop negative",
        &["render", HEART, "--crop=-1:4,0:1,0:1", "--out", "out.png"],
        "invalid digit",
        dir,
    ));
    c.push(refused(
        "--crop with --bricks",
        &render("0:10,0:10,0:10", &["--bricks", "2,1,1"]),
        "does not render in bricks",
        dir,
    ));
    c.push(refused(
        "--crop past a pipe's volume, refused before it is read",
        &[
            "render",
            "--stream",
            "-",
            "--dims",
            "4,4,4",
            "--type",
            "u8",
            "--crop",
            "0:4,0:1,0:1",
            "--slicing",
            "object",
            "--lod",
            "0",
            "--window",
            "0,255",
            "--out",
            "out.png",
        ],
        "reaches past the volume",
        dir,
    ));
    c.push(refused(
        "--crop with --reference field",
        &["verify", "--crop", "0:10,0:10,0:10", "--reference", "field"],
        "indexes the grid rendered",
        dir,
    ));
    // Clipping planes.
    let clip = |planes: &[&'static str], more: &[&'static str]| {
        let mut a = vec!["render", HEART];
        for p in planes {
            a.extend_from_slice(&["--clip", p]);
        }
        a.extend_from_slice(more);
        a.extend_from_slice(&out);
        a
    };
    c.push(refused(
        "--clip with a NaN",
        &clip(&["nan,0,0,1"], &[]),
        "is not finite",
        dir,
    ));
    c.push(refused(
        "--clip with a zero normal",
        &clip(&["0,0,0,1"], &[]),
        "the normal NX,NY,NZ is zero",
        dir,
    ));
    c.push(refused(
        "--clip with three numbers",
        &clip(&["1,0,0"], &[]),
        "expected 4 comma-separated numbers",
        dir,
    ));
    c.push(refused(
        "--clip, nine planes",
        &clip(&["1,0,0,1"; 9], &[]),
        "at most 8 clip one frame",
        dir,
    ));
    c.push(refused(
        "--clip with --slicing object",
        &clip(&["1,0,0,1"], &["--slicing", "object"]),
        "--clip does not render with --slicing object",
        dir,
    ));
    c.push(refused(
        "--clip with --perspective",
        &clip(&["1,0,0,1"], &["--perspective", "30"]),
        "--clip does not render with --perspective",
        dir,
    ));
    c.push(refused(
        "--clip with --bricks",
        &clip(&["1,0,0,1"], &["--bricks", "2,1,1"]),
        "--clip does not render in bricks",
        dir,
    ));
    c.push(refused(
        "--clip, verify against the sheet reference",
        &["verify", HEART, "--clip", "1,0,0,1"],
        "measure a clipped frame against its cut model with --reference continuous",
        dir,
    ));
    c.push(
        Case::new(
            "--clip keeping nothing: an empty picture",
            args(&[
                "render",
                HEART,
                "--clip",
                "1,0,0,-1e6",
                "--size",
                "32x32",
                "--out",
                "none.png",
            ]),
            Expect::Renders,
            vec![],
        )
        .checked(|dir| {
            let (_, _, px) = png(dir, "none.png")?;
            match px.iter().all(|p| p[..3] == [0.0; 3]) {
                true => Ok("none.png: nothing drawn".into()),
                false => Err("none.png has something on it".into()),
            }
        }),
    );
    // The built-in scene's corner voxel alone: one splat, a small blob in a clear picture.
    c.push(
        Case::new(
            "--crop keeping one voxel: its splat alone",
            args(&[
                "render",
                "--crop",
                "0:0,0:0,0:0",
                "--size",
                "32x32",
                "--out",
                "one.png",
            ]),
            Expect::Renders,
            vec![],
        )
        .checked(|dir| {
            let (_, _, px) = png(dir, "one.png")?;
            // Over the black background: a lit pixel has colour.
            let lit = px.iter().filter(|p| p[..3] != [0.0; 3]).count();
            match lit * 20 <= px.len() {
                true => Ok(format!("one.png: {lit} pixels lit")),
                false => Err(format!("one.png: {lit} pixels lit for one voxel")),
            }
        }),
    );
    c
}
