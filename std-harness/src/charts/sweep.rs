//! The trade-off sweep: every configuration rendered and measured against the f64 reference.

use crate::args::RenderArgs;
use crate::metrics::compare;
use crate::pipeline::quality::config::{accum_name, lookup_name, method_name, Config};
use crate::pipeline::quality::model as quality;
use crate::pipeline::{render_continuous_ref, render_ref};
use crate::reference::continuous::Reconstruction;
use crate::CliError;

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Measured {
    pub config: Config,
    /// Frame seconds: median, min, max over the runs.
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Overall RGB PSNR against the f64 reference, dB (infinite if identical).
    pub psnr_db: f64,
    /// Max abs RGB error against the reference.
    pub max_abs: f64,
    /// The `--quality` model's footprint error for this configuration at this view.
    pub footprint_error: f64,
    pub pareto: bool,
    /// Overall RGB PSNR against the continuous integral
    /// ([`crate::reference::continuous`]; the kernel's field for a Gaussian, else trilinear), dB.
    pub continuous_db: f64,
    /// On the frontier of time against `continuous_db`.
    pub pareto_continuous: bool,
}

impl Measured {
    /// PSNR + 20·log₁₀(footprint error): what the `--quality` model calls K, for this row.
    pub fn k_db(&self) -> f64 {
        self.psnr_db + 20.0 * self.footprint_error.log10()
    }
}

/// Renders the scene of `base` with every configuration in `configs`, `runs` times each, and
/// measures it against the f64 reference. Prints one line per configuration.
pub fn sweep(
    base: &RenderArgs,
    configs: &[Config],
    runs: usize,
) -> Result<Vec<Measured>, CliError> {
    let r = super::open(base)?;
    let p = r.prepared();
    let (reference, ref_s) = render_ref(p)?;
    crate::say!(
        "{}: {}x{}, reference {:.2} s; {} configurations x {runs} runs",
        p.name,
        base.size.0,
        base.size.1,
        ref_s,
        configs.len()
    );
    let rec = match p.kernel {
        footprint::Kernel::Gaussian { .. } => Reconstruction::Kernel,
        _ => Reconstruction::Trilinear,
    };
    let (truth, truth_s) = render_continuous_ref(p, rec)?;
    crate::say!(
        "continuous reference ({} reconstruction): {truth_s:.2} s, step {:.4} world units, last change {:.1} dB",
        rec.name(),
        truth.step,
        truth.change_db
    );
    // One untimed render first, so the first configuration is not timed with cold caches.
    let base_plan = crate::args::plan(base)?;
    if let Some(c) = configs.first() {
        r.fresh_frame_of(&c.plan(&base_plan))?;
    }
    let mut out = Vec::new();
    let bar = crate::io::progress::Progress::new("chart", configs.len(), "configurations");
    for c in configs {
        let plan = c.plan(&base_plan);
        let mut times = Vec::with_capacity(runs);
        let mut image = Vec::new();
        for _ in 0..runs.max(1) {
            let f = r.fresh_frame_of(&plan)?;
            times.push(f.seconds);
            image = f.image;
        }
        times.sort_by(f64::total_cmp);
        let (_, overall) = compare(&image, &reference);
        let footprint_error = match c.slab() {
            Some(_) => f64::NAN,
            None => quality::footprint_error(p, c)?,
        };
        let (_, against_truth) = compare(&image, &truth.image);
        let m = Measured {
            continuous_db: against_truth.psnr_db,
            pareto_continuous: false,
            footprint_error,
            config: *c,
            median_s: times[times.len() / 2],
            min_s: times[0],
            max_s: times[times.len() - 1],
            psnr_db: overall.psnr_db,
            max_abs: overall.max_abs,
            pareto: false,
        };
        bar.suspend(|| {
            crate::say!(
                "{:<36} {:>8.3} s ({:.3}–{:.3})  {:>7.2} dB  max {:.2e}  continuous {:>6.2} dB",
                c.label(),
                m.median_s,
                m.min_s,
                m.max_s,
                m.psnr_db,
                m.max_abs,
                m.continuous_db
            )
        });
        bar.step();
        out.push(m);
    }
    mark_pareto(&mut out);
    Ok(out)
}

