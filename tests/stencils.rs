//! Phase stencils (`footprint::stencil`) at every footprint size they now cover (half-extent
//! 1.5 … 60 px, phases lowered for wide footprints), against brute force:
//!
//! - the splat visits only the per-row ranges the stencils store, yet every pixel equals, bit for
//!   bit, what brute force over the whole box gives: for a narrow footprint the blend of the four
//!   phase stencils computed here from the sampler (so the ranges skip only exact zeros); for a
//!   wide one the same blend inside the support where all four corners are non-zero, the sampler
//!   itself at the support's edge, and zero outside it;
//! - read at the nearest phase instead ([`PhaseLookup::Nearest`]), every pixel of a narrow
//!   footprint is, bit for bit, the nearest corner stencil's entry (a wide one is still blended);
//! - the weights stay within the blending bound of the per-pixel table walk (`splat_rows` through
//!   the same view table), and the total deposit matches it.

use footprint::geometry::{Footprint, FootprintOptions};
use footprint::splat::{splat, ImageMut};
use footprint::stencil::{
    self, minor_semi_axis, PhaseLookup, Stencils, BLEND_REACH, DEFAULT_PHASES, MAX_STENCIL_SIDE,
    PHASE_REACH,
};
use footprint::{GenericTable, Kernel, Lookup, ViewTable};
use glam::Mat3;

/// A footprint of the default Gaussian for a voxel grid scaled by `s` px, stretched `a`:1 along
/// x and turned `deg` in the screen.
fn footprint(s: f32, a: f32, deg: f32) -> Footprint {
    let (sin, cos) = deg.to_radians().sin_cos();
    let turn = Mat3::from_cols_array(&[cos, sin, 0.0, -sin, cos, 0.0, 0.0, 0.0, 1.0]);
    let g2s = turn * Mat3::from_diagonal(glam::Vec3::new(s * a, s, s));
    Footprint::new(&Kernel::PAPER_GAUSSIAN, &g2s, FootprintOptions::default()).unwrap()
}

const SHAPES: [(f32, f32, f32); 9] = [
    (0.5, 1.0, 0.0),
    (0.9, 1.0, 0.0),
    (1.6, 1.0, 0.0),
    (1.6, 3.0, 30.0),
    (3.0, 1.0, 0.0),
    (3.0, 4.0, 60.0),
    (8.0, 1.0, 0.0),
    (20.0, 1.5, 20.0),
    (5.0, 4.0, 30.0), // long and thin: edged (side 59, P = 17)
];

const CENTRES: [[f32; 2]; 5] = [
    [100.0, 100.0],
    [100.37, 99.81],
    [99.03, 100.96],
    [100.5, 100.5],
    [3.2, 197.7], // clipped at the left and bottom edges
];

const SIZE: usize = 200;

fn phase(c: f32, i: i64, p: usize) -> (usize, f32) {
    let t = (c - i as f32) * p as f32;
    let k = (t.max(0.0) as usize).min(p - 1);
    (k, (t - k as f32).clamp(0.0, 1.0))
}

/// Checks the splat of footprint (`s`, `a`, `deg`) ([`footprint`]) at every [`CENTRES`] against
/// brute force, bit for bit, with each [`PhaseLookup`]; returns its box side and whether it is
/// edged (`None` when no stencils apply).
fn check_against_brute_force(
    generic: &GenericTable<129>,
    s: f32,
    a: f32,
    deg: f32,
) -> Option<(usize, bool)> {
    let r = check_lookup(generic, (s, a, deg), PhaseLookup::Blend);
    assert_eq!(r, check_lookup(generic, (s, a, deg), PhaseLookup::Nearest));
    r
}

