#![no_main]
//! Fuzz target: the core's transfer function over any window (any `f32` bits, windows wider than
//! `f32` holds and narrower than its smallest step included) and any table, on any values. A
//! checked function's lookup is straight RGBA in [0, 1] (never NaN), non-finite values are
//! transparent, the bound below which everything is transparent holds, and where the visible
//! values are one interval it holds exactly the values the lookup makes visible.
use footprint::shade::TransferFunction;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((head, rest)) = data.split_first_chunk::<9>() else {
        return;
    };
    let n = 2 + usize::from(head[0] % 63);
    let lo = f32::from_le_bytes([head[1], head[2], head[3], head[4]]);
    let hi = f32::from_le_bytes([head[5], head[6], head[7], head[8]]);
    if rest.len() < 4 * n {
        return;
    }
    let (entries, probes) = rest.split_at(4 * n);
    let lut: Vec<[f32; 4]> = entries
        .chunks_exact(4)
        .map(|c| [0, 1, 2, 3].map(|i| f32::from(c[i]) / 255.0))
        .collect();
    let tf = TransferFunction { lut: &lut, lo, hi };
    if tf.check().is_err() {
        return;
    }
    let clear_below = tf.transparent_at_or_below();
    let interval = tf.visible_interval();
    let mut values: Vec<f32> = probes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    values.extend([lo, hi, f32::MAX, -f32::MAX, 0.0, f32::INFINITY, f32::NAN]);
    if let Some((a, b)) = interval {
        values.extend([a, b]);
    }
    for v in values {
        let c = tf.lookup(v);
        assert!(
            c.iter().all(|x| (-1e-6..=1.0 + 1e-6).contains(x)),
            "lookup({v}) = {c:?} over [{lo}, {hi}]"
        );
        if !v.is_finite() {
            assert_eq!(c, [0.0; 4]);
            continue;
        }
        if v <= clear_below {
            assert_eq!(c[3], 0.0, "{v} at or below {clear_below} is transparent");
        }
        if let Some((a, b)) = interval {
            assert_eq!(a <= v && v <= b, c[3] > 0.0, "{v} against [{a}, {b}]");
        }
    }
});
