//! The generic table's byte format: round trips, and every corruption is a typed error.

use footprint::table::{crc32, TableError};
use footprint::{GenericTable, Kernel};
use footprint_suite::{default_kernels, max_rel_diff, splat_args};
use proptest::prelude::*;

fn bytes_of<const N: usize>(t: &GenericTable<N>) -> Vec<u8> {
    let mut b = vec![0u8; t.serialized_len()];
    let n = t.write_bytes(&mut b).unwrap();
    assert_eq!(n, b.len());
    b
}

/// Rewrites the trailing CRC so a deliberate edit is not caught by the checksum first.
fn reseal(b: &mut [u8]) {
    let n = b.len() - 4;
    let crc = crc32(&b[..n]);
    b[n..].copy_from_slice(&crc.to_le_bytes());
}

#[test]
fn crc32_matches_the_standard_check_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
}

#[test]
fn tables_round_trip_exactly() {
    for k in default_kernels() {
        let t = GenericTable::<33>::build(k);
        let back = GenericTable::<33>::from_bytes(&bytes_of(&t)).unwrap();
        assert_eq!(back, t, "{k}");
    }
}

#[test]
fn corruptions_are_typed_errors() {
    let t = GenericTable::<17>::build(Kernel::PAPER_GAUSSIAN);
    let good = bytes_of(&t);
    let spec_len = t.kernel().spec().len();
    let mut small = vec![0u8; good.len() - 1];
    assert!(matches!(
        t.write_bytes(&mut small),
        Err(TableError::BufferTooSmall { .. })
    ));

    let load = |b: &[u8]| GenericTable::<17>::from_bytes(b);
    assert!(matches!(
        load(&good[..5]),
        Err(TableError::Truncated { .. })
    ));
    assert!(matches!(
        load(&good[..good.len() - 1]),
        Err(TableError::Truncated { .. })
    ));
    let mut long = good.clone();
    long.push(0);
    assert!(matches!(load(&long), Err(TableError::TrailingBytes { .. })));
    let mut b = good.clone();
    b[0] = b'X';
    assert_eq!(load(&b), Err(TableError::BadMagic));
    let mut b = good.clone();
    b[4] = 2;
    assert_eq!(load(&b), Err(TableError::UnsupportedVersion { found: 2 }));
    assert_eq!(
        GenericTable::<33>::from_bytes(&good),
        Err(TableError::SizeMismatch {
            expected: 33,
            found: 17
        })
    );
    let mut b = good.clone();
    let mid = b.len() / 2;
    b[mid] ^= 0x40;
    assert!(matches!(load(&b), Err(TableError::ChecksumMismatch { .. })));
    // NaN sample, checksum made consistent: still refused.
    let mut b = good.clone();
    let at = 12 + spec_len + 4 * 100;
    b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    reseal(&mut b);
    assert_eq!(load(&b), Err(TableError::NonFinite { index: 100 }));
    // A bad spec, checksum consistent.
    let mut b = good.clone();
    b[12] = b'x';
    reseal(&mut b);
    assert!(matches!(load(&b), Err(TableError::BadSpec(_))));
    // load_into leaves the table unchanged on error.
    let mut target = GenericTable::<17>::build(Kernel::cone(1.0).unwrap());
    let before = target.clone();
    assert!(target.load_into(&b).is_err());
    assert_eq!(target, before);
}

proptest! {
    #![proptest_config(footprint_suite::proptest_config(256))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let _ = GenericTable::<5>::from_bytes(&bytes);
    }

    #[test]
    fn any_single_byte_flip_is_refused(at in 0usize..1200, bit in 0u8..8) {
        let t = GenericTable::<17>::build(Kernel::PAPER_GAUSSIAN);
        let mut b = bytes_of(&t);
        let at = at % b.len();
        b[at] ^= 1 << bit;
        prop_assert!(GenericTable::<17>::from_bytes(&b).is_err());
    }
}

/// `footprint tables` writes a file that `footprint splat --table-file` loads to the same image as
/// building the table in memory; a table for another kernel is refused.
#[test]
fn tables_command_output_loads_in_splat() {
    let dir = footprint_suite::tmpdir("tables");
    let file = dir.join("g65.fpt");
    let code = footprint_harness::run([
        "footprint",
        "tables",
        "--kernel",
        "gaussian:spread=1.6,sigmas=2.5",
        "--size",
        "65",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let mut a = splat_args();
    a.rotate_z = 30.0;
    let built = footprint_harness::args::single(&a)
        .and_then(|s| footprint_harness::pipeline::ends::single::splat_image(&s))
        .unwrap()
        .0;
    a.footprint.table_file = Some(file.clone());
    let loaded = footprint_harness::args::single(&a)
        .and_then(|s| footprint_harness::pipeline::ends::single::splat_image(&s))
        .unwrap()
        .0;
    assert_eq!(max_rel_diff(&loaded, &built), 0.0);
    a.footprint.kernel = "cone".into();
    assert!(footprint_harness::args::single(&a)
        .and_then(|s| footprint_harness::pipeline::ends::single::splat_image(&s))
        .is_err());
    a.footprint.kernel = "gaussian".into();
    a.footprint.table = 33;
    let err = footprint_harness::args::single(&a)
        .and_then(|s| footprint_harness::pipeline::ends::single::splat_image(&s))
        .unwrap_err();
    assert!(
        err.message.contains("65x65") && err.message.contains("33x33"),
        "{err}"
    );
}

/// `from_file_const` (the compile-time loader a firmware puts in flash) gives what `from_bytes`
/// gives, and refuses every corruption `from_bytes` refuses (as a panic: a compile error in a
/// `static`).
#[test]
fn the_const_loader_agrees_with_from_bytes() {
    for k in default_kernels() {
        let t = GenericTable::<17>::build(k);
        let bytes = bytes_of(&t);
        assert_eq!(GenericTable::<17>::from_file_const(k, &bytes), t, "{k}");
    }
    // The committed firmware table, decoded at compile time, is the one the core builds.
    static FLASH: GenericTable<33> = GenericTable::from_file_const(
        Kernel::PAPER_GAUSSIAN,
        include_bytes!("../embedded/scene/gaussian-33.fpt"),
    );
    let bytes = include_bytes!("../embedded/scene/gaussian-33.fpt");
    assert_eq!(GenericTable::<33>::from_bytes(bytes).unwrap(), FLASH);
    assert_eq!(FLASH, GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN));
    let good = bytes_of(&GenericTable::<9>::build(Kernel::PAPER_GAUSSIAN));
    let spec_len = Kernel::PAPER_GAUSSIAN.spec().len();
    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("truncated", good[..good.len() - 1].to_vec()),
        ("short header", good[..8].to_vec()),
    ];
    let mut b = good.clone();
    b[0] = b'X';
    cases.push(("magic", b));
    let mut b = good.clone();
    b[4] = 9;
    reseal(&mut b);
    cases.push(("version", b));
    let mut b = good.clone();
    b[8] = 7;
    reseal(&mut b);
    cases.push(("N", b));
    let mut b = good.clone();
    b[12 + spec_len] ^= 1;
    cases.push(("crc", b));
    let mut b = good.clone();
    b[12 + spec_len..12 + spec_len + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    reseal(&mut b);
    cases.push(("NaN sample", b));
    for (what, bytes) in cases {
        assert!(GenericTable::<9>::from_bytes(&bytes).is_err(), "{what}");
        let r = std::panic::catch_unwind(|| {
            GenericTable::<9>::from_file_const(Kernel::PAPER_GAUSSIAN, &bytes)
        });
        assert!(r.is_err(), "{what}: accepted");
    }
}
