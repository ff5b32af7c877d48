//! The pipeline's one door (issue 76): a scene and a plan built as typed values render through
//! `pipeline::render` / `Renderer` to the same frames the pieces behind it give, the f64 reference
//! is an end like the others, and turning the camera through the renderer equals opening it again.

use footprint_harness::args::{parse_args, plan, scene};
use footprint_harness::pipeline::{prepare, render, render_ref, Renderer};
use footprint_harness::plan::{End, Lod, Plan};
use footprint_harness::scene::Scene;

#[test]
fn the_reference_is_an_ordinary_end() {
    let args = parse_args(&["--size", "48x40", "--method", "reference"]).unwrap();
    let (s, p) = (scene(&args).unwrap(), plan(&args).unwrap());
    assert_eq!(p.end, End::Reference);
    let (frame, r) = render(&s, &p).unwrap();
    let (direct, _) = render_ref(r.prepared()).unwrap();
    assert_eq!(frame.image.len(), 48 * 40);
    // The scene's voxels project closer than the smallest footprint at this size, so the frame
    // is supersampled: the end draws the f64 reference at k× the size, rounded to f32, and the
    // decorator averages it; `render_ref` averages in f64 and rounds once. They differ by the
    // f32 rounding alone.
    assert!(r.prepared().supersample > 1, "the decorator is exercised");
    for (a, b) in frame.image.iter().zip(&direct) {
        for (x, y) in a.iter().zip(b) {
            assert!((f64::from(*x) - y).abs() <= 1e-6, "{x} against {y}");
        }
    }
    assert!(
        frame.image.iter().any(|c| c[3] > 0.01),
        "the scene is visible"
    );
}

#[test]
fn a_plan_built_in_code_renders_through_the_door_and_decides_nothing_after() {
    let args = parse_args(&["--size", "40x40", "--view", "30,20,0"]).unwrap();
    let s = scene(&args).unwrap();
    // The default plan: the pilot chooses the slicing; --lod auto the level.
    let asked = plan(&args).unwrap();
    assert!(asked.auto_slicing.is_some());
    let mut r = Renderer::open(&s, &asked).unwrap();
    assert_eq!(r.plan().auto_slicing, None, "every automatic choice made");
    assert_eq!(r.plan().quality, None);
    let (first, _) = r.frame().unwrap();
    let (second, from_pilot) = r.frame().unwrap();
    assert!(!from_pilot, "the second frame is rendered, not the pilot's");
    assert_eq!(first.image, second.image);
    // A plan a program builds itself: level 0 explicitly, object sheets.
    let built = Plan {
        lod: Lod::Level(0),
        auto_slicing: None,
        auto_subsample: false,
        ..asked.clone()
    };
    let (f, r) = render(&s, &built).unwrap();
    assert_eq!(r.prepared().level, 0);
    let p = prepare(&(s.clone(), built.clone())).unwrap();
    let again = footprint_harness::pipeline::render_core(&p, &built)
        .unwrap()
        .0;
    assert_eq!(f.image, again);
}

