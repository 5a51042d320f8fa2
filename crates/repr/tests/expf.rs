//! `evtac_repr::expf` against the platform's `expf` (glibc on linux-gnu), on every input the
//! static accumulator can produce: `-(dt as f32) / tau` with `dt >= 0`, i.e. every float with
//! the sign bit set (NaNs and infinities included), and a strided sweep of the positive ones.

use evtac_repr::expf::{Flavor, expf, expf_slice};

/// Compares `flavor` with `f32::exp` on the bit patterns `start..end` (every `stride`-th),
/// through both the vectorized slice path and the scalar one; returns the first mismatch.
fn first_mismatch(flavor: Flavor, start: u64, end: u64, stride: u64) -> Option<(u32, u32, u32)> {
    const BLOCK: usize = 4096;
    let mut xs = Vec::with_capacity(BLOCK);
    let mut out = vec![0.0f32; BLOCK];
    let mut bits = start;
    while bits < end {
        xs.clear();
        while xs.len() < BLOCK && bits < end {
            xs.push(f32::from_bits(bits as u32));
            bits += stride;
        }
        expf_slice(&xs, &mut out, flavor);
        for (&x, &got) in xs.iter().zip(&out) {
            let want = x.exp();
            let same = |v: f32| v.to_bits() == want.to_bits() || (v.is_nan() && want.is_nan());
            if !same(got) {
                return Some((x.to_bits(), got.to_bits(), want.to_bits()));
            }
            if !same(expf(x, flavor)) {
                return Some((x.to_bits(), expf(x, flavor).to_bits(), want.to_bits()));
            }
        }
    }
    None
}

/// Every negative input on both cores, then a strided sweep of the positive ones.
fn check_all(flavor: Flavor) {
    let half = 1u64 << 31;
    let mid = half + half / 2;
    let found = std::thread::scope(|s| {
        let a = s.spawn(|| first_mismatch(flavor, half, mid, 1));
        let b = s.spawn(|| first_mismatch(flavor, mid, 2 * half, 1));
        let c = first_mismatch(flavor, 0, half, 97);
        [a.join().unwrap(), b.join().unwrap(), c]
    });
    if let Some(m) = found.into_iter().flatten().next() {
        panic!(
            "expf({:e} = {:#010x}): got {:#010x}, the platform gives {:#010x}",
            f32::from_bits(m.0),
            m.0,
            m.1,
            m.2
        );
    }
}

#[cfg(all(target_os = "linux", target_env = "gnu", target_arch = "x86_64"))]
#[test]
fn glibc_expf_is_reproduced_on_every_negative_input() {
    check_all(Flavor::detect());
}

/// glibc picks its build without FMA when told the CPU has neither FMA nor AVX2; the test runs
/// itself again that way.
#[cfg(all(target_os = "linux", target_env = "gnu", target_arch = "x86_64"))]
#[test]
fn glibc_expf_without_fma_is_reproduced_on_every_negative_input() {
    const TUNABLES: &str = "glibc.cpu.hwcaps=-AVX2,-FMA";
    if std::env::var("GLIBC_TUNABLES").as_deref() == Ok(TUNABLES) {
        check_all(Flavor::PLAIN);
        return;
    }
    let status = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "expf::glibc_expf_without_fma_is_reproduced_on_every_negative_input",
            "--nocapture",
        ])
        .env("GLIBC_TUNABLES", TUNABLES)
        .status()
        .expect("the test binary runs again");
    assert!(status.success(), "the run with glibc's plain expf failed");
}

#[test]
fn special_inputs_follow_glibc() {
    for flavor in [Flavor::detect(), Flavor::PLAIN] {
        assert_eq!(expf(f32::NEG_INFINITY, flavor), 0.0);
        assert_eq!(expf(f32::INFINITY, flavor), f32::INFINITY);
        assert!(expf(f32::NAN, flavor).is_nan());
        assert_eq!(expf(-200.0, flavor), 0.0);
        assert_eq!(expf(100.0, flavor), f32::INFINITY);
        assert_eq!(expf(-0.0, flavor), 1.0);
        assert_eq!(expf(1.0, flavor), std::f32::consts::E);
    }
}