/// [`check_against_brute_force`] with one `lookup`.
fn check_lookup(
    generic: &GenericTable<129>,
    (s, a, deg): (f32, f32, f32),
    lookup: PhaseLookup,
) -> Option<(usize, bool)> {
    let fp = footprint(s, a, deg);
    let table = ViewTable::<129>::build(&fp, generic, Lookup::Bilinear, Lookup::Bilinear);
    let Some(len) = stencil::len_for(&fp, DEFAULT_PHASES) else {
        // Only a long thin footprint may be left to the table walk.
        let e = fp.half_extent[0].max(fp.half_extent[1]);
        assert!(
            e > 2.0 * minor_semi_axis(&fp),
            "scale {s}, {a}:1 at {deg}°: no stencils"
        );
        return None;
    };
    let mut buffer = vec![0.0f32; len];
    let st = Stencils::build(&table, DEFAULT_PHASES, &mut buffer)
        .unwrap()
        .with_phase_lookup(lookup);
    let r = minor_semi_axis(&fp);
    let p = st.phases();
    let wide = stencil::plan_for(&fp, DEFAULT_PHASES).unwrap().edged;
    let nearest = lookup == PhaseLookup::Nearest && !wide;
    assert_eq!(
        st.phase_lookup(),
        if nearest { lookup } else { PhaseLookup::Blend }
    );
    let reach = if wide { PHASE_REACH } else { BLEND_REACH };
    assert!(
        p == DEFAULT_PHASES || p as f32 * r >= reach,
        "P = {p} at r = {r}"
    );
    println!(
        "scale {s}, {a}:1 at {deg}°: half-extents {:?} px, minor semi-axis {r:.2} px, B = {}, P = {p}, {} KiB",
        fp.half_extent,
        st.side(),
        len * 4 / 1024
    );
    assert!(st.side() <= MAX_STENCIL_SIDE);
    let reach = (st.side() / 2) as i64;
    // The stencil weight (before renormalisation) at box pixel (mx, my) for phase (a, b).
    let raw = |pa: usize, pb: usize, mx: i64, my: i64| {
        let q = [
            (mx - reach) as f32 + 0.5 - pa as f32 / p as f32,
            (my - reach) as f32 + 0.5 - pb as f32 / p as f32,
        ];
        if fp.contains(q) {
            table.weight(q)
        } else {
            0.0
        }
    };
    let sums: Vec<f32> = (0..(p + 1) * (p + 1))
        .map(|k| {
            let (pa, pb) = (k % (p + 1), k / (p + 1));
            let b = st.side() as i64;
            let mut sum = 0.0f32;
            for my in 0..b {
                for mx in 0..b {
                    sum += raw(pa, pb, mx, my);
                }
            }
            sum
        })
        .collect();
    let stencil = |pa: usize, pb: usize, mx: i64, my: i64| {
        let w = raw(pa, pb, mx, my);
        if fp.renormalise {
            w * (1.0 / sums[pb * (p + 1) + pa])
        } else {
            w
        }
    };
    for c in CENTRES {
        let mut got = vec![0.0f32; SIZE * SIZE];
        let mut img = ImageMut::new(&mut got, SIZE, SIZE, SIZE).unwrap();
        st.splat(c, &1.0f32, &mut img, |_, _, _| {}).unwrap();
        // Brute force: the blend over the whole box.
        let (ix, iy) = (c[0].floor() as i64, c[1].floor() as i64);
        let ((ka, fx), (kb, fy)) = (phase(c[0], ix, p), phase(c[1], iy, p));
        let (w00, w10, w01, w11) = (
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        );
        let mut want = vec![0.0f32; SIZE * SIZE];
        let b = st.side() as i64;
        for my in 0..b {
            for mx in 0..b {
                let (x, y) = (ix - reach + mx, iy - reach + my);
                if x < 0 || y < 0 || x >= SIZE as i64 || y >= SIZE as i64 {
                    continue;
                }
                let corners = [
                    stencil(ka, kb, mx, my),
                    stencil(ka + 1, kb, mx, my),
                    stencil(ka, kb + 1, mx, my),
                    stencil(ka + 1, kb + 1, mx, my),
                ];
                let q = [x as f32 + 0.5 - c[0], y as f32 + 0.5 - c[1]];
                // Wide: only pixel centres inside the support (the table walk's rows), and
                // the sampler itself where a corner stencil is zero.
                let inside = fp.row_span(q[1]).is_some_and(|(lo, hi)| {
                    let (x0, x1) = ((c[0] + lo - 0.5).ceil(), (c[0] + hi - 0.5).floor());
                    x as f32 >= x0 && x as f32 <= x1
                });
                want[y as usize * SIZE + x as usize] = if wide && !inside {
                    0.0
                } else if wide && corners.contains(&0.0) {
                    table.weight(q)
                } else if nearest {
                    corners[usize::from(fx >= 0.5) + 2 * usize::from(fy >= 0.5)]
                } else {
                    w00 * corners[0] + w10 * corners[1] + w01 * corners[2] + w11 * corners[3]
                };
            }
        }
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                g.to_bits() == w.to_bits(),
                "scale {s}, {a}:1 at {deg}°, {lookup:?}, centre {c:?}: pixel {i} is {g}, brute \
                 force {w}"
            );
        }
    }
    Some((st.side(), wide))
}