/// Marks the configurations no other beats in both time (median) and PSNR: against the sheet
/// reference (`pareto`) and against the continuous integral (`pareto_continuous`).
pub fn mark_pareto(rows: &mut [Measured]) {
    let front = |q: &[(f64, f64)], i: usize| {
        let (t, p) = q[i];
        !q.iter()
            .enumerate()
            .any(|(j, &(tj, pj))| j != i && tj <= t && pj >= p && (tj < t || pj > p))
    };
    // The sheet reference measures object slicing only: image slabs never sit on its frontier.
    let sheets: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| match r.config.slab() {
            Some(_) => (f64::INFINITY, f64::NEG_INFINITY),
            None => (r.median_s, r.psnr_db),
        })
        .collect();
    let truth: Vec<(f64, f64)> = rows.iter().map(|r| (r.median_s, r.continuous_db)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        r.pareto = r.config.slab().is_none() && front(&sheets, i);
        r.pareto_continuous = front(&truth, i);
    }
}

/// The trade-off CSV: one row per configuration.
pub fn csv(rows: &[Measured]) -> String {
    let mut s = String::from(
        "config,table,lookup,method,accum,backend,median_s,min_s,max_s,psnr_db,max_abs,footprint_error,k_db,pareto,continuous_psnr_db,continuous_pareto,slicing,slab\n",
    );
    for r in rows {
        let c = &r.config;
        s.push_str(&format!(
            "{},{},{},{},{},{},{:.6},{:.6},{:.6},{:.3},{:.4e},{:.4e},{:.3},{},{:.3},{},{},{}\n",
            c.label(),
            c.table,
            lookup_name(c.lookup),
            method_name(c.method),
            accum_name(c.accum),
            footprint::math::BACKEND,
            r.median_s,
            r.min_s,
            r.max_s,
            r.psnr_db,
            r.max_abs,
            r.footprint_error,
            r.k_db(),
            r.pareto,
            r.continuous_db,
            r.pareto_continuous,
            if c.slab().is_some() {
                "image"
            } else {
                "object"
            },
            c.slab().map_or(String::new(), |t| t.to_string())
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: f64, q: f64) -> Measured {
        Measured {
            config: Config::all()[0],
            median_s: t,
            min_s: t,
            max_s: t,
            psnr_db: q,
            max_abs: 0.0,
            footprint_error: 0.1,
            pareto: false,
            // The continuous figure reversed, so its frontier differs from the sheets'.
            continuous_db: 100.0 - q,
            pareto_continuous: false,
        }
    }

    #[test]
    fn pareto_keeps_exactly_the_undominated() {
        // (time, PSNR): b dominates c (faster and better); a and d trade off; e ties a.
        let mut rows = vec![
            row(1.0, 40.0),
            row(2.0, 60.0),
            row(2.5, 55.0),
            row(3.0, 70.0),
            row(1.0, 40.0),
        ];
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [true, true, false, true, true]);
        // Against the continuous figures (60, 40, 45, 30, 60) only the fastest best survive.
        let front: Vec<bool> = rows.iter().map(|r| r.pareto_continuous).collect();
        assert_eq!(front, [true, false, false, false, true]);
    }

    #[test]
    fn every_configuration_once_with_bench_names() {
        let all = Config::all();
        assert_eq!(all.len(), 56);
        let mut labels: Vec<String> = all.iter().map(Config::label).collect();
        labels.sort();
        labels.dedup();
        assert_eq!(labels.len(), 56);
        assert!(labels.contains(&format!(
            "n=33/bilinear/direct/fixed/{}",
            footprint::math::BACKEND
        )));
    }
}
