#![no_main]
//! Fuzz target: whole-file loads of every format, as `footprint render FILE` does them (raw,
//! gzip, zlib, base64 and ASCII data; attached and detached headers). The first byte picks the
//! extension; the rest is the file, written to a scratch folder and loaded by path. A load must
//! end in a volume whose samples match its dimensions, or in a one-line error — never a panic,
//! and never an allocation beyond what the input can fill (libFuzzer's malloc limit catches those).
use footprint_harness::io::formats::{self, raw::RawOptions};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

const EXTENSIONS: [&str; 10] = [
    "nrrd", "nhdr", "vti", "vtk", "mhd", "mha", "nii", "nii.gz", "raw", "vtr",
];

fuzz_target!(|data: &[u8]| {
    static DIR: OnceLock<std::path::PathBuf> = OnceLock::new();
    let dir = DIR.get_or_init(footprint_fuzz::scratch);
    let Some((&pick, mut rest)) = data.split_first() else {
        return;
    };
    let ext = EXTENSIONS[usize::from(pick) % EXTENSIONS.len()];
    let raw = (ext == "raw" && rest.len() >= 4).then(|| {
        let o = RawOptions {
            dims: [0, 1, 2].map(|a| 1 + usize::from(rest[a] % 16)),
            ty: footprint_fuzz::SAMPLE_TYPES[usize::from(rest[3] % 8)],
            big_endian: rest[3] & 8 != 0,
            spacing: [1.0, 1.0, 1.0],
        };
        rest = &rest[4..];
        o
    });
    let path = dir.join(format!("volume.{ext}"));
    std::fs::write(&path, rest).expect("scratch write");
    match formats::load(&path, raw.as_ref()) {
        Ok(v) => {
            assert_eq!(v.len(), v.dims.iter().product::<usize>());
            let (lo, hi) = v.range();
            let none_finite = (lo, hi) == (f32::INFINITY, f32::NEG_INFINITY);
            assert!(lo <= hi || none_finite, "range {lo}..{hi}");
            let mut sheet = vec![0.0f32; v.dims[0] * v.dims[1]];
            for k in 0..v.dims[2] {
                v.sheet_into(2, k, &mut sheet);
            }
        }
        Err(e) => {
            let text = e.to_string();
            assert!(
                !text.is_empty() && !text.contains('\n'),
                "not one line: {text:?}"
            );
        }
    }
});