#[test]
fn stencils_cover_every_size_and_skip_only_zeros() {
    let generic = GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN);
    let mut covered = 0;
    // Boxes wider than 16 px blended to the edge, and read at the edge.
    let mut kinds = [0, 0];
    for &(s, a, deg) in &SHAPES {
        let Some((side, wide)) = check_against_brute_force(&generic, s, a, deg) else {
            continue;
        };
        kinds[usize::from(wide)] += usize::from(side > 16);
        covered += usize::from(side > 16);
    }
    assert!(
        covered >= 2,
        "no footprint wider than the old 16 px limit was tested"
    );
    assert!(
        kinds[0] >= 1 && kinds[1] >= 1,
        "wide footprints blended to the edge and read at the edge: {kinds:?}"
    );
}

/// Round footprints from 0.5 to 5.2 px per voxel step: every window width of the small-box
/// splat (row runs of 3 to 17 px, including the runs of 7 and 12 px it blends over one pixel more,
/// and the runs from 16 px up it leaves to the general loop), against brute force.
#[test]
fn every_window_width_matches_brute_force() {
    let generic = GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN);
    let mut sides = Vec::new();
    for i in 0..40 {
        let s = 0.5 + i as f32 * 0.12;
        if let Some((side, _)) = check_against_brute_force(&generic, s, 1.0, 0.0) {
            sides.push(side);
        }
    }
    assert_eq!(sides.len(), 40);
    assert!(sides.contains(&5) && sides.contains(&19), "{sides:?}");
}

/// One unit splatted by `st` at centre `c` into a fresh `SIZE`² image.
fn splat_one(st: &Stencils<'_, ViewTable<129>>, c: [f32; 2]) -> Vec<f32> {
    let mut img = vec![0.0f32; SIZE * SIZE];
    st.splat(
        c,
        &1.0f32,
        &mut ImageMut::new(&mut img, SIZE, SIZE, SIZE).unwrap(),
        |_, _, _| {},
    )
    .unwrap();
    img
}

#[test]
fn wide_footprints_match_the_table_walk() {
    let generic = GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN);
    let mut worst = (0.0f64, 0.0f64);
    for &(s, a, deg) in &SHAPES {
        let fp = footprint(s, a, deg);
        if fp.renormalise {
            continue; // renormalised per phase, not per splat: compared by the flat-field tests
        }
        let table = ViewTable::<129>::build(&fp, &generic, Lookup::Bilinear, Lookup::Bilinear);
        let Some(len) = stencil::len_for(&fp, DEFAULT_PHASES) else {
            continue;
        };
        let mut buffer = vec![0.0f32; len];
        let st = Stencils::build(&table, DEFAULT_PHASES, &mut buffer).unwrap();
        for c in &CENTRES[..4] {
            let got = splat_one(&st, *c);
            let mut want = vec![0.0f32; SIZE * SIZE];
            splat(
                &table,
                *c,
                &1.0f32,
                &mut ImageMut::new(&mut want, SIZE, SIZE, SIZE).unwrap(),
            )
            .unwrap();
            let peak = want.iter().fold(0.0f32, |m, &v| m.max(v)) as f64;
            // Within the phase-blending bound (wide footprints read the edge from the table).
            let interior = got
                .iter()
                .zip(&want)
                .filter(|(_, &w)| f64::from(w) > 0.1 * peak)
                .map(|(&g, &w)| f64::from((g - w).abs()) / peak)
                .fold(0.0, f64::max);
            let total = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>();
            let mass = (total(&got) / total(&want) - 1.0).abs();
            assert!(
                interior < 2e-3,
                "scale {s}, {a}:1 at {deg}°: interior error {interior:.2e} of peak"
            );
            assert!(
                mass < 2e-3,
                "scale {s}, {a}:1 at {deg}°: total weight off by {mass:.2e}"
            );
            worst = (worst.0.max(interior), worst.1.max(mass));
        }
    }
    println!(
        "worst interior error {:.2e} of peak, total weight {:.2e}",
        worst.0, worst.1
    );
}

