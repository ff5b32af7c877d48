//! ParaView presets: an exported `.json` (RGBPoints, Points, ColorSpace) samples to the transfer
//! function its points define; the built-in ParaView-named presets resolve; malformed presets are
//! one line on stderr, exit 2 and no output file.

use footprint_harness::tf;
use footprint_suite::tmpdir;

#[test]
fn an_exported_preset_samples_to_its_points() {
    let d = tmpdir("pv-preset");
    let f = d.join("p.json");
    // Positions in data units (100…300), mapped onto the window; RGB interpolation; opacity with a
    // midpoint of 0.25 on the first interval and a step (sharpness 1) on the second.
    std::fs::write(
        &f,
        r#"[{"ColorSpace":"RGB","Name":"test","RGBPoints":[100,0,0,1, 200,1,0,0, 300,1,1,1],
            "Points":[100,0,0.25,0, 200,0.5,0.5,1, 300,1,0.5,0]}]"#,
    )
    .unwrap();
    let p = tf::load(f.to_str().unwrap()).unwrap();
    let lut = tf::lut(&p);
    let at = |t: f32| lut[(t * (tf::LUT_SIZE - 1) as f32).round() as usize];
    let close = |a: [f32; 4], b: [f32; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 0.01);
    assert!(close(at(0.0), [0.0, 0.0, 1.0, 0.0]), "{:?}", at(0.0));
    assert!(close(at(0.5), [1.0, 0.0, 0.0, 0.5]), "{:?}", at(0.5));
    assert!(close(at(1.0), [1.0, 1.0, 1.0, 1.0]), "{:?}", at(1.0));
    // First interval, a quarter in: the midpoint, so half the opacity step (0.25); colour linear.
    let q = at(0.125);
    assert!(
        (q[3] - 0.25).abs() < 0.01 && (q[0] - 0.25).abs() < 0.01,
        "{q:?}"
    );
    // Second interval: a step at its midpoint.
    assert!((at(0.74)[3] - 0.5).abs() < 0.01 && (at(0.76)[3] - 1.0).abs() < 0.01);
    // Without Points: ParaView's default ramp.
    std::fs::write(&f, r#"{"RGBPoints":[0,0,0,0, 1,1,1,1]}"#).unwrap();
    let lut = tf::lut(&tf::load(f.to_str().unwrap()).unwrap());
    assert!((lut[128][3] - 128.0 / 255.0).abs() < 1e-3);
    // A named preset from a file of several.
    std::fs::write(
        &f,
        r#"[{"Name":"a","RGBPoints":[0,0,0,0,1,1,1,1]},{"Name":"b","RGBPoints":[0,1,0,0,1,1,0,0]}]"#,
    )
    .unwrap();
    let b = tf::load(&format!("{}#b", f.display())).unwrap();
    assert_eq!(b[0][1..4], [1.0, 0.0, 0.0]);
    let msg = tf::load(&format!("{}#c", f.display())).unwrap_err().message;
    assert!(msg.contains("a, b"), "{msg}");
    // Built-ins, by ParaView's names or ours.
    for name in [
        "Grayscale",
        "Cool to Warm",
        "cool-to-warm",
        "Viridis",
        "X Ray",
        "xray",
    ] {
        let p = tf::load(name).unwrap_or_else(|e| panic!("{name}: {}", e.message));
        assert_eq!(p.len(), tf::LUT_SIZE);
    }
    let x = tf::load("X Ray").unwrap();
    assert_eq!((x[0][1], x[tf::LUT_SIZE - 1][1]), (1.0, 0.0));
    // Viridis ends: matplotlib's first and last entries.
    let v = tf::load("Viridis").unwrap();
    assert!((v[0][1] - 0.267).abs() < 1e-3 && (v[tf::LUT_SIZE - 1][3] - 0.144).abs() < 1e-3);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn malformed_presets_fail_cleanly() {
    let d = tmpdir("pv-bad");
    let out = d.join("out.png");
    for (name, text, word) in [
        ("not-json.json", "{RGBPoints: [", "JSON"),
        (
            "no-rgb.json",
            r#"[{"Name":"x","Points":[0,0,0.5,0,1,1,0.5,0]}]"#,
            "RGBPoints",
        ),
        ("odd.json", r#"{"RGBPoints":[0,0,0,0,1,1,1]}"#, "RGBPoints"),
        (
            "space.json",
            r#"{"ColorSpace":"CMYK","RGBPoints":[0,0,0,0,1,1,1,1]}"#,
            "ColorSpace",
        ),
        ("range.json", r#"{"RGBPoints":[0,0,0,0,0,1,1,1]}"#, "range"),
        (
            "colour.json",
            r#"{"RGBPoints":[0,0,0,0,1,2,1,1]}"#,
            "[0, 1]",
        ),
        (
            "strings.json",
            r#"{"RGBPoints":[0,"a",0,0,1,1,1,1]}"#,
            "number",
        ),
        (
            "opacity.json",
            r#"{"RGBPoints":[0,0,0,0,1,1,1,1],"Points":[0,0,0.5,0,1,7,0.5,0]}"#,
            "opacities",
        ),
        ("scalar.json", "42", "preset"),
    ] {
        let f = d.join(name);
        std::fs::write(&f, text).unwrap();
        let msg = tf::load(f.to_str().unwrap()).unwrap_err().message;
        assert!(msg.contains(word) && !msg.contains('\n'), "{name}: {msg}");
        let code = footprint_harness::run(vec![
            "footprint",
            "render",
            "--size",
            "32x32",
            "--tf",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}");
        assert!(!out.exists(), "{name}: output written");
    }
    std::fs::remove_dir_all(&d).unwrap();
}
