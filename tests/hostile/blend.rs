//! Projections (issue 77, `--blend`): an unknown blend, and the flags a projection cannot honour
//! (lit shading, clipping planes, object slicing, fixed point, bricks, a depth map, the
//! sheet reference): each a one-line refusal.
//! A projection over a crop renders.

use super::{args, png, refused, Case, Expect, HEART};
use std::path::Path;

pub(super) fn cases(dir: &Path) -> Vec<Case> {
    let mut c = Vec::new();
    let render = |blend: &'static str, more: &[&'static str]| {
        let mut a = vec!["render", HEART, "--blend", blend];
        a.extend_from_slice(more);
        a.extend_from_slice(&["--out", "out.png"]);
        a
    };
    c.push(refused(
        "--blend sum (no such blend)",
        &render("sum", &[]),
        "invalid value 'sum'",
        dir,
    ));
    c.push(refused(
        "--blend mip with --shading phong",
        &render("mip", &["--shading", "phong"]),
        "has no surface to light",
        dir,
    ));
    c.push(refused(
        "--blend minip with --clip",
        &render("minip", &["--clip", "1,0,0,1"]),
        "do not cut kernels yet",
        dir,
    ));
    c.push(refused(
        "--blend average with --slicing object",
        &render("average", &["--slicing", "object"]),
        "--blend average with --slicing object",
        dir,
    ));
    c.push(refused(
        "--blend mip with --accum fixed",
        &render("mip", &["--accum", "fixed"]),
        "there is no fixed-point post-classification",
        dir,
    ));
    c.push(refused(
        "--blend mip with --bricks",
        &render("mip", &["--bricks", "2,1,1"]),
        "does not render in bricks",
        dir,
    ));
    c.push(refused(
        "--blend mip with --depth-map",
        &render("mip", &["--depth-map", "depth.pfm"]),
        "a projection has no depth",
        dir,
    ));
    c.push(refused(
        "verify --blend mip against the sheet reference",
        &["verify", HEART, "--blend", "mip"],
        "measure a projection against its own model with --reference continuous",
        dir,
    ));
    c.push(
        Case::new(
            "--blend mip over a crop: renders",
            args(&[
                "render",
                HEART,
                "--blend",
                "mip",
                "--crop",
                "4:27,10:31,2:9",
                "--size",
                "32x32",
                "--out",
                "mip.png",
            ]),
            Expect::Renders,
            vec![],
        )
        .checked(|dir| {
            let (_, _, px) = png(dir, "mip.png")?;
            let lit = px.iter().filter(|p| p[..3] != [0.0; 3]).count();
            match lit > 0 {
                true => Ok(format!("mip.png: {lit} pixels lit")),
                false => Err("mip.png: nothing drawn".into()),
            }
        }),
    );
    c
}
