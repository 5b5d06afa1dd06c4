//! The vector unit's state between faer's kernels and the rest of the crate.
//!
//! faer picks AVX / AVX-512 kernels at run time and can return with the
//! upper halves of the vector registers in use ("dirty"). The rest of the
//! crate is compiled for the x86-64 baseline (SSE2, so the FMU runs on any
//! x86-64 host), and while the upper state is dirty every SSE instruction
//! pays a merge with it: the spring loop of the full space measured 4x
//! slower after a set-up that ran faer (cloth 100 x 100, AMD EPYC). So the
//! run clears the upper state (`vzeroupper`) at the start of every
//! communication step, at the end of set-up and after each faer call inside a
//! step (so the host, too, gets its vector unit back clean). It changes
//! no value: only the speed of what follows.

/// Clears the upper halves of the vector registers where the CPU has AVX;
/// nothing elsewhere. A few cycles.
#[inline]
pub fn clean() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX (checked above), all zero_upper needs.
        unsafe { zero_upper() }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper();
}
