//! The continuous model of a projection (`--blend mip|minip|average`; `footprint::render::post`'s
//! `blend` module defines it): one ray's maximum, minimum or average of the normalised value
//! reconstruction over its chord, marched in f64.
//!
//! **Quadrature.** The chord is cut into equal steps of at most `h` (world units) and the field
//! is sampled at their midpoints. The average is the midpoint rule (second order in h). The
//! maximum (minimum) is the vertex of the parabola through the extreme sample and its two
//! neighbours (the extreme sample itself at the chord's ends): exact where the field is locally
//! quadratic, third order in h. The caller halves h until two passes agree
//! (`super::continuous`'s convergence).

use super::field::{Field, Taps};
use footprint::render::Blend;
use footprint::shade::Shader;
use glam::DVec3;

/// One ray's running projection in f64: the extreme sample and its neighbours, or the sum.
struct Fold {
    blend: Blend,
    best: f64,
    before: f64,
    after: f64,
    last: f64,
    sum: f64,
    count: f64,
}

impl Fold {
    fn new(blend: Blend) -> Self {
        Fold {
            blend,
            best: f64::NAN,
            before: f64::NAN,
            after: f64::NAN,
            last: f64::NAN,
            sum: 0.0,
            count: 0.0,
        }
    }

    fn add(&mut self, v: f64) {
        self.sum += v;
        self.count += 1.0;
        let better = match self.blend {
            Blend::Maximum => v > self.best,
            _ => v < self.best,
        };
        if self.best.is_nan() || better {
            (self.before, self.best, self.after) = (self.last, v, f64::NAN);
        } else if self.after.is_nan() {
            self.after = v;
        }
        self.last = v;
    }

    fn value(&self) -> Option<f64> {
        if self.count == 0.0 {
            return None;
        }
        Some(match self.blend {
            Blend::Average => self.sum / self.count,
            _ if self.before.is_nan() || self.after.is_nan() => self.best,
            _ => {
                let d2 = self.after - 2.0 * self.best + self.before;
                let d1 = self.after - self.before;
                if d2 == 0.0 {
                    self.best
                } else {
                    self.best - d1 * d1 / (8.0 * d2)
                }
            }
        })
    }
}

/// The projection along g0 + t·dg (grid units) over [t0, t1] (`per_t` world units per unit of
/// t) with steps of at most `h` world units; `None` where no sample has a weight.
fn project(
    field: &Field<'_>,
    blend: Blend,
    (g0, dg): (DVec3, DVec3),
    (t0, t1): (f64, f64),
    per_t: f64,
    h: f64,
    taps: &mut Taps,
) -> Option<f64> {
    if !(t1 > t0) {
        return None;
    }
    let steps = (((t1 - t0) * per_t / h).ceil() as usize).max(1);
    let step = (t1 - t0) / steps as f64;
    let mut fold = Fold::new(blend);
    for k in 0..steps {
        let tm = t0 + (k as f64 + 0.5) * step;
        if let Some(v) = field.value_at(g0 + dg * tm, taps) {
            fold.add(v);
        }
    }
    fold.value()
}

/// A projecting ray's pixel over `bg` (premultiplied RGBA): the value [`project`]ed along
/// `ray` ((g0, dg), (t0, t1), per_t) with steps of at most `h`, classified by `shader`'s
/// transfer function (its colour and opacity, unshaded: the renderer's
/// `footprint::render::post::Classify::projection`); `bg` where the ray has no value.
pub(super) fn pixel(
    field: &Field<'_>,
    shader: &Shader<'_>,
    blend: Blend,
    (line, span, per_t): ((DVec3, DVec3), (f64, f64), f64),
    h: f64,
    taps: &mut Taps,
    bg: [f64; 4],
) -> [f64; 4] {
    let p = project(field, blend, line, span, per_t, h, taps)
        .map_or([0.0; 4], |v| shader.pixel(v as f32).map(f64::from));
    let t = 1.0 - p[3];
    [0, 1, 2, 3].map(|c| p[c] + t * bg[c])
}

#[cfg(test)]
mod tests {
    use super::{Blend, Fold};

    /// The f64 fold agrees with the core's f32 one on the same samples.
    #[test]
    fn the_reference_fold_is_the_cores() {
        let samples = [0.3, 0.9, 1.7, 2.2, 2.0, 1.1, 0.4, 0.8];
        for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
            let mut fold = Fold::new(blend);
            let mut state = blend.start();
            for v in samples {
                fold.add(v);
                blend.fold(&mut state, v as f32, 1.0);
            }
            let (a, b) = (
                fold.value().unwrap(),
                f64::from(blend.projected(state).unwrap()),
            );
            assert!((a - b).abs() < 1e-5, "{blend:?}: {a} {b}");
        }
    }
}
