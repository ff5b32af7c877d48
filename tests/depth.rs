//! Depth (issue 77): `footprint probe` and `render --depth-map` give where each ray's accumulated
//! opacity first reaches 0.5 in the frame's continuous model, within one voxel of the analytic
//! surface of an opaque slab and of a sphere, in world units from the volume's centre.

use footprint_harness::args::keywords::from_keywords;
use footprint_harness::args::{RenderArgs, Value};
use footprint_harness::commands::probe::probe_frame;
use footprint_harness::io::image::encode_npy;
use footprint_harness::io::stream::InMemory;
use footprint_harness::io::volume::{Data, Samples, Volume};
use std::sync::Arc;

/// A control-point transfer function: transparent below 0.4 of the window, opaque (opacity 1
/// per world unit) from 0.6.
fn step_tf(dir: &std::path::Path) -> String {
    let path = dir.join("step.tf");
    std::fs::write(&path, "0 1 1 1 0\n0.4 1 1 1 0\n0.6 1 1 1 1\n1 1 1 1 1\n").unwrap();
    path.display().to_string()
}

/// `render` arguments for the u8 volume `dims` whose voxel (i, j, k) is 255 where `inside`, 0
/// elsewhere, at 48×48, seen from `view`.
fn request(
    dims: [usize; 3],
    inside: impl Fn(f64, f64, f64) -> bool,
    view: [f64; 3],
    tf: &str,
) -> RenderArgs {
    let mut v = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                v.push(if inside(i as f64, j as f64, k as f64) {
                    255u8
                } else {
                    0
                });
            }
        }
    }
    let volume = Volume::new(dims, [1.0; 3], Samples::U8(Data::from(v)));
    let list = |v: &[f64]| Value::List(v.iter().map(|x| Value::Float(*x)).collect());
    let mut args: RenderArgs = from_keywords([
        ("size", &Value::List(vec![Value::Int(48), Value::Int(48)])),
        ("view", &list(&view)),
        ("window", &list(&[0.0, 255.0])),
        ("tf", &Value::Text(tf.into())),
    ])
    .unwrap();
    args.memory = Some(InMemory {
        volume: Arc::new(volume),
        name: "test".into(),
    });
    args
}

#[test]
fn the_depth_of_an_opaque_slab_is_its_face_within_a_voxel() {
    let dir = tempfile::tempdir().unwrap();
    let tf = step_tf(dir.path());
    // Voxels k = 12 … 19 of 32 are the slab: its faces lie half a voxel outside them, at
    // k = 11.5 and 19.5, ±4 world units from the centre (k = 15.5) along z.
    for view in [[0.0, 0.0, 0.0], [180.0, 0.0, 0.0], [30.0, 20.0, 0.0]] {
        let args = request([32, 32, 32], |_, _, k| (12.0..20.0).contains(&k), view, &tf);
        let (probes, _) = probe_frame(&args, None).unwrap();
        let mut hits = 0;
        for p in &probes {
            if p.depth.is_nan() {
                continue;
            }
            hits += 1;
            // The crossing is on the face toward the viewer (unless the ray enters through the
            // slab's side, which lies at the volume's edge, |x| or |y| near 16).
            let side = p.world[0].abs() > 14.5 || p.world[1].abs() > 14.5;
            if !side {
                assert!(
                    (p.world[2].abs() - 4.0).abs() <= 1.0,
                    "{view:?}: a crossing at {:?} is not within a voxel of a face",
                    p.world
                );
                assert!(
                    p.value > 0.0,
                    "{view:?}: the value there is the slab's: {p:?}"
                );
                // Seen along z, the face toward the viewer is 4 world units nearer than the
                // centre.
                if view[1] == 0.0 && view[0] % 180.0 == 0.0 {
                    assert!((p.depth + 4.0).abs() <= 1.0, "{view:?}: {p:?}");
                }
            }
        }
        assert!(
            hits > 48 * 48 / 4,
            "{view:?}: the slab covers the view ({hits} hits)"
        );
    }
}

