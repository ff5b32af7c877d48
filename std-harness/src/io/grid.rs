//! A rectilinear grid's coordinates (VTK's XML `.vtr`): per axis, the world position of every
//! sample, so that spacing varies along each axis (the paper's ozone data sat on such a grid,
//! uneven in height).
//!
//! **Conventions.** Coordinates are world units (as the file gives them) and must be finite and
//! strictly increasing along each axis: a coordinate that repeats (two samples at one place, whose
//! kernels would have no width between them) or goes back (samples out of order, whose sheets
//! would not composite in depth order) is refused with the axis and the index, never reordered
//! or merged silently. The volume the renderer sees has the *mean* spacing per axis,
//! (last − first) / (n − 1), so its box is the grid's; each sample then stands at its own
//! position in that volume's grid steps ([`Coordinates::positions`]), and the renderer scales each
//! kernel to the sample's own spacings (`footprint::refine`, "Rectilinear grids").

use std::fmt::Write as _;

/// Per axis (i, j, k), every sample's world coordinate: finite, strictly increasing.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinates {
    axes: [Vec<f64>; 3],
}

/// The axis names messages use.
const AXES: [&str; 3] = ["x", "y", "z"];

impl Coordinates {
    /// `axes` checked against `dims` (one coordinate per sample, finite, strictly increasing);
    /// the error names the axis and the first coordinate at fault.
    pub fn new(axes: [Vec<f64>; 3], dims: [usize; 3]) -> Result<Self, String> {
        for (a, c) in axes.iter().enumerate() {
            let name = AXES[a];
            if c.len() != dims[a] {
                return Err(format!(
                    "{name} coordinates: {} given, the extent has {} samples",
                    c.len(),
                    dims[a]
                ));
            }
            if let Some(i) = c.iter().position(|v| !v.is_finite()) {
                return Err(format!(
                    "{name} coordinate {i} is {}: coordinates must be finite",
                    c[i]
                ));
            }
            if let Some(i) = (1..c.len()).find(|&i| c[i] <= c[i - 1]) {
                let how = if c[i] == c[i - 1] {
                    "repeats the one before"
                } else {
                    "is below the one before"
                };
                return Err(format!(
                    "{name} coordinate {i} ({}) {how} ({}): a rectilinear grid's coordinates \
                     must increase strictly along each axis (a reversed axis: reverse its \
                     coordinates and samples)",
                    c[i],
                    c[i - 1]
                ));
            }
        }
        Ok(Coordinates { axes })
    }

    /// Axis `a`'s coordinates, world units.
    pub fn axis(&self, a: usize) -> &[f64] {
        &self.axes[a]
    }

    /// The mean spacing per axis, (last − first) / (n − 1), world units (1 for one sample): the
    /// volume's spacing, whose box is the grid's.
    pub fn mean_spacing(&self) -> [f32; 3] {
        std::array::from_fn(|a| {
            let c = &self.axes[a];
            match c.len() {
                0 | 1 => 1.0,
                n => ((c[n - 1] - c[0]) / (n - 1) as f64) as f32,
            }
        })
    }

    /// Every sample's position in grid steps of [`Coordinates::mean_spacing`], from 0 (the
    /// first) to n − 1 (the last), per axis.
    pub fn positions(&self) -> [Vec<f64>; 3] {
        let mean = self.mean_spacing();
        std::array::from_fn(|a| {
            let c = &self.axes[a];
            c.iter().map(|&x| (x - c[0]) / f64::from(mean[a])).collect()
        })
    }

    /// The least and greatest distance between neighbours per axis, world units (the mean
    /// spacing for one sample).
    pub fn gaps(&self) -> [(f64, f64); 3] {
        let mean = self.mean_spacing();
        std::array::from_fn(|a| {
            self.axes[a]
                .windows(2)
                .map(|w| w[1] - w[0])
                .fold(None, |m: Option<(f64, f64)>, g| {
                    Some(m.map_or((g, g), |(lo, hi)| (lo.min(g), hi.max(g))))
                })
                .unwrap_or((f64::from(mean[a]), f64::from(mean[a])))
        })
    }

    /// Whether every axis's spacing is even (to a part in 10⁶ of the mean): a rectilinear file
    /// of a uniform grid.
    pub fn is_uniform(&self) -> bool {
        let mean = self.mean_spacing();
        self.gaps()
            .iter()
            .zip(mean)
            .all(|(&(lo, hi), m)| hi - lo <= 1e-6 * f64::from(m).abs())
    }

    /// One line for `info`: the spacing range per axis.
    pub fn describe(&self) -> String {
        let mut s = String::from("rectilinear, spacing");
        for (a, (lo, hi)) in self.gaps().iter().enumerate() {
            let _ = write!(s, " {}: {lo:.6}..{hi:.6}", AXES[a]);
            if a < 2 {
                s.push(',');
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_span_the_mean_grid_and_faults_are_named() {
        let c =
            Coordinates::new([vec![0.0, 1.0, 3.0], vec![5.0], vec![-1.0, 1.0]], [3, 1, 2]).unwrap();
        assert_eq!(c.mean_spacing(), [1.5, 1.0, 2.0]);
        assert_eq!(c.positions()[0], vec![0.0, 1.0 / 1.5, 2.0]);
        assert_eq!(c.gaps()[0], (1.0, 2.0));
        assert!(!c.is_uniform());
        let bad = |x: Vec<f64>| Coordinates::new([x, vec![0.0], vec![0.0]], [3, 1, 1]);
        assert!(bad(vec![0.0, 1.0, 1.0])
            .unwrap_err()
            .contains("x coordinate 2 (1) repeats"));
        assert!(bad(vec![0.0, 2.0, 1.0]).unwrap_err().contains("is below"));
        assert!(bad(vec![0.0, f64::NAN, 1.0])
            .unwrap_err()
            .contains("finite"));
        assert!(bad(vec![0.0, 1.0]).unwrap_err().contains("2 given"));
    }
}
