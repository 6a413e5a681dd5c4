//! A cache prefetch hint for the memory-latency-bound loops of region growing.

/// Asks the CPU to start loading the cache line that holds `value`, so that a later read
/// finds it in cache. Only a hint: it changes no result, and is a no-op off x86-64.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: `_mm_prefetch` needs SSE, which every x86-64 CPU has. A prefetch never
    // faults and reads nothing the program sees; `value` is a live reference besides.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            std::ptr::from_ref(value).cast(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
