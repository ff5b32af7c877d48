//! What `--refine` refined ([`crate::pipeline::ends::refine`]): the record a frame carries to the JSON.

/// What `--refine` did, for the JSON and the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Refinement {
    /// The threshold, premultiplied RGBA units (0..1).
    pub threshold: f32,
    /// Whether the sheet axis was refined too (`--refine-sheets`).
    pub sheets: bool,
    /// Per grid axis, the factor of each interval.
    pub factors: [Vec<u8>; 3],
    /// Coarse and refined samples.
    pub coarse_samples: usize,
    /// Refined samples (coarse included).
    pub samples: usize,
}

impl Refinement {
    /// The JSON record: threshold, whether the sheet axis was refined, samples before and after,
    /// and per grid axis how many intervals got factors 1, 2 and 4.
    pub fn json(&self) -> crate::io::json::Json {
        let [i, j, k] = self.counts();
        crate::io::json::Json::object()
            .num(
                "threshold",
                self.threshold.to_string().parse().unwrap_or(f64::NAN),
            )
            .bool("sheets", self.sheets)
            .num("coarse_samples", self.coarse_samples as f64)
            .num("samples", self.samples as f64)
            .obj(
                "factors",
                crate::io::json::Json::object()
                    .arr_usize("i", &i)
                    .arr_usize("j", &j)
                    .arr_usize("k", &k),
            )
    }

    /// Per axis, how many intervals got factors 1, 2 and 4.
    pub fn counts(&self) -> [[usize; 3]; 3] {
        std::array::from_fn(|a| {
            [1, 2, 4].map(|k| self.factors[a].iter().filter(|&&x| x == k).count())
        })
    }
}
