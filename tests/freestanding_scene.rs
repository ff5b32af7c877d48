//! The freestanding program's scene (`tests/freestanding/src/scene.rs`) rendered on the host with
//! std linked: the same total weight within the table's error. The checksum is printed so CI can
//! show both builds side by side (float paths are compared with a tolerance, not bit for bit).

#[allow(dead_code)]
mod scene {
    include!("freestanding/src/scene.rs");
}

#[test]
fn freestanding_scene_on_the_host() {
    let mut pixels = vec![0.0f32; scene::SIDE * scene::SIDE];
    let sum = scene::render(&mut pixels).unwrap();
    println!(
        "host: checksum 0x{:08x}, sum of weights bits 0x{:08x}",
        scene::checksum(&pixels),
        sum.to_bits()
    );
    assert!((sum - 1.0).abs() < 0.01, "sum of weights {sum}");
}
