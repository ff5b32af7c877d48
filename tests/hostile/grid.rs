//! Rectilinear grids (issue 77, `.vtr`): coordinates that are NaN, repeat, go back or are too few;
//! coordinate arrays missing, too many or of several components; and the flags that place
//! kernels on a uniform grid (each a one-line refusal, naming the axis and index where the
//! coordinates are at fault).

use super::{refused, Case};
use std::path::Path;

/// A 3×2×2 `.vtr` of ones whose coordinates are `x` and y, z = 0 1, or whose `Coordinates`
/// element holds `coordinates` instead.
fn vtr(x: &str, coordinates: Option<&str>) -> Vec<u8> {
    let array = |name: &str, body: &str| {
        format!("<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">{body}</DataArray>")
    };
    let coords = match coordinates {
        Some(c) => c.to_string(),
        None => [array("x", x), array("y", "0 1"), array("z", "0 1")].concat(),
    };
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"RectilinearGrid\" version=\"0.1\">\n\
         <RectilinearGrid WholeExtent=\"0 2 0 1 0 1\"><Piece Extent=\"0 2 0 1 0 1\">\n\
         <PointData Scalars=\"v\"><DataArray type=\"Float32\" Name=\"v\" format=\"ascii\">\
         1 1 1 1 1 1 1 1 1 1 1 1</DataArray></PointData>\n<Coordinates>{coords}</Coordinates>\n\
         </Piece></RectilinearGrid></VTKFile>\n"
    )
    .into_bytes()
}

pub(super) fn cases(dir: &Path) -> Vec<Case> {
    let mut c = Vec::new();
    let two = "<DataArray type=\"Float64\" Name=\"x\" format=\"ascii\">0 1 2</DataArray>\
               <DataArray type=\"Float64\" Name=\"y\" format=\"ascii\">0 1</DataArray>";
    let pairs = "<DataArray type=\"Float64\" Name=\"x\" NumberOfComponents=\"2\" \
                 format=\"ascii\">0 0 1 1 2 2</DataArray>\
                 <DataArray type=\"Float64\" Name=\"y\" format=\"ascii\">0 1</DataArray>\
                 <DataArray type=\"Float64\" Name=\"z\" format=\"ascii\">0 1</DataArray>";
    for (name, file, bytes, want) in [
        (
            "a .vtr: NaN coordinates",
            "nan.vtr",
            vtr("0 nan 2", None),
            "x coordinate 1 is NaN",
        ),
        (
            "a .vtr: a repeated coordinate",
            "repeat.vtr",
            vtr("0 1 1", None),
            "repeats the one before",
        ),
        (
            "a .vtr: coordinates going back",
            "back.vtr",
            vtr("0 2 1", None),
            "is below the one before",
        ),
        (
            "a .vtr: too few coordinates",
            "few.vtr",
            vtr("0 1", None),
            "x coordinates: expected 3 values",
        ),
        (
            "a .vtr: no Coordinates",
            "none.vtr",
            vtr("", Some("")),
            "Coordinates hold 0",
        ),
        (
            "a .vtr: two coordinate arrays",
            "two.vtr",
            vtr("", Some(two)),
            "expected 3 (x, y, z)",
        ),
        (
            "a .vtr: coordinates of two components",
            "pairs.vtr",
            vtr("", Some(pairs)),
            "expected 1",
        ),
        (
            "a .vtr: infinite coordinates",
            "inf.vtr",
            vtr("0 1 inf", None),
            "must be finite",
        ),
    ] {
        let mut case = refused(name, &["render", file, "--out", "out.png"], want, dir);
        case.before = vec![(dir.join(file), bytes)];
        c.push(case);
    }
    for (name, flag, want) in [
        (
            "a .vtr with --slicing image",
            &["--slicing", "image"][..],
            "image-aligned slabs",
        ),
        (
            "a .vtr with --classification post",
            &["--classification", "post"],
            "post-classification",
        ),
        (
            "a .vtr with --accum fixed",
            &["--accum", "fixed"],
            "fixed-point",
        ),
        (
            "a .vtr with --crop",
            &["--crop", "0:1,0:1,0:1"],
            "crop the file",
        ),
        (
            "a .vtr in bricks",
            &["--bricks", "1,1,2"],
            "does not render in bricks",
        ),
    ] {
        let mut a = vec!["render", "ok.vtr", "--out", "out.png"];
        a.extend_from_slice(flag);
        let mut case = refused(name, &a, want, dir);
        case.before = vec![(dir.join("ok.vtr"), vtr("0 1 3", None))];
        c.push(case);
    }
    c
}
