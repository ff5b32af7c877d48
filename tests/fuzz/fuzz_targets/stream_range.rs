#![no_main]
//! Fuzz target: a streamed file's data path. The first bytes choose the sample type, byte order,
//! dimensions (1 to 8 each) and offset; the rest is the file. The range pass (`file_summary`, in
//! chunks, in f64) finds the value map wide samples need and, through it, the smallest and
//! largest finite value that decoding the whole file with that map finds (as values: −0 = +0); the file source with
//! that map delivers every sheet along every axis as the decoded volume holds it; a file too
//! short for its layout is refused in one line.
use footprint::source::SheetSource;
use footprint_harness::io::stream::{decode_into, file_summary, FileSource, Layout};
use footprint_harness::io::volume::ValueMap;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((head, body)) = data.split_first_chunk::<5>() else {
        return;
    };
    let ty = footprint_fuzz::SAMPLE_TYPES[usize::from(head[0] % 8)];
    let big_endian = head[0] & 8 != 0;
    let dims = [1, 2, 3].map(|i| 1 + usize::from(head[i] % 8));
    let offset = u64::from(head[4] % 16);
    let path = footprint_fuzz::scratch().join("stream_range.raw");
    std::fs::write(&path, body).expect("scratch file");
    let mut layout = Layout {
        path,
        offset,
        dims,
        ty,
        big_endian,
        values: ValueMap::IDENTITY,
    };
    let n = dims.iter().product::<usize>();
    let need = n * ty.size();
    let fits = offset as usize + need <= body.len();
    let summary = file_summary(&layout);
    let Ok(((lo, hi), _, values)) = summary else {
        let e = summary.unwrap_err().to_string();
        assert!(!fits, "a file that holds its layout is read: {e}");
        assert!(!e.contains('\n'));
        return;
    };
    assert!(fits, "a short file is refused");
    let mut all = vec![0.0f32; n];
    decode_into(&body[offset as usize..][..need], ty, big_endian, values, &mut all);
    let finite = all.iter().copied().filter(|v| v.is_finite());
    let want = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    // As values: −0 and +0 are one value, and which one a min or max of the two returns is not
    // specified (the range pass found (−0, +0) where this fold found (−0, −0)).
    assert!(lo == want.0 && hi == want.1, "{:?} against {want:?}", (lo, hi));
    layout.values = values;
    let mut src = FileSource::open(layout).expect("the layout fits");
    let [nx, ny, _] = dims;
    let at = |i: usize, j: usize, k: usize| all[i + nx * (j + ny * k)];
    for axis in 0..3 {
        let (a, b) = footprint::geometry::in_sheet_axes(axis);
        let mut sheet = vec![0.0f32; dims[a] * dims[b]];
        for s in (0..dims[axis]).rev() {
            src.read_sheet(axis, s, &mut sheet)
                .expect("a sheet of a file that fits");
            for vb in 0..dims[b] {
                for ua in 0..dims[a] {
                    let mut ijk = [0; 3];
                    (ijk[axis], ijk[a], ijk[b]) = (s, ua, vb);
                    let want = at(ijk[0], ijk[1], ijk[2]);
                    let got = sheet[vb * dims[a] + ua];
                    assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()));
                }
            }
        }
    }
});
