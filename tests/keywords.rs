//! A request built from typed keywords (the Python package's path, issue 76) resolves to the same
//! scene and plan as the same flags, meets the same rules between fields (checked on the values,
//! in `args::resolve`, not by clap), and refuses the values the flags refuse.

use footprint_harness::args::keywords::{defaults, from_keywords};
use footprint_harness::args::{parse_args, plan, scene, RenderArgs, Value};
use footprint_harness::commands::bench::BenchArgs;
use footprint_harness::commands::verify::VerifyArgs;

fn int(i: i64) -> Value {
    Value::Int(i)
}
fn float(x: f64) -> Value {
    Value::Float(x)
}
fn text(t: &str) -> Value {
    Value::Text(t.into())
}
fn list(v: &[Value]) -> Value {
    Value::List(v.to_vec())
}

fn keyworded(pairs: &[(&str, Value)]) -> Result<RenderArgs, String> {
    from_keywords(pairs.iter().map(|(k, v)| (*k, v))).map_err(|e| e.to_string())
}

/// The scene and plan (or the refusal) of a request, as text to compare.
fn resolved(args: &RenderArgs) -> String {
    match (scene(args), plan(args)) {
        (Ok(s), Ok(p)) => format!("{s:?}\n{p:?}"),
        (Err(e), _) | (_, Err(e)) => format!("refused: {e}"),
    }
}

