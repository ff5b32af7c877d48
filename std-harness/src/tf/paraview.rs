//! ParaView's colour-map presets: its exported `.json` files (`RGBPoints`, optional `Points` for
//! opacity, `ColorSpace`) and built-in presets named after ParaView's common ones.
//!
//! A preset's positions are mapped linearly from their own range onto the value window (t ∈ [0, 1]),
//! as ParaView does when it applies a preset to data ("rescale to data range"). Colours between
//! points are interpolated in the preset's `ColorSpace` — `RGB`, `HSV` (the shorter way round
//! the hue circle, as VTK's default), `Lab` and `Lab/CIEDE2000` (CIELAB, sRGB primaries, D65),
//! `Diverging` (Moreland's Msh interpolation, which puts white between two saturated ends) or
//! `Step` — and sampled at [`super::LUT_SIZE`] positions, which the lookup table then reads
//! exactly. Opacity: `Points` (x, opacity, midpoint, sharpness per point; the midpoint is honoured,
//! and sharpness 0 is linear, 1 a step, in between linear — an approximation of VTK's Hermite
//! shape), else ParaView's default for volumes, a ramp from 0 to 1 over the range.

use super::LUT_SIZE;
use crate::CliError;

/// ParaView's "Cool to Warm" (Moreland's diverging map), "Grayscale", "X Ray" and "Viridis
/// (matplotlib)" — the last as 33 points sampled from matplotlib's table (`viridis`, 256 entries),
/// which linear interpolation reproduces within 0.0097 per channel (measured against all 256).
const VIRIDIS: &[f32] = &[
    0.00000, 0.26700, 0.00487, 0.32942, 0.03125, 0.27702, 0.05034, 0.37572, 0.06250, 0.28233,
    0.09495, 0.41733, 0.09375, 0.28288, 0.13592, 0.45343, 0.12500, 0.27883, 0.17549, 0.48340,
    0.15625, 0.27059, 0.21407, 0.50705, 0.18750, 0.25897, 0.25154, 0.52474, 0.21875, 0.24497,
    0.28768, 0.53726, 0.25000, 0.22974, 0.32236, 0.54571, 0.28125, 0.21430, 0.35562, 0.55118,
    0.31250, 0.19943, 0.38761, 0.55464, 0.34375, 0.18556, 0.41857, 0.55675, 0.37500, 0.17272,
    0.44879, 0.55788, 0.40625, 0.16067, 0.47854, 0.55812, 0.43750, 0.14904, 0.50805, 0.55725,
    0.46875, 0.13777, 0.53749, 0.55491, 0.50000, 0.12757, 0.56695, 0.55056, 0.53125, 0.12057,
    0.59642, 0.54361, 0.56250, 0.12064, 0.62583, 0.53349, 0.59375, 0.13227, 0.65501, 0.51966,
    0.62500, 0.15785, 0.68376, 0.50169, 0.65625, 0.19657, 0.71183, 0.47922, 0.68750, 0.24607,
    0.73891, 0.45202, 0.71875, 0.30415, 0.76470, 0.41994, 0.75000, 0.36921, 0.78889, 0.38291,
    0.78125, 0.44014, 0.81114, 0.34097, 0.81250, 0.51599, 0.83116, 0.29428, 0.84375, 0.59584,
    0.84872, 0.24333, 0.87500, 0.67849, 0.86374, 0.18950, 0.90625, 0.76237, 0.87642, 0.13706,
    0.93750, 0.84556, 0.88732, 0.09970, 0.96875, 0.92611, 0.89733, 0.10407, 1.00000, 0.99325,
    0.90616, 0.14394,
];

