//! Label maps: a volume whose samples *name* materials (0 background, 1 liver, 2 tumour, …)
//! rather than measure a quantity, classified by an exact lookup of each sample's value.
//!
//! A label is classified *before* reconstruction, like every pre-classified voxel: each voxel's
//! own label gives its straight colour and opacity, and the kernels then blend those shaded
//! voxels. So the picture holds only the labels' colours and their blends and composites: no
//! label value is ever interpolated into another label's colour (a transfer function over the
//! values 1 and 3 shows label 2's colour where a 1 meets a 3; this lookup cannot, since it is
//! asked for sample values only). Values that name no label (absent from the table, between
//! labels, NaN) are transparent.
//!
//! Post-classification, projections and levels of detail reconstruct *values* between samples,
//! which name no label: label maps are for pre-classified rendering (the harness refuses the
//! rest).

use super::TransferFunctionError;

/// One label: the sample value it names and the straight colour and opacity it shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Label {
    /// The sample value, as the renderer reads it ([`super::Sample::to_f32`]); finite.
    pub value: f32,
    /// Straight (not premultiplied) RGBA, each channel in [0, 1]; the opacity is that of a slab
    /// one reference distance thick, as a [`super::TransferFunction`]'s.
    pub rgba: [f32; 4],
}

/// A label table: [`Label`]s sorted by strictly increasing value (caller-owned, no allocation).
/// [`Labels::lookup`] finds a sample's label by binary search.
#[derive(Clone, Copy, Debug)]
pub struct Labels<'a> {
    /// The labels, values strictly increasing.
    pub entries: &'a [Label],
}

/// A transfer function every value of which is transparent: what a [`super::Shader`] that
/// classifies by labels carries as its (unused) transfer function.
pub(crate) const CLEAR: [[f32; 4]; 2] = [[0.0; 4]; 2];

impl Labels<'_> {
    /// Checks that the table can classify: at least one label, finite values strictly
    /// increasing, every channel in [0, 1].
    pub fn check(&self) -> Result<(), TransferFunctionError> {
        if self.entries.is_empty() {
            return Err(TransferFunctionError::NoLabels);
        }
        for (index, l) in self.entries.iter().enumerate() {
            let after = index == 0 || self.entries[index - 1].value < l.value;
            if !(l.value.is_finite() && after) {
                return Err(TransferFunctionError::LabelOrder { index });
            }
            if !l.rgba.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(TransferFunctionError::LabelEntry { index });
            }
        }
        Ok(())
    }

    /// Straight RGBA of the label `value` names; transparent when it names none (NaN included).
    #[inline]
    pub fn lookup(&self, value: f32) -> [f32; 4] {
        if value.is_nan() {
            return [0.0; 4];
        }
        match self.entries.binary_search_by(|l| {
            l.value
                .partial_cmp(&value)
                .unwrap_or(core::cmp::Ordering::Less)
        }) {
            Ok(i) => self.entries[i].rgba,
            Err(_) => [0.0; 4],
        }
    }

    /// The largest value at or below which every value is transparent: just below the first
    /// label with opacity above 0 (values between labels name none); +∞ when no label is
    /// visible. Exact, so a classifier may skip values at or below it with one comparison.
    pub fn transparent_at_or_below(&self) -> f32 {
        match self.entries.iter().find(|l| l.rgba[3] > 0.0) {
            Some(l) => l.value.next_down(),
            None => f32::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE: [Label; 3] = [
        Label {
            value: 0.0,
            rgba: [0.0; 4],
        },
        Label {
            value: 1.0,
            rgba: [1.0, 0.0, 0.0, 0.5],
        },
        Label {
            value: 3.0,
            rgba: [0.0, 0.0, 1.0, 1.0],
        },
    ];

    #[test]
    fn lookup_is_exact_and_unlabelled_values_are_clear() {
        let l = Labels { entries: &TABLE };
        l.check().unwrap();
        assert_eq!(l.lookup(1.0), TABLE[1].rgba);
        assert_eq!(l.lookup(3.0), TABLE[2].rgba);
        for v in [
            2.0,
            1.5,
            -1.0,
            4.0,
            f32::NAN,
            f32::INFINITY,
            1.0f32.next_up(),
        ] {
            assert_eq!(l.lookup(v), [0.0; 4], "{v}");
        }
        // Everything below label 1 is clear; label 1 itself is not.
        let bound = l.transparent_at_or_below();
        assert!(bound < 1.0 && bound.next_up() == 1.0);
    }

    #[test]
    fn check_refuses_unordered_or_bad_tables() {
        let mut t = TABLE;
        t.swap(1, 2);
        assert_eq!(
            Labels { entries: &t }.check(),
            Err(TransferFunctionError::LabelOrder { index: 2 })
        );
        let mut t = TABLE;
        t[2].value = t[1].value;
        assert!(Labels { entries: &t }.check().is_err());
        let mut t = TABLE;
        t[0].value = f32::NAN;
        assert!(Labels { entries: &t }.check().is_err());
        let mut t = TABLE;
        t[1].rgba[3] = 1.5;
        assert_eq!(
            Labels { entries: &t }.check(),
            Err(TransferFunctionError::LabelEntry { index: 1 })
        );
        assert_eq!(
            Labels { entries: &[] }.check(),
            Err(TransferFunctionError::NoLabels)
        );
        let clear = [TABLE[0]];
        assert_eq!(
            Labels { entries: &clear }.transparent_at_or_below(),
            f32::INFINITY
        );
    }
}