#[test]
fn keywords_resolve_as_the_same_flags_do() {
    type Case<'a> = (Vec<&'a str>, Vec<(&'a str, Value)>);
    let cases: Vec<Case> = vec![
        (vec![], vec![]),
        (
            vec![
                "--size",
                "48x40",
                "--view",
                "30,20,0",
                "--shading",
                "phong",
                "--lod",
                "0",
            ],
            vec![
                ("size", list(&[int(48), int(40)])),
                ("view", list(&[int(30), float(20.0), int(0)])),
                ("shading", text("phong")),
                ("lod", int(0)),
            ],
        ),
        (
            vec![
                "--slicing",
                "image",
                "--slab",
                "2",
                "--view",
                "+x",
                "--zoom",
                "1.5",
            ],
            vec![
                ("slicing", text("image")),
                ("slab", int(2)),
                ("view", text("+x")),
                ("zoom", float(1.5)),
            ],
        ),
        (
            vec![
                "--perspective",
                "40",
                "--eye-distance",
                "300",
                "--supersample",
                "2",
            ],
            vec![
                ("perspective", int(40)),
                ("eye_distance", float(300.0)),
                ("supersample", int(2)),
            ],
        ),
        (
            vec![
                "--quality",
                "40",
                "--quality-reference",
                "continuous",
                "--threads",
                "2",
            ],
            vec![
                ("quality", int(40)),
                ("quality_reference", text("continuous")),
                ("threads", int(2)),
            ],
        ),
        (
            vec![
                "--classification",
                "post",
                "--slab-post",
                "0.5",
                "--window",
                "0,100",
            ],
            vec![
                ("classification", text("post")),
                ("slab_post", float(0.5)),
                ("window", list(&[int(0), int(100)])),
            ],
        ),
        (
            vec![
                "--cull",
                "0.01",
                "--subsample",
                "auto",
                "--accum",
                "float",
                "--table",
                "65",
            ],
            vec![
                ("cull", float(0.01)),
                ("subsample", text("auto")),
                ("accum", text("float")),
                ("table", int(65)),
            ],
        ),
        (
            vec!["--refine", "0.1", "--refine-sheets", "--scene-size", "16"],
            vec![
                ("refine", float(0.1)),
                ("refine_sheets", Value::Bool(true)),
                ("scene_size", int(16)),
            ],
        ),
        (
            vec![
                "--kernel", "bilinear", "--method", "direct", "--lookup", "nearest",
            ],
            vec![
                ("kernel", text("bilinear")),
                ("method", text("direct")),
                ("lookup", text("nearest")),
            ],
        ),
        (
            vec![
                "vol.raw",
                "--dims",
                "4,5,6",
                "--type",
                "u16",
                "--endian",
                "big",
                "--spacing",
                "1,1,2",
            ],
            vec![
                ("volume", text("vol.raw")),
                ("dims", list(&[int(4), int(5), int(6)])),
                ("type", text("u16")),
                ("endian", text("big")),
                ("spacing", list(&[int(1), int(1), int(2)])),
            ],
        ),
    ];
    for (flags, keywords) in cases {
        let by_flags = resolved(&parse_args(&flags).unwrap());
        let by_keywords = resolved(&keyworded(&keywords).unwrap());
        assert!(!by_flags.starts_with("refused"), "{flags:?}: {by_flags}");
        assert_eq!(by_flags, by_keywords, "{flags:?}");
    }
}

#[test]
fn the_rules_between_fields_hold_for_keywords() {
    for (keywords, needle) in [
        (vec![("eye_distance", int(300))], "needs --perspective"),
        (vec![("refine_sheets", Value::Bool(true))], "needs --refine"),
        (
            vec![("quality_reference", text("continuous"))],
            "needs --quality",
        ),
        (
            vec![("quality", int(40)), ("table", int(65))],
            "--table cannot be used with --quality",
        ),
        (
            vec![("quality", int(40)), ("slab", int(2))],
            "--slab cannot be used with --quality",
        ),
        (
            vec![("quality", int(40)), ("refine", float(0.1))],
            "--refine cannot be used with --quality",
        ),
        (
            vec![("quality", int(40)), ("accum", text("fixed"))],
            "--accum cannot be used with --quality",
        ),
    ] {
        let args = keyworded(&keywords).unwrap();
        let e = plan(&args).expect_err("refused").to_string();
        assert!(e.contains(needle), "{keywords:?}: {e}");
    }
    // The same rules refuse the same flags (clap or the resolver, whichever comes first).
    for flags in [
        &["--eye-distance", "300"][..],
        &["--refine-sheets"],
        &["--quality", "40", "--refine", "0.1"],
    ] {
        let refused = parse_args(flags).map_or(true, |a| plan(&a).is_err());
        assert!(refused, "{flags:?}");
    }
}

#[test]
fn keywords_refuse_what_the_flags_refuse() {
    for (key, value, needle) in [
        ("size", list(&[int(0), int(5)]), "1..=16384"),
        ("size", list(&[int(5)]), "expected 2 numbers"),
        ("size", text("big"), "not WxH"),
        ("lod", int(99), "expected auto or a level"),
        ("lod", text("coarse"), "expected auto or a level"),
        ("supersample", int(9), "1..=8"),
        ("zoom", int(-1), "positive"),
        ("zoom", float(f64::NAN), "not finite"),
        ("zoom", text("2"), "expected a number"),
        ("perspective", int(180), "field of view"),
        (
            "slicing",
            text("diagonal"),
            "expected one of object, image, auto",
        ),
        ("threads", float(2.5), "whole number"),
        ("threads", int(-2), "whole number"),
        ("cull", float(1.5), "strictly between 0 and 1"),
        ("depth", int(12), "8 or 16"),
        ("dims", list(&[int(4), int(0), int(4)]), "at least 1"),
        ("spacing", list(&[int(1), int(-1), int(1)]), "not positive"),
        ("refine", float(-1.0), "≥ 0"),
        ("scene_size", int(1), "2..=512"),
        ("refine_sheets", int(1), "True or False"),
        ("glossiness", int(1), "unknown keyword 'glossiness'"),
        ("eye-distance", int(1), "unknown keyword"),
    ] {
        let e = keyworded(&[(key, value.clone())]).expect_err("refused");
        assert!(e.contains(needle), "{key}={value}: {e}");
        assert!(e.contains(key), "the error names the keyword: {e}");
    }
}

#[test]
fn the_commands_take_their_own_keywords_first() {
    let v: VerifyArgs = from_keywords([
        ("min_psnr", &int(40)),
        ("reference", &text("continuous")),
        ("size", &list(&[int(32), int(32)])),
    ])
    .unwrap();
    assert_eq!(v.min_psnr, Some(40.0));
    assert_eq!(v.render.size, (32, 32));
    let b: BenchArgs = from_keywords([("frames", &int(3)), ("orbit", &float(2.5))]).unwrap();
    assert_eq!((b.frames, b.orbit), (3, 2.5));
    // Defaults are the command line's.
    let d: BenchArgs = defaults();
    assert_eq!(d.frames, 10);
    assert_eq!(resolved(&d.render), resolved(&parse_args(&[]).unwrap()));
    let e = from_keywords::<BenchArgs>([("min_psnr", &int(40))])
        .expect_err("verify's keyword is not bench's");
    assert!(e.to_string().contains("unknown keyword"), "{e}");
}
