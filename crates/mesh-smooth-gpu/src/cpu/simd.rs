//! Runtime choice of the widest vector instructions the CPU has, for the filter kernels.
//!
//! The kernels are plain loops written for the auto-vectoriser. Built for the baseline
//! target (SSE2 on x86-64) they run four lanes wide; [`widest!`] also compiles one for
//! AVX2 and picks it at run time where the CPU has it, so the same binary runs everywhere
//! and uses eight lanes where it can. Lane width does not change a result: the kernels do
//! element-wise IEEE arithmetic only (no reductions across lanes, no fused multiply-add).

/// Defines `fn $name(args) -> ret` that calls `$kernel(args)` (an `#[inline(always)]`
/// function) compiled for AVX2 when the CPU has it, else as built.
macro_rules! widest {
    ($(#[$meta:meta])* fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? => $kernel:path) => {
        $(#[$meta])*
        fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) $(-> $ret)? {
                    $kernel($($arg),*)
                }
                #[allow(unsafe_code)]
                // SAFETY: the CPU has AVX2, checked just above; that is all `avx2` needs.
                return unsafe { avx2($($arg),*) };
            }
            $kernel($($arg),*)
        }
    };
}

pub(crate) use widest;
