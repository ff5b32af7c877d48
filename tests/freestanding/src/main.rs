//! Freestanding proof that the core needs neither std, alloc nor libc: builds a generic and a view
//! table, splats one sample into a 64×64 image on the stack (see `scene.rs`), and prints a checksum
//! of the image's bits and its total weight through raw Linux syscalls (write, exit_group). Exit
//! code 0 on success, 1 on an error or a total weight off by more than 1 %.
#![no_std]
#![no_main]

mod scene;

fn write(bytes: &[u8]) {
    // SAFETY: write(2) on fd 1 with a valid pointer and length; the result is ignored.
    unsafe {
        core::arch::asm!("syscall", inlateout("rax") 1usize => _, in("rdi") 1usize,
            in("rsi") bytes.as_ptr(), in("rdx") bytes.len(), lateout("rcx") _, lateout("r11") _,
            options(nostack));
    }
}

fn exit(code: usize) -> ! {
    // SAFETY: exit_group(2) never returns.
    unsafe {
        core::arch::asm!("syscall", in("rax") 231usize, in("rdi") code, options(noreturn, nostack));
    }
}

fn hex(v: u32, out: &mut [u8; 8]) {
    for (i, o) in out.iter_mut().enumerate() {
        let nibble = (v >> (28 - 4 * i)) & 0xf;
        *o = b"0123456789abcdef"[nibble as usize];
    }
}

/// Entry point, called from `_start` with a 16-byte-aligned stack.
extern "C" fn main() -> ! {
    let mut pixels = [0.0f32; scene::SIDE * scene::SIDE];
    match scene::render(&mut pixels) {
        Ok(sum) => {
            let mut digits = [0u8; 8];
            write(b"footprint freestanding: checksum 0x");
            hex(scene::checksum(&pixels), &mut digits);
            write(&digits);
            write(b", sum of weights bits 0x");
            hex(sum.to_bits(), &mut digits);
            write(&digits);
            // The splat must deposit one unit, less the 33×33 table's error (≤ 1 %).
            let ok = (sum - 1.0).abs() < 0.01;
            write(if ok { b" (ok)\n" } else { b" (WRONG: expected 1)\n" });
            exit(if ok { 0 } else { 1 })
        }
        Err(_) => {
            write(b"footprint freestanding: error\n");
            exit(1)
        }
    }
}

// The kernel enters _start with rsp 16-byte aligned and no return address; align and call main.
core::arch::global_asm!(".globl _start", "_start:", "and rsp, -16", "call {main}", "ud2", main = sym main);

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    write(b"footprint freestanding: panic\n");
    exit(101)
}
