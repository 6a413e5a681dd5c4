//! A branch-free `exp(−e)` that the compiler vectorises inside the bilateral loop
//! (`f32::exp` is a libm call per element and dominated the filter's time).

use super::fma;

const LOG2_E: f32 = std::f32::consts::LOG2_E;
const LN_2: f32 = std::f32::consts::LN_2;
/// 1.5 · 2²³: adding it rounds an `f32` in (−2²², 2²²) to an integer, which then sits in
/// the low mantissa bits.
const ROUND_MAGIC: f32 = 12_582_912.0;
const ROUND_MAGIC_BITS: u32 = 0x4B40_0000;
/// Beyond this the filter takes `exp(−e)` as 0. A weight of `exp(−50) ≈ 2e-22` times a
/// normal's component stays a normal `f32` (down to components of 1e-16); smaller weights
/// give subnormal products, which GPUs flush to zero and CPUs keep, so that a triangle
/// whose every weight lies below this would get a different normal on each (or the
/// normal of one rounding-dominated neighbour). Such a triangle, unlike all of its
/// neighbours, keeps its own normal on both backends; the GPU kernel uses the same value.
pub(crate) const EXP_NEG_CUTOFF: f32 = 50.0;

/// `exp(−e)` for `e ≥ 0`, relative error below 1e-6 for `e ≤ 10` (a few ulp of the
/// reduced argument beyond), exactly 0 for `e >` [`EXP_NEG_CUTOFF`].
///
/// `exp(−e) = 2^i · exp(f · ln 2)` with `i = round(−e · log2 e)`, `|f| ≤ 1/2`, the second
/// factor by a degree-6 Taylor polynomial (truncation error < 2e-7 on that interval) in
/// fused multiply-adds and `2^i` built from its exponent bits.
#[inline(always)]
pub(crate) fn exp_neg(e: f32) -> f32 {
    let clamped = if e < EXP_NEG_CUTOFF {
        e
    } else {
        EXP_NEG_CUTOFF
    };
    let t = -clamped * LOG2_E;
    let shifted = t + ROUND_MAGIC;
    let i = shifted.to_bits().wrapping_sub(ROUND_MAGIC_BITS) as i32;
    let f = t - (shifted - ROUND_MAGIC);
    let g = f * LN_2;
    let p = [1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0]
        .into_iter()
        .fold(1.0 / 720.0, |p, c| fma(p, g, c));
    let scale = f32::from_bits((i.wrapping_add(127) as u32) << 23);
    if e > EXP_NEG_CUTOFF { 0.0 } else { p * scale }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let e = k as f32 * 1e-4 * EXP_NEG_CUTOFF / 20.0;
            let got = f64::from(exp_neg(e));
            let want = (-f64::from(e)).exp();
            let rel = ((got - want) / want).abs();
            let allowed = 1e-6 + 1.2e-7 * f64::from(e);
            assert!(rel <= allowed, "exp(-{e}) = {got}, want {want}, rel {rel}");
            worst = worst.max(rel);
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn edges() {
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(EXP_NEG_CUTOFF + 0.5), 0.0);
        assert_eq!(exp_neg(f32::INFINITY), 0.0);
        assert!(exp_neg(EXP_NEG_CUTOFF - 0.1) > 0.0);
    }
}
