//! Sheet accumulators and images kept from one frame for the next. A band's accumulator ends
//! its frame clear: the renderer composites every sheet over the rows it touched and clears those
//! rows, and touches no other pixel. So a later frame of the same size can take it as it is, without
//! allocating and filling megabytes per band (`try_filled`, `memset` and page faults were about
//! 4 % of a blobs re-render in `perf record`). An accumulator is given back only after a band
//! finished without error; one that met an error is dropped. A frame's image is kept apart from
//! them (its pixels are not clear): the sheet renderer starts every band's rows afresh
//! (background or transparent) before compositing into them.

use crate::io::try_filled;
use crate::CliError;
use std::any::Any;
use std::sync::Mutex;

/// Most accumulators kept (more threads than this allocate the rest afresh).
pub const MAX_SPARES: usize = 16;

/// Most images kept: a frame renders one.
pub const MAX_IMAGES: usize = 2;

/// Buffers of any pixel type, each kept as its `Vec`: clear accumulators, and images whose
/// pixels are left as they were (a frame's bands overwrite every pixel before reading one).
#[derive(Debug)]
pub struct Spares {
    clear: Shelf,
    images: Shelf,
}

impl Default for Spares {
    fn default() -> Self {
        Spares {
            clear: Shelf::new(MAX_SPARES),
            images: Shelf::new(MAX_IMAGES),
        }
    }
}

impl Spares {
    /// A clear accumulator of `n` pixels: a kept one of that type and length, else a new one
    /// filled with `zero` (allocation failing is an error naming `what`).
    pub fn take<T: Copy + Send + 'static>(
        &self,
        n: usize,
        zero: T,
        what: &str,
    ) -> Result<Vec<T>, CliError> {
        self.clear
            .take(n)
            .map_or_else(|| try_filled(n, zero, what), Ok)
    }

    /// Keeps `acc` for a later [`Spares::take`]. Every pixel must equal `zero` (the caller's
    /// promise, checked in debug builds); past [`MAX_SPARES`] the oldest kept is dropped.
    pub fn give<T: Copy + PartialEq + Send + 'static>(&self, acc: Vec<T>, zero: T) {
        debug_assert!(
            acc.iter().all(|p| *p == zero),
            "an accumulator given back is not clear"
        );
        self.clear.give(acc);
    }

    /// An image of `n` pixels whose contents the caller will overwrite: a kept one of that type
    /// and length as it was left, else a new one filled with `fill`.
    pub fn take_image<T: Copy + Send + 'static>(
        &self,
        n: usize,
        fill: T,
        what: &str,
    ) -> Result<Vec<T>, CliError> {
        self.images
            .take(n)
            .map_or_else(|| try_filled(n, fill, what), Ok)
    }

    /// Where no image of `T` and `n` pixels is kept but one of `U` is, makes it one of `T`, each
    /// pixel through `convert` (in place where the two have the same size and alignment, as the
    /// fixed path's `[u32; 4]` and the float `[f32; 4]` it is handed back as), for a later
    /// [`Spares::take_image`]: the page faults of a fresh image cost more than the pass.
    pub fn convert_image<U: Send + 'static, T: Copy + Send + 'static>(
        &self,
        n: usize,
        convert: impl Fn(U) -> T,
    ) {
        if self.images.holds::<T>(n) {
            return;
        }
        if let Some(image) = self.images.take::<U>(n) {
            self.images
                .give(image.into_iter().map(convert).collect::<Vec<T>>());
        }
    }

    /// Keeps a finished frame's `image` for a later [`Spares::take_image`] (past [`MAX_IMAGES`],
    /// the oldest kept is dropped).
    pub fn give_image<T: Send + 'static>(&self, image: Vec<T>) {
        self.images.give(image);
    }
}

/// Kept `Vec`s of any element type, at most `cap`, the newest last.
#[derive(Debug)]
struct Shelf {
    kept: Mutex<Vec<Box<dyn Any + Send>>>,
    cap: usize,
}

impl Shelf {
    fn new(cap: usize) -> Self {
        Shelf {
            kept: Mutex::new(Vec::new()),
            cap,
        }
    }