/// `Stencils::build_split` gives `build`'s stencils bit for bit however the caller splits the
/// sampling (here: in reverse order, and on two threads of uneven halves).
#[test]
fn split_builds_are_the_same_bits() {
    let generic = GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN);
    for &(s, a, deg) in &SHAPES {
        let fp = footprint(s, a, deg);
        let table = ViewTable::<129>::build(&fp, &generic, Lookup::Bilinear, Lookup::Bilinear);
        let Some(len) = stencil::len_for(&fp, DEFAULT_PHASES) else {
            continue;
        };
        let mut plain = vec![0.0f32; len];
        Stencils::build(&table, DEFAULT_PHASES, &mut plain).unwrap();
        let mut reversed = vec![f32::NAN; len];
        Stencils::build_split(&table, DEFAULT_PHASES, &mut reversed, |w, fill| {
            let cells = fill.cells();
            for (k, st) in w.chunks_exact_mut(cells).enumerate().rev() {
                fill.fill(k, st);
            }
        })
        .unwrap();
        let mut threaded = vec![f32::NAN; len];
        Stencils::build_split(&table, DEFAULT_PHASES, &mut threaded, |w, fill| {
            let cells = fill.cells();
            let cut = (w.len() / cells / 3) * cells;
            let (x, y) = w.split_at_mut(cut);
            std::thread::scope(|scope| {
                scope.spawn(|| {
                    for (k, st) in x.chunks_exact_mut(cells).enumerate() {
                        fill.fill(k, st);
                    }
                });
                scope.spawn(|| {
                    for (k, st) in y.chunks_exact_mut(cells).enumerate() {
                        fill.fill(cut / cells + k, st);
                    }
                });
            });
        })
        .unwrap();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&plain), bits(&reversed), "scale {s}, {a}:1 at {deg}°");
        assert_eq!(bits(&plain), bits(&threaded), "scale {s}, {a}:1 at {deg}°");
    }
}