#[test]
fn reframing_the_renderer_equals_opening_it_at_the_new_view() {
    let base = ["--size", "40x32", "--slicing", "object", "--lod", "0"];
    let args = parse_args(&base).unwrap();
    let mut r = Renderer::open(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
    let mut turned = base.to_vec();
    turned.extend_from_slice(&["--view", "50,10,0"]);
    let turned = parse_args(&turned).unwrap();
    r.reframe(&scene(&turned).unwrap()).unwrap();
    let (a, _) = r.frame().unwrap();
    let (b, _) = render(&scene(&turned).unwrap(), &plan(&turned).unwrap()).unwrap();
    assert_eq!(a.image, b.image);
}

#[test]
fn the_typed_defaults_are_the_command_lines() {
    let args = parse_args(&[]).unwrap();
    assert_eq!(Plan::default(), plan(&args).unwrap());
    // Scene holds shared handles (a program's volume, a pipe): compared as written out.
    let (typed, resolved) = (Scene::default(), scene(&args).unwrap());
    assert_eq!(format!("{typed:?}"), format!("{resolved:?}"));
}

#[test]
fn a_program_renders_a_typed_scene_and_plan_without_flags() {
    // What a library user writes: no flag string anywhere.
    let scene = Scene {
        size: (48, 48),
        view: [30.0, 20.0, 0.0],
        ..Scene::default()
    };
    let slabs = Plan {
        end: End::Slabs { thickness: 1.0 },
        auto_slicing: None,
        auto_subsample: false,
        threads: 1,
        ..Plan::default()
    };
    let (frame, r) = render(&scene, &slabs).unwrap();
    assert_eq!(r.plan().end, End::Slabs { thickness: 1.0 });
    assert_eq!(frame.image.len(), 48 * 48);
    // The same request as flags gives the same bits.
    let args = parse_args(&[
        "--size",
        "48x48",
        "--view",
        "30,20,0",
        "--slicing",
        "image",
        "--threads",
        "1",
    ])
    .unwrap();
    let (flags, _) = render(
        &footprint_harness::args::scene(&args).unwrap(),
        &plan(&args).unwrap(),
    )
    .unwrap();
    assert_eq!(frame.image, flags.image);
}

/// Supersampling is one decorator around whatever end draws the frame: for every end, a frame
/// at w × h supersampled 2× is the mean of the 2 × 2 blocks of the same end's frame at 2w × 2h
/// with no supersampling (the view scales with the size, so the wide frames are the same).
#[test]
fn supersampling_wraps_every_end_alike() {
    use footprint_harness::pipeline::stages::supersample::to_output;
    let ends: [&[&str]; 6] = [
        &["--slicing", "object"],
        &["--slicing", "object", "--accum", "fixed"],
        &["--slicing", "image", "--slab", "1"],
        &["--classification", "post"],
        &["--refine", "0.05"],
        &["--method", "reference"],
    ];
    for end in ends {
        let draw = |size: &str, k: &str| {
            let mut flags = vec!["--size", size, "--view", "30,20,0", "--lod", "0"];
            flags.extend_from_slice(&["--supersample", k]);
            flags.extend_from_slice(end);
            let args = parse_args(&flags).unwrap();
            let (frame, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
            (frame.image, r.prepared().supersample)
        };
        let (small, k) = draw("24x20", "2");
        assert_eq!(k, 2, "{end:?}: supersampled");
        let (wide, k) = draw("48x40", "1");
        assert_eq!(k, 1, "{end:?}: not supersampled");
        let averaged = to_output(wide, (24, 20), 2);
        let worst = small
            .iter()
            .zip(&averaged)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0f32, f32::max);
        assert!(small == averaged, "{end:?}: differs by up to {worst}");
        assert!(small.iter().any(|c| c[3] > 0.01), "{end:?}: visible");
    }
}

/// Turning a typed scene (what `--orbit` steps by) adds to the azimuth, or turns a view matrix
/// about the volume's vertical axis; a full turn in steps comes back to the start.
#[test]
fn a_turned_scene_adds_azimuth_or_turns_the_matrix() {
    let s = scene(&parse_args(&["--view", "30,20,5"]).unwrap()).unwrap();
    let t = s.turned(45.0);
    assert_eq!(t.view, [75.0, 20.0, 5.0]);
    assert_eq!((t.size, t.zoom, t.view_matrix), (s.size, s.zoom, None));
    let m = ["--view-matrix", "0.8,0,0.6,0,1,0,-0.6,0,0.8"];
    let s = scene(&parse_args(&m).unwrap()).unwrap();
    let quarter = s.turned(90.0).view_matrix.unwrap();
    assert!(
        quarter
            .iter()
            .zip(s.view_matrix.unwrap())
            .any(|(a, b)| (a - b).abs() > 0.5),
        "a quarter turn moves the matrix"
    );
    let mut back = s.clone();
    for _ in 0..4 {
        back = back.turned(90.0);
    }
    for (a, b) in back.view_matrix.unwrap().iter().zip(s.view_matrix.unwrap()) {
        assert!((a - b).abs() < 1e-5, "{a} against {b}");
    }
}

/// `--shading` is a typed part of the scene: parsed when the request is resolved (a bad one is
/// refused before any volume is read, naming the flag), spelled back as given, and completed
/// with the volume's spacing only when it is prepared.
#[test]
fn shading_is_resolved_with_the_scene() {
    use footprint::shade::Shading;
    use footprint_harness::scene::ShadingSpec;
    let bad = parse_args(&["/no/such/volume.nrrd", "--shading", "glossy"]).unwrap();
    let e = scene(&bad).unwrap_err().message;
    assert!(e.contains("--shading 'glossy'"), "{e}");
    for s in ["emission", "phong", "texture", "iso:0.5", "iso:-1200"] {
        let spec = ShadingSpec::parse(s).unwrap();
        assert_eq!(spec.to_string(), s);
        let ok = parse_args(&["--shading", s]).unwrap();
        assert_eq!(scene(&ok).unwrap().shading, spec);
    }
    for bad in ["iso:", "iso:nan", "iso:1e39", "Phong", ""] {
        assert!(ShadingSpec::parse(bad).is_err(), "{bad}");
    }
    match ShadingSpec::parse("iso:7").unwrap().at_spacing(0.5) {
        Shading::Iso {
            value, thickness, ..
        } => assert_eq!((value, thickness), (7.0, 0.75)),
        other => panic!("{other:?}"),
    }
}