#[test]
fn the_depth_of_a_sphere_is_its_surface_within_a_voxel() {
    let dir = tempfile::tempdir().unwrap();
    let tf = step_tf(dir.path());
    // Voxels within 12 of the centre (19.5, 19.5, 19.5): the ball of radius 12 sampled at the
    // voxel centres, its analytic surface.
    let c = 19.5;
    let inside = move |i: f64, j: f64, k: f64| {
        ((i - c).powi(2) + (j - c).powi(2) + (k - c).powi(2)).sqrt() <= 12.0
    };
    for view in [[0.0, 0.0, 0.0], [30.0, 20.0, 0.0]] {
        let args = request([40, 40, 40], inside, view, &tf);
        let (probes, _) = probe_frame(&args, None).unwrap();
        let (mut checked, mut worst) = (0, 0.0f64);
        for p in &probes {
            if p.depth.is_nan() {
                continue;
            }
            // The crossing's distance from the surface (radius 12), on the near half, for rays
            // at least a voxel and a half inside the silhouette (a grazing ray meets the blurred
            // edge along its length, and its crossing lies where it passes deepest).
            let r = p.world.iter().map(|x| x * x).sum::<f64>().sqrt();
            let rho = (r * r - p.depth * p.depth).max(0.0).sqrt();
            if rho > 11.0 {
                continue;
            }
            assert!(p.depth < 0.0, "{view:?}: {p:?} is not on the near side");
            worst = worst.max((r - 12.0).abs());
            checked += 1;
        }
        assert!(
            worst <= 1.0,
            "{view:?}: a crossing {worst:.3} from the surface"
        );
        eprintln!("{view:?}: {checked} crossings, the worst {worst:.3} from the surface");
        assert!(checked > 150, "{view:?}: {checked} rays checked");
        // A ray that misses the sphere has no depth.
        assert!(probes[0].depth.is_nan(), "{view:?}: the corner ray misses");
    }
}

#[test]
fn render_writes_the_depth_map_beside_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let tf = step_tf(dir.path());
    let raw = dir.path().join("slab.raw");
    let mut v = vec![0u8; 32 * 32 * 32];
    v[12 * 32 * 32..20 * 32 * 32].fill(255);
    std::fs::write(&raw, &v).unwrap();
    let (npy, pfm, png) = (
        dir.path().join("d.npy"),
        dir.path().join("d.pfm"),
        dir.path().join("x.png"),
    );
    for depth in [&npy, &pfm] {
        footprint_harness::run_with(
            [
                "footprint",
                "render",
                raw.to_str().unwrap(),
                "--dims",
                "32,32,32",
                "--type",
                "u8",
                "--window",
                "0,255",
                "--tf",
                &tf,
                "--size",
                "48x48",
                "--out",
                png.to_str().unwrap(),
                "--depth-map",
                depth.to_str().unwrap(),
            ],
            None,
        )
        .unwrap();
    }
    let bytes = std::fs::read(&npy).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header = 10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!(header % 64, 0, "the header is padded to 64 bytes");
    let text = String::from_utf8_lossy(&bytes[10..header]);
    assert!(text.contains("'shape': (48, 48)"), "{text}");
    let depth: Vec<f32> = bytes[header..]
        .chunks(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(depth.len(), 48 * 48);
    // The centre pixel sees the near face, 4 world units in front of the centre (within a
    // voxel); the corners see nothing.
    let centre = depth[24 * 48 + 24];
    assert!((centre + 4.0).abs() <= 1.0, "{centre}");
    assert!(depth[0].is_nan());
    // The PFM holds the same values (rows bottom to top).
    let pfm = footprint_harness::io::image::decode_pfm(&std::fs::read(&pfm).unwrap(), "d").unwrap();
    let same = pfm
        .data
        .iter()
        .zip(&depth)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same, "the PFM and the .npy agree");
    // The encoder's own layout for a small array.
    let e = encode_npy(&[1.0, 2.0], 1, 2);
    let header = 10 + u16::from_le_bytes([e[8], e[9]]) as usize;
    assert_eq!(
        (header % 64, e.len(), e[header - 1]),
        (0, header + 8, b'\n')
    );
    assert_eq!(&e[header..header + 4], &1.0f32.to_le_bytes());
    // One frame's: not with --orbit.
    let e = footprint_harness::run_with(
        [
            "footprint",
            "render",
            "--scene-size",
            "8",
            "--size",
            "16x16",
            "--orbit",
            "4",
            "--out",
            png.to_str().unwrap(),
            "--depth-map",
            npy.to_str().unwrap(),
        ],
        None,
    )
    .expect_err("refused");
    assert!(e.to_string().contains("--depth-map"), "{e}");
}