    fn take<T: 'static>(&self, n: usize) -> Option<Vec<T>> {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let at = kept
            .iter()
            .position(|b| b.downcast_ref::<Vec<T>>().is_some_and(|v| v.len() == n))?;
        kept.remove(at).downcast::<Vec<T>>().ok().map(|v| *v)
    }

    /// Whether a `Vec<T>` of length `n` is kept.
    fn holds<T: 'static>(&self, n: usize) -> bool {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter()
            .any(|b| b.downcast_ref::<Vec<T>>().is_some_and(|v| v.len() == n))
    }

    fn give<T: Send + 'static>(&self, v: Vec<T>) {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        if kept.len() == self.cap {
            kept.remove(0);
        }
        kept.push(Box::new(v));
    }
}

#[cfg(test)]
mod tests {
    use super::Spares;

    /// A given-back accumulator comes back for the same type and length only, and fresh ones
    /// are filled with the zero asked for.
    #[test]
    fn spares_match_type_and_length() {
        let s = Spares::default();
        let a = s.take(6, [0.0f32; 4], "test").unwrap();
        assert_eq!(a, vec![[0.0f32; 4]; 6]);
        let ptr = a.as_ptr();
        s.give(a, [0.0f32; 4]);
        // Another type or length: a new one.
        let b = s.take(6, [0i64; 4], "test").unwrap();
        assert_eq!(b, vec![[0i64; 4]; 6]);
        let c = s.take(5, [0.0f32; 4], "test").unwrap();
        assert_ne!(c.as_ptr(), ptr);
        // The same: the one given back.
        let d = s.take(6, [0.0f32; 4], "test").unwrap();
        assert_eq!(d.as_ptr(), ptr);
        // Taken, so no longer kept.
        let e = s.take(6, [0.0f32; 4], "test").unwrap();
        assert_ne!(e.as_ptr(), ptr);
    }

    /// Images are kept apart from the clear accumulators: an image given back is never taken as
    /// an accumulator, and comes back as it was.
    #[test]
    fn images_are_not_taken_as_accumulators() {
        let s = Spares::default();
        s.give_image(vec![[0.5f32; 4]; 3]);
        assert_eq!(
            s.take(3, [0.0f32; 4], "test").unwrap(),
            vec![[0.0f32; 4]; 3]
        );
        assert_eq!(
            s.take_image(3, [0.0f32; 4], "test").unwrap(),
            vec![[0.5f32; 4]; 3]
        );
        assert_eq!(
            s.take_image(3, [0.0f32; 4], "test").unwrap(),
            vec![[0.0f32; 4]; 3]
        );
    }

    /// A kept image of another type and the same length becomes one of the type asked for,
    /// converted, in place where the layouts agree; one of the type asked for is left alone.
    #[test]
    fn an_image_of_another_type_is_converted() {
        let s = Spares::default();
        let bits = |p: [f32; 4]| p.map(f32::to_bits);
        let image = vec![[0.5f32; 4]; 3];
        let ptr = image.as_ptr() as usize;
        s.give_image(image);
        s.convert_image(4, bits);
        s.convert_image(3, bits);
        let got = s.take_image(3, [0u32; 4], "test").unwrap();
        let half = [0.5f32.to_bits(); 4];
        assert_eq!((got.as_ptr() as usize, got), (ptr, vec![half; 3]));
        s.give_image(vec![[1u32; 4]; 3]);
        s.give_image(vec![[0.5f32; 4]; 3]);
        s.convert_image(3, bits);
        assert_eq!(
            s.take_image(3, [0u32; 4], "test").unwrap(),
            vec![[1u32; 4]; 3]
        );
        assert_eq!(
            s.take_image(3, [0.0f32; 4], "test").unwrap(),
            vec![[0.5f32; 4]; 3]
        );
    }

    /// At most two images are kept, the newest: a third given back drops the oldest.
    #[test]
    fn the_newest_images_are_kept() {
        let s = Spares::default();
        for v in [1.0f32, 2.0, 3.0] {
            s.give_image(vec![v; 2]);
        }
        assert_eq!(s.take_image(2, 0.0f32, "test").unwrap(), vec![2.0; 2]);
        assert_eq!(s.take_image(2, 0.0f32, "test").unwrap(), vec![3.0; 2]);
        assert_eq!(s.take_image(2, 0.0f32, "test").unwrap(), vec![0.0; 2]);
    }

    /// Giving back an accumulator that is not clear is a bug the debug build catches.
    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "not clear")]
    fn a_dirty_accumulator_is_refused() {
        Spares::default().give(vec![[0.0f32, 0.0, 0.5, 0.0]], [0.0f32; 4]);
    }
}
