//! Transfer-function presets and the sampling of control points into a lookup table: what
//! `footprint render --tf NAME` uses, so a library caller gets the same colours.
//!
//! A control point is `[t, r, g, b, a]`: t ∈ [0, 1] the position in the value window, colour
//! straight (not premultiplied), a the opacity of a slab one world unit thick (see
//! [`crate::shade`]). Points are in increasing t.

/// Entries in the lookup tables the presets are sampled into (the CLI's size).
pub const LUT_SIZE: usize = 256;

/// A built-in transfer function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Preset {
    /// Grey linear ramp: colour and opacity rise together (`grey`).
    Grey,
    /// CT: air transparent, skin a faint tan veil, bone near-opaque ivory (`ct-bone-skin`).
    CtBoneSkin,
    /// Density, after the paper's ozone and orbital images: blue (low) → green → red (high)
    /// (`density`).
    Density,
}

const GREY: [[f32; 5]; 2] = [[0.0, 0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0, 1.0]];
const CT_BONE_SKIN: [[f32; 5]; 7] = [
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [0.18, 0.0, 0.0, 0.0, 0.0],
    [0.24, 0.9, 0.62, 0.5, 0.06],
    [0.34, 0.9, 0.62, 0.5, 0.03],
    [0.45, 0.9, 0.75, 0.6, 0.0],
    [0.55, 0.95, 0.92, 0.85, 0.35],
    [1.0, 1.0, 1.0, 0.95, 0.9],
];
const DENSITY: [[f32; 5]; 5] = [
    [0.0, 0.0, 0.0, 1.0, 0.0],
    [0.08, 0.1, 0.2, 1.0, 0.01],
    [0.35, 0.1, 0.9, 0.3, 0.06],
    [0.7, 1.0, 0.3, 0.1, 0.25],
    [1.0, 1.0, 0.1, 0.05, 0.6],
];

impl Preset {
    /// Every preset, in the order the CLI lists them.
    pub const ALL: [Preset; 3] = [Preset::Grey, Preset::CtBoneSkin, Preset::Density];

    /// The name `--tf` takes.
    pub const fn name(self) -> &'static str {
        match self {
            Preset::Grey => "grey",
            Preset::CtBoneSkin => "ct-bone-skin",
            Preset::Density => "density",
        }
    }

    /// The preset called `name` (as [`Preset::name`] spells it).
    pub fn from_name(name: &str) -> Option<Preset> {
        Preset::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Its control points `[t, r, g, b, a]`.
    pub const fn points(self) -> &'static [[f32; 5]] {
        match self {
            Preset::Grey => &GREY,
            Preset::CtBoneSkin => &CT_BONE_SKIN,
            Preset::Density => &DENSITY,
        }
    }

    /// Its lookup table of [`LUT_SIZE`] straight RGBA entries ([`sample_points`] of its points,
    /// evaluated at compile time: the same bits).
    pub const fn lut(self) -> &'static [[f32; 4]; LUT_SIZE] {
        match self {
            Preset::Grey => &GREY_LUT,
            Preset::CtBoneSkin => &CT_BONE_SKIN_LUT,
            Preset::Density => &DENSITY_LUT,
        }
    }
}

static GREY_LUT: [[f32; 4]; LUT_SIZE] = sampled(&GREY);
static CT_BONE_SKIN_LUT: [[f32; 4]; LUT_SIZE] = sampled(&CT_BONE_SKIN);
static DENSITY_LUT: [[f32; 4]; LUT_SIZE] = sampled(&DENSITY);

const fn sampled(points: &[[f32; 5]]) -> [[f32; 4]; LUT_SIZE] {
    let mut out = [[0.0; 4]; LUT_SIZE];
    let mut i = 0;
    while i < LUT_SIZE {
        out[i] = entry(points, i as f32 / (LUT_SIZE - 1) as f32);
        i += 1;
    }
    out
}

/// The table entry at position `t` of non-empty `points`: linear between the points around it,
/// constant beyond the ends.
const fn entry(points: &[[f32; 5]], t: f32) -> [f32; 4] {
    let mut j = 0;
    while j < points.len() && points[j][0] < t {
        j += 1;
    }
    if j == points.len() {
        j -= 1;
    }
    let (p, q) = if j == 0 {
        (points[0], points[0])
    } else {
        (points[j - 1], points[j])
    };
    let f = if q[0] > p[0] {
        let f = (t - p[0]) / (q[0] - p[0]);
        if f < 0.0 {
            0.0
        } else if f > 1.0 {
            1.0
        } else {
            f
        }
    } else {
        0.0
    };
    [
        p[1] + f * (q[1] - p[1]),
        p[2] + f * (q[2] - p[2]),
        p[3] + f * (q[3] - p[3]),
        p[4] + f * (q[4] - p[4]),
    ]
}

/// Samples control points into `out` (entry i at t = i / (len − 1); one entry: t = 0): linear
/// between points, constant beyond the ends. `points` must have t increasing; an empty `points`
/// leaves `out` as it is.
pub fn sample_points(points: &[[f32; 5]], out: &mut [[f32; 4]]) {
    if points.is_empty() {
        return;
    }
    let last = out.len().saturating_sub(1).max(1);
    for (i, e) in out.iter_mut().enumerate() {
        *e = entry(points, i as f32 / last as f32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_luts_span_the_points() {
        for p in Preset::ALL {
            assert_eq!(Preset::from_name(p.name()), Some(p));
            let lut = p.lut();
            let mut runtime = [[0.0; 4]; LUT_SIZE];
            sample_points(p.points(), &mut runtime);
            assert_eq!(&runtime, lut, "compile-time and run-time sampling agree");
            let (a, b) = (p.points()[0], p.points()[p.points().len() - 1]);
            // The ends (the last one interpolated at f = 1: within rounding).
            assert_eq!(lut[0], [a[1], a[2], a[3], a[4]]);
            for c in 0..4 {
                assert!((lut[LUT_SIZE - 1][c] - b[c + 1]).abs() < 1e-6);
            }
        }
        assert_eq!(Preset::from_name("fog"), None);
        // The grey ramp is the identity on every channel.
        let grey = Preset::Grey.lut();
        assert!((grey[51][3] - 0.2).abs() < 1e-6);
    }
}
