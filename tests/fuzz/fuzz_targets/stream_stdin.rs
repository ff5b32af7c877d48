#![no_main]
//! Fuzz target: the standard-input stream reader (`--stream -`). The first four bytes give the
//! dimensions (1–16 each) and the sample type and byte order; the rest is the stream. Every
//! z-slice the stream holds in full is delivered, in order; the first it does not is an error;
//! asking out of order is an error; nothing panics.
use footprint::source::SheetSource;
use footprint_harness::io::stream::PipeSource;
use footprint_harness::io::volume::SampleType;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let dims = [0, 1, 2].map(|a| 1 + usize::from(data[a] % 16));
    let ty = footprint_fuzz::SAMPLE_TYPES[usize::from(data[3] % 8)];
    let big_endian = data[3] & 8 != 0;
    let stream = &data[4..];
    let mut src = PipeSource::new(std::io::Cursor::new(stream), dims, ty, big_endian, "stdin");
    let slice = dims[0] * dims[1];
    let mut out = vec![0.0f32; slice];
    if data[3] & 16 != 0 {
        assert!(src.read_sheet(2, 1, &mut out).is_err());
        assert!(src
            .read_sheet(0, 0, &mut vec![0.0; dims[1] * dims[2]])
            .is_err());
    }
    for k in 0..dims[2] {
        let holds = stream.len() >= (k + 1) * slice * ty.size();
        let got = src.read_sheet(2, k, &mut out);
        assert_eq!(got.is_ok(), holds, "z-slice {k}: {got:?}");
        if !holds {
            break;
        }
        if !matches!(ty, SampleType::F32 | SampleType::F64) {
            assert!(out.iter().all(|v| v.is_finite()));
        }
    }
});