/// A built-in ParaView-named preset, matched ignoring case, spaces, hyphens and underscores
/// (`"Cool to Warm"`, `cool-to-warm`): its name, colour space and RGB points.
fn builtin(name: &str) -> Option<(&'static str, &'static str, &'static [f32])> {
    let key: String = name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric())
        .collect::<String>()
        .to_ascii_lowercase();
    Some(match key.as_str() {
        "grayscale" | "greyscale" => (
            "Grayscale",
            "RGB",
            &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        ),
        "xray" => ("X Ray", "RGB", &[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
        "cooltowarm" => (
            "Cool to Warm",
            "Diverging",
            &[
                0.0,
                0.231_372_55,
                0.298_039_22,
                0.752_941_2,
                0.5,
                0.865,
                0.865,
                0.865,
                1.0,
                0.705_882_4,
                0.015_686_275,
                0.149_019_6,
            ],
        ),
        "viridis" | "viridismatplotlib" => ("Viridis (matplotlib)", "Lab", VIRIDIS),
        _ => return None,
    })
}

/// Names of the built-in ParaView presets.
pub const BUILTINS: [&str; 4] = ["Grayscale", "Cool to Warm", "Viridis", "X Ray"];

/// The control points (`t r g b a`, see [`super`]) of a built-in ParaView preset, if `name`
/// is one.
pub fn builtin_points(name: &str) -> Option<Vec<[f32; 5]>> {
    let (_, space, rgb) = builtin(name)?;
    let rgb: Vec<f64> = rgb.iter().map(|&v| f64::from(v)).collect();
    sample(&rgb, None, space).ok()
}

/// Parses a ParaView preset file (an array of presets, or one object): the first preset with
/// `RGBPoints`, or the one named `want`; `file` names the file in messages.
pub fn parse_json(text: &str, file: &str, want: Option<&str>) -> Result<Vec<[f32; 5]>, CliError> {
    let bad = |m: String| CliError::input(format!("{file}: {m}"));
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    let presets: Vec<&serde_json::Value> = match &v {
        serde_json::Value::Array(a) => a.iter().collect(),
        o @ serde_json::Value::Object(_) => vec![o],
        _ => {
            return Err(bad(
                "expected a ParaView preset (an object or an array of them)".into(),
            ))
        }
    };
    let names: Vec<&str> = presets
        .iter()
        .filter_map(|p| p.get("Name").and_then(|n| n.as_str()))
        .collect();
    let p = match want {
        Some(w) => presets
            .iter()
            .find(|p| p.get("Name").and_then(|n| n.as_str()) == Some(w))
            .ok_or_else(|| {
                bad(format!(
                    "no preset named '{w}' (the file has: {})",
                    names.join(", ")
                ))
            })?,
        None => presets
            .iter()
            .find(|p| p.get("RGBPoints").is_some())
            .ok_or_else(|| bad("no preset with RGBPoints".into()))?,
    };
    let numbers = |key: &str| -> Result<Option<Vec<f64>>, CliError> {
        match p.get(key) {
            None => Ok(None),
            Some(serde_json::Value::Array(a)) => a
                .iter()
                .map(|x| x.as_f64().filter(|x| x.is_finite()))
                .collect::<Option<Vec<f64>>>()
                .map(Some)
                .ok_or_else(|| bad(format!("{key}: every entry must be a finite number"))),
            Some(_) => Err(bad(format!("{key}: expected an array of numbers"))),
        }
    };
    let rgb = numbers("RGBPoints")?.ok_or_else(|| bad("the preset has no RGBPoints".into()))?;
    let alpha = numbers("Points")?;
    let space = p
        .get("ColorSpace")
        .and_then(|s| s.as_str())
        .unwrap_or("RGB");
    sample(&rgb, alpha.as_deref(), space).map_err(bad)
}

/// sRGB (0–1, gamma-encoded, as presets store colours) to CIELAB (D65).
fn lab(c: [f64; 3]) -> [f64; 3] {
    let lin = c.map(|v| {
        if v > 0.04045 {
            ((v + 0.055) / 1.055).powf(2.4)
        } else {
            v / 12.92
        }
    });
    let x = (0.4124 * lin[0] + 0.3576 * lin[1] + 0.1805 * lin[2]) / 0.950_47;
    let y = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2];
    let z = (0.0193 * lin[0] + 0.1192 * lin[1] + 0.9505 * lin[2]) / 1.088_83;
    let f = |t: f64| {
        if t > 0.008_856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIELAB (D65) back to sRGB, clamped to [0, 1].
fn rgb_of_lab(l: [f64; 3]) -> [f64; 3] {
    let fy = (l[0] + 16.0) / 116.0;
    let fx = fy + l[1] / 500.0;
    let fz = fy - l[2] / 200.0;
    let g = |f: f64| {
        if f.powi(3) > 0.008_856 {
            f.powi(3)
        } else {
            (f - 16.0 / 116.0) / 7.787
        }
    };
    let (x, y, z) = (g(fx) * 0.950_47, g(fy), g(fz) * 1.088_83);
    let lin = [
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    ];
    lin.map(|v| {
        let v = if v > 0.003_130_8 {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        } else {
            12.92 * v
        };
        v.clamp(0.0, 1.0)
    })
}

/// CIELAB to Moreland's Msh (magnitude, saturation, hue).
fn msh(l: [f64; 3]) -> [f64; 3] {
    let m = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
    let s = if m > 0.001 {
        (l[0] / m).clamp(-1.0, 1.0).acos()
    } else {
        0.0
    };
    let h = if s > 0.001 { l[2].atan2(l[1]) } else { 0.0 };
    [m, s, h]
}

fn lab_of_msh(c: [f64; 3]) -> [f64; 3] {
    [
        c[0] * c[1].cos(),
        c[0] * c[1].sin() * c[2].cos(),
        c[0] * c[1].sin() * c[2].sin(),
    ]
}

/// Moreland's hue adjustment: the hue an unsaturated end takes toward a saturated one.
fn adjust_hue(m: [f64; 3], unsat_m: f64) -> f64 {
    if m[0] >= unsat_m - 0.1 {
        return m[2];
    }
    let spin = m[1] * (unsat_m * unsat_m - m[0] * m[0]).sqrt() / (m[0] * m[1].sin());
    if m[2] > -0.3 * std::f64::consts::PI {
        m[2] + spin
    } else {
        m[2] - spin
    }
}

/// Moreland's diverging interpolation between sRGB colours `a` and `b` at `t`.
fn diverging(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    let (mut m1, mut m2) = (msh(lab(a)), msh(lab(b)));
    let mut t = t;
    if m1[1] > 0.05 && m2[1] > 0.05 && (m1[2] - m2[2]).abs() > std::f64::consts::PI / 3.0 {
        // Two saturated, distinct colours: pass through white in the middle.
        let mid = m1[0].max(m2[0]).max(88.0);
        if t < 0.5 {
            m2 = [mid, 0.0, 0.0];
            t *= 2.0;
        } else {
            m1 = [mid, 0.0, 0.0];
            t = 2.0 * t - 1.0;
        }
    }
    if m1[1] < 0.05 && m2[1] > 0.05 {
        m1[2] = adjust_hue(m2, m1[0]);
    } else if m2[1] < 0.05 && m1[1] > 0.05 {
        m2[2] = adjust_hue(m1, m2[0]);
    }
    let c = [0, 1, 2].map(|i| (1.0 - t) * m1[i] + t * m2[i]);
    rgb_of_lab(lab_of_msh(c))
}

fn hsv(c: [f64; 3]) -> [f64; 3] {
    let max = c[0].max(c[1]).max(c[2]);
    let min = c[0].min(c[1]).min(c[2]);
    let d = max - min;
    let h = if d <= 0.0 {
        0.0
    } else if max == c[0] {
        ((c[1] - c[2]) / d).rem_euclid(6.0) / 6.0
    } else if max == c[1] {
        ((c[2] - c[0]) / d + 2.0) / 6.0
    } else {
        ((c[0] - c[1]) / d + 4.0) / 6.0
    };
    [h, if max > 0.0 { d / max } else { 0.0 }, max]
}

fn rgb_of_hsv(c: [f64; 3]) -> [f64; 3] {
    let h = c[0].rem_euclid(1.0) * 6.0;
    let (s, v) = (c[1], c[2]);
    let f = h - h.floor();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match h.floor() as i32 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

/// The colour between `a` and `b` at `t` ∈ [0, 1] in colour space `space`.
fn mix(a: [f64; 3], b: [f64; 3], t: f64, space: &str) -> Result<[f64; 3], String> {
    Ok(match space.to_ascii_lowercase().as_str() {
        "rgb" => [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i])),
        "step" => {
            if t < 1.0 {
                a
            } else {
                b
            }
        }
        "hsv" => {
            let (mut x, y) = (hsv(a), hsv(b));
            if (y[0] - x[0]).abs() > 0.5 {
                x[0] += if y[0] > x[0] { 1.0 } else { -1.0 };
            }
            rgb_of_hsv([0, 1, 2].map(|i| x[i] + t * (y[i] - x[i])))
        }
        "lab" | "lab/ciede2000" | "cielab" => {
            let (x, y) = (lab(a), lab(b));
            rgb_of_lab([0, 1, 2].map(|i| x[i] + t * (y[i] - x[i])))
        }
        "diverging" => diverging(a, b, t),
        o => {
            return Err(format!(
                "ColorSpace '{o}' is not RGB, HSV, Lab, Lab/CIEDE2000, Diverging or Step"
            ))
        }
    })
}

/// Splits a flat list of `key` into points of four numbers (`fields` names them, for messages):
/// at least two, with positions (the first number) that do not decrease.
fn quads(v: &[f64], key: &str, fields: &str) -> Result<Vec<[f64; 4]>, String> {
    if v.len() < 8 || !v.len().is_multiple_of(4) {
        return Err(format!(
            "{key}: {} numbers; expected {fields} for at least two points",
            v.len()
        ));
    }
    let p: Vec<[f64; 4]> = v.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    if p.windows(2).any(|w| w[1][0] < w[0][0]) {
        return Err(format!("{key}: positions must not decrease"));
    }
    Ok(p)
}

/// The interval of `points` that holds `x`: the index j of its right end (the first point at or
/// past `x`, the last if none is; 0 when `x` is at or before the first point) and the fraction
/// t ∈ [0, 1] of the way from point j − 1 to j (1 for an interval of zero width; 0 when j = 0).
fn locate(points: &[[f64; 4]], x: f64) -> (usize, f64) {
    let j = points
        .iter()
        .position(|p| p[0] >= x)
        .unwrap_or(points.len() - 1);
    if j == 0 {
        return (0, 0.0);
    }
    let (p, q) = (points[j - 1], points[j]);
    let t = if q[0] > p[0] {
        fraction(x, p[0], q[0]).clamp(0.0, 1.0)
    } else {
        1.0
    };
    (j, t)
}

/// (x − a) / (b − a) for a < b, measured in halves (exact) so that positions spanning more than
/// f64 can hold (±10³⁰⁸) do not overflow to ∞ / ∞.
fn fraction(x: f64, a: f64, b: f64) -> f64 {
    (x * 0.5 - a * 0.5) / (b * 0.5 - a * 0.5)
}

/// The point a fraction `t` of the way from `a` to `b`, without overflow where b − a does.
fn between(a: f64, b: f64, t: f64) -> f64 {
    let span = b - a;
    if span.is_finite() {
        a + t * span
    } else {
        a * (1.0 - t) + b * t
    }
}

/// Samples a preset's colours (`x r g b` quadruples) and opacities (`x a midpoint sharpness`)
/// into [`LUT_SIZE`] control points over t ∈ [0, 1] (the colour range mapped onto the window).
fn sample(rgb: &[f64], alpha: Option<&[f64]>, space: &str) -> Result<Vec<[f32; 5]>, String> {
    let pts = quads(rgb, "RGBPoints", "x r g b")?;
    if pts
        .iter()
        .any(|p| p[1..].iter().any(|c| !(0.0..=1.0).contains(c)))
    {
        return Err("RGBPoints: colours must be in [0, 1]".into());
    }
    let (x0, x1) = (pts[0][0], pts[pts.len() - 1][0]);
    if x1 <= x0 {
        return Err("RGBPoints: the positions span no range".into());
    }
    let ops = match alpha {
        None => None,
        Some(a) => {
            let p = quads(a, "Points", "x opacity midpoint sharpness")?;
            if p.iter().any(|q| !(0.0..=1.0).contains(&q[1])) {
                return Err("Points: opacities must be in [0, 1]".into());
            }
            Some(p)
        }
    };
    let colour = |x: f64| -> Result<[f64; 3], String> {
        let (j, t) = locate(&pts, x);
        if j == 0 {
            return Ok([pts[0][1], pts[0][2], pts[0][3]]);
        }
        let (p, q) = (pts[j - 1], pts[j]);
        mix([p[1], p[2], p[3]], [q[1], q[2], q[3]], t, space)
    };
    let opacity = |x: f64| -> f64 {
        let Some(o) = &ops else {
            return fraction(x, x0, x1).clamp(0.0, 1.0);
        };
        let (j, t) = locate(o, x);
        if j == 0 || x >= o[o.len() - 1][0] {
            return o[j][1];
        }
        let (p, q) = (o[j - 1], o[j]);
        // The interval's midpoint and sharpness are its left point's.
        let (m, sharp) = (p[2].clamp(1e-6, 1.0 - 1e-6), p[3]);
        let v = if sharp >= 0.99 {
            if t < m {
                0.0
            } else {
                1.0
            }
        } else if t < m {
            0.5 * t / m
        } else {
            0.5 + 0.5 * (t - m) / (1.0 - m)
        };
        p[1] + v * (q[1] - p[1])
    };
    (0..LUT_SIZE)
        .map(|i| {
            let t = i as f64 / (LUT_SIZE - 1) as f64;
            let x = between(x0, x1, t);
            let c = colour(x)?;
            Ok([
                t as f32,
                c[0] as f32,
                c[1] as f32,
                c[2] as f32,
                opacity(x) as f32,
            ])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_round_trips_and_diverging_passes_through_white() {
        for c in [
            [0.2, 0.5, 0.9],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
        ] {
            let back = rgb_of_lab(lab(c));
            for i in 0..3 {
                assert!((back[i] - c[i]).abs() < 2e-3, "{c:?} -> {back:?}");
            }
        }
        let p = builtin_points("Cool to Warm").unwrap();
        let mid = p[LUT_SIZE / 2];
        // Near the midpoint: the light grey ParaView shows (0.865).
        assert!(
            mid[1..4].iter().all(|&c| (c - 0.865).abs() < 0.03),
            "{mid:?}"
        );
        assert_eq!(p[0][1..4], [0.231_372_55, 0.298_039_22, 0.752_941_2]);
        assert!((p[0][4], p[LUT_SIZE - 1][4]) == (0.0, 1.0));
    }
}