/// Read at the nearest phase ([`PhaseLookup::Nearest`]), a narrow footprint's weights stay within
/// the bound `footprint::stencil::PhaseLookup` derives against the blended splat at the same
/// centre c, as fractions of the footprint's peak (its weight at its centre). The footprint moved to the nearest phase node c' (at most √2/(2P) px) changes a
/// weight by at most √2/(2P) · peak/(σ·√e), σ = r/2.5 (r the shorter semi-axis), where the pixel
/// centre lies inside the support from both; where it crosses the support's edge (the truncated
/// Gaussian drops there from a few per cent of its peak to nothing) by at most its weight on the
/// inside. A renormalised footprint is divided by its sum over the pixels, S(c') instead of S(c),
/// which adds at most peak · |S(c)/S(c') − 1|; and blending's own error is (2.5/(P·r))²/8 (all
/// the sums and weights here computed from the table). Every splat of a renormalised footprint
/// deposits the blended splat's total.
#[test]
fn nearest_phase_stays_within_its_bound() {
    let generic = GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN);
    let mut tested = 0;
    let mut worst = 0.0f64;
    for &(s, a, deg) in &SHAPES {
        let fp = footprint(s, a, deg);
        let table = ViewTable::<129>::build(&fp, &generic, Lookup::Bilinear, Lookup::Bilinear);
        let Some(plan) = stencil::plan_for(&fp, DEFAULT_PHASES).filter(|p| !p.edged) else {
            continue;
        };
        let mut buffer = vec![0.0f32; plan.floats()];
        let blend = Stencils::build(&table, DEFAULT_PHASES, &mut buffer).unwrap();
        let nearest = blend.with_phase_lookup(PhaseLookup::Nearest);
        let (p, r) = (plan.phases as f64, f64::from(minor_semi_axis(&fp)));
        let sigma = r / 2.5;
        let moved_by = 2f64.sqrt() / (2.0 * p) / (sigma * 1f64.exp().sqrt());
        let blending = (2.5 / (p * r)).powi(2) / 8.0;
        let reach = plan.side as i64 / 2;
        let weight = |q: [f64; 2]| {
            let q = q.map(|x| x as f32);
            fp.contains(q).then(|| f64::from(table.weight(q)))
        };
        // The footprint's weights at the pixel centres of the box around `c`.
        let weights = |c: [f64; 2]| {
            let (ix, iy) = (c[0].floor() as i64, c[1].floor() as i64);
            let mut v = Vec::new();
            for y in iy - reach..=iy + reach {
                for x in ix - reach..=ix + reach {
                    v.push((
                        (x, y),
                        weight([x as f64 + 0.5 - c[0], y as f64 + 0.5 - c[1]]),
                    ));
                }
            }
            v
        };
        let sum = |c: [f64; 2]| weights(c).iter().filter_map(|w| w.1).sum::<f64>();
        let mut moved_any = false;
        for c in CENTRES.iter().chain(&[[100.49, 100.51], [100.01, 100.99]]) {
            let (want, got) = (splat_one(&blend, *c), splat_one(&nearest, *c));
            let exact = c.map(f64::from);
            let node = exact.map(|x| (x * p).round() / p);
            let (renormalised, divided) = if fp.renormalise {
                ((sum(exact) / sum(node) - 1.0).abs(), sum(exact))
            } else {
                (0.0, 1.0)
            };
            // The footprint's peak (at its centre; a small one's pixels may all lie well off it).
            let raw_peak = weight([0.0, 0.0]).unwrap();
            let peak = raw_peak / divided;
            for ((x, y), w) in weights(exact) {
                let (ux, uy) = (x as usize, y as usize);
                if x < 0 || y < 0 || ux >= SIZE || uy >= SIZE {
                    continue;
                }
                let moved = weight([x as f64 + 0.5 - node[0], y as f64 + 0.5 - node[1]]);
                let edge = match (w, moved) {
                    (Some(_), Some(_)) | (None, None) => 0.0,
                    (Some(v), None) | (None, Some(v)) => v / raw_peak,
                };
                let bound = moved_by + edge + renormalised + blending;
                let i = uy * SIZE + ux;
                let err = f64::from((got[i] - want[i]).abs()) / peak;
                assert!(
                    err <= bound,
                    "scale {s}, {a}:1 at {deg}°, centre {c:?}, pixel ({x}, {y}): {err:.2e} of \
                     peak, bound {bound:.2e} (edge {edge:.2e})"
                );
                moved_any |= err > 0.0;
                worst = worst.max(err / bound);
            }
            let total = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>();
            let mass = (total(&got) / total(&want) - 1.0).abs();
            // Not renormalised: the sampled sum of a wide footprint varies with its phase too.
            let tolerance = if fp.renormalise { 1e-5 } else { 1e-3 };
            assert!(
                mass < tolerance,
                "scale {s}, {a}:1 at {deg}°: total off by {mass:.2e}"
            );
        }
        assert!(
            moved_any,
            "scale {s}, {a}:1 at {deg}°: nearest read no other phase"
        );
        tested += 1;
    }
    assert!(tested >= 5, "{tested} narrow or blended shapes");
    println!("worst error {:.0} % of the bound", worst * 100.0);
}
