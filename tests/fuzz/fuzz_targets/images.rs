#![no_main]
//! Fuzz target: the image decoders the harness reads with — greyscale PFM (`compare`) and PNG
//! (`--background`, checked against the image size before decoding). The first byte picks the
//! decoder. A PFM that decodes re-encodes to the same bytes' values; a PNG is asked for the size
//! its header states (when small) and for a size it does not state (which must be refused); the
//! second bit of the first byte picks the transfer curve (linear or sRGB), and a PNG that decodes
//! is written again in every output style (RGB or RGBA, 8 or 16 bits) and read back.
use footprint_harness::io::image::{
    decode_pfm, decode_png_rgba, decode_png_rgba_sized, encode_pfm, encode_png, Gamma, PngStyle,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    if pick % 2 == 0 {
        if let Ok(img) = decode_pfm(bytes, "fuzz.pfm") {
            assert_eq!(img.data.len(), img.width * img.height);
            let again = decode_pfm(&encode_pfm(&img), "again.pfm").expect("own encoding decodes");
            assert_eq!((again.width, again.height), (img.width, img.height));
            assert!(img
                .data
                .iter()
                .zip(&again.data)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        return;
    }
    // IHDR width and height (big-endian, after the 8-byte signature and the chunk's 8-byte head).
    let be = |o: usize| {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let gamma = if pick & 2 == 0 {
        Gamma::Linear
    } else {
        Gamma::Srgb
    };
    if let (Some(w), Some(h)) = (be(16), be(20)) {
        if (1..=256).contains(&w) && (1..=256).contains(&h) {
            if let Ok((dw, dh, px)) = decode_png_rgba_sized(bytes, "fuzz.png", (w, h), gamma) {
                assert_eq!((dw, dh, px.len()), (w, h, w * h));
                assert!(px.iter().all(|p| p.iter().all(|c| (0.0..=1.0).contains(c))
                    && p[..3].iter().all(|c| *c <= p[3])));
                for (alpha, sixteen) in [(false, false), (true, false), (false, true), (true, true)] {
                    let style = PngStyle {
                        alpha,
                        gamma,
                        sixteen,
                    };
                    let png = encode_png(&px, w, h, style).expect("a decoded image encodes");
                    let (aw, ah, again) = decode_png_rgba(&png, "again.png").expect("own PNG decodes");
                    assert_eq!((aw, ah, again.len()), (w, h, w * h));
                }
            }
        }
        // A size the header does not state is refused before decoding.
        if (w, h) != (3, 5) {
            assert!(decode_png_rgba_sized(bytes, "fuzz.png", (3, 5), gamma).is_err());
        }
    }
});
