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
    let want: Vec<[f32; 4]> = direct.iter().map(|c| c.map(|x| x as f32)).collect();
    assert_eq!(frame.image, want);
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
