//! A branch-free `2^t` that the compiler vectorises inside the bilateral loop
//! (`f32::exp` is a libm call per element and dominated the filter's time).

use super::fma;

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
/// [`EXP_NEG_CUTOFF`] in powers of two: [`exp2_nonpositive`] is 0 below its negative.
const EXP2_CUTOFF: f32 = EXP_NEG_CUTOFF * std::f32::consts::LOG2_E;
/// `2^f` on [−1/2, 1/2], highest degree first: the minimax polynomial of degree 5 for
/// the relative error (Remez; 7.5e-8), its constant term rounded to 1 so that `2^0` is
/// exactly 1 (2.2e-7 in `f32` arithmetic, against 2e-7 for the degree-6 Taylor polynomial
/// this replaced).
const EXP2_POLYNOMIAL: [f32; 6] = [
    1.327_647_2e-3,
    9.675_541e-3,
    5.550_713e-2,
    2.402_212e-1,
    6.931_469_4e-1,
    1.0,
];

/// `2^t` for `t ≤ 0`, the bilateral weight `exp(−e)` with its exponent `t = −e · log2 e`
/// (the filter folds `log2 e` into its inverse variances): relative error below 3e-7
/// down to `−EXP_NEG_CUTOFF · log2 e` (`e` up to [`EXP_NEG_CUTOFF`]), exactly 0 below it
/// and for NaN.
///
/// `2^t = 2^i · 2^f` with `i = round(t)`, `|f| ≤ 1/2`: the second factor by
/// [`EXP2_POLYNOMIAL`] in fused multiply-adds, the first built from its exponent bits.
/// Below the cutoff `i` may be anything; the result is then replaced by 0. Against
/// `exp(−e)` by a degree-6 Taylor polynomial of `f · ln 2` after a clamp, this spares a
/// clamp, two multiplications and a multiply-add per weight: the bilateral stage took
/// 2–5 % less time on a 424 × 240 frame (one thread each, run side by side). Adding `i`
/// to the polynomial's exponent bits directly, rather than multiplying by `2^i`, made
/// it 5 % slower (it puts an integer addition after the polynomial, on the critical
/// path). The polynomial goes by Estrin's scheme, `(c₁f + c₀) + f²((c₃f + c₂) +
/// f²(c₅f + c₄))`: three fused multiply-adds deep after `f²` instead of Horner's five in
/// a row, for one more multiplication. The bilateral stage of a 424 × 240 frame took
/// 4.83 instead of 4.96 ms on one thread (AMD EPYC, AVX2, medians of 6 alternated runs);
/// the error bound is the same (test `matches_exp2`).
///
/// `ROUNDS` says that the compiled copy rounds to the nearest integer in one instruction
/// (x86-64 with SSE4.1, AArch64): `f` then comes from `t` minus its rounding, two steps
/// after `t` instead of three; elsewhere that rounding is a library call, and `f` comes
/// from the rounding `i` already needs, undone. Both round half to even, so they give the
/// same bits. The one instruction took the bilateral stage of a 424 × 240 frame from
/// 5.24–5.30 to 5.10–5.15 ms on one thread (AMD EPYC, AVX2, alternated runs).
#[inline(always)]
pub(crate) fn exp2_nonpositive<const ROUNDS: bool>(t: f32) -> f32 {
    let shifted = t + ROUND_MAGIC;
    let i = shifted.to_bits().wrapping_sub(ROUND_MAGIC_BITS) as i32;
    let f = t - if ROUNDS {
        t.round_ties_even()
    } else {
        shifted - ROUND_MAGIC
    };
    let [c5, c4, c3, c2, c1, c0] = EXP2_POLYNOMIAL;
    let f2 = f * f;
    // Estrin's scheme: the three inner multiply-adds do not wait for each other.
    let p = fma(fma(fma(c5, f, c4), f2, fma(c3, f, c2)), f2, fma(c1, f, c0));
    let scale = f32::from_bits((i.wrapping_add(127) as u32) << 23);
    if t >= -EXP2_CUTOFF { p * scale } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `exp(−e)` through [`exp2_nonpositive`], as the filter calls it.
    fn exp_neg(e: f32) -> f32 {
        exp2_nonpositive::<false>(-e * std::f32::consts::LOG2_E)
    }

    #[test]
    fn matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let e = k as f32 * 1e-4 * EXP_NEG_CUTOFF / 20.0;
            let got = f64::from(exp_neg(e));
            let want = (-f64::from(e)).exp();
            let rel = ((got - want) / want).abs();
            let allowed = 4e-7 + 1.2e-7 * f64::from(e);
            assert!(rel <= allowed, "exp(-{e}) = {got}, want {want}, rel {rel}");
            worst = worst.max(rel);
        }
        assert!(worst > 0.0);
    }

    /// Points of the whole range, each half-integer (where the rounding to `i` turns) and
    /// the floats beside it, and values beyond the range.
    fn sweep() -> impl Iterator<Item = f32> {
        let range = (0..=1_000_000).map(|k| -(k as f32) * EXP2_CUTOFF / 1e6);
        let turns = (0..=160).flat_map(|i| {
            let t = -(i as f32) / 2.0;
            [
                t,
                f32::from_bits(t.to_bits() + 1),
                f32::from_bits(t.to_bits().max(1) - 1),
            ]
        });
        let beyond = [
            -EXP2_CUTOFF - 1e-3,
            -1e6,
            -3e38,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        range.chain(turns).chain(beyond)
    }

    /// Against `2^t` directly, both roundings.
    #[test]
    fn matches_exp2() {
        let check = |t: f32, got: f32| {
            let (got, want) = (f64::from(got), f64::from(t).exp2());
            let rel = ((got - want) / want).abs();
            assert!(rel <= 3e-7, "2^{t} = {got}, want {want}, rel {rel}");
        };
        for t in sweep().filter(|t| (-EXP2_CUTOFF..=0.0).contains(t)) {
            check(t, exp2_nonpositive::<false>(t));
            check(t, exp2_nonpositive::<true>(t));
        }
    }

    /// The rounding instruction and the rounding undone give the same bits, ties included.
    #[test]
    fn both_roundings_agree() {
        let mut ties = 0;
        for t in sweep() {
            let (undone, rounded) = (exp2_nonpositive::<false>(t), exp2_nonpositive::<true>(t));
            assert_eq!(undone.to_bits(), rounded.to_bits(), "2^{t}");
            ties += usize::from(t.fract().abs() == 0.5);
        }
        assert!(ties >= 80);
    }

    #[test]
    fn edges() {
        assert_eq!(exp2_nonpositive::<false>(0.0), 1.0);
        assert_eq!(exp2_nonpositive::<true>(-1.0), 0.5);
        assert_eq!(exp_neg(EXP_NEG_CUTOFF + 0.5), 0.0);
        assert_eq!(exp_neg(f32::INFINITY), 0.0);
        assert_eq!(exp2_nonpositive::<false>(f32::NAN), 0.0);
        assert_eq!(exp2_nonpositive::<true>(f32::NAN), 0.0);
        assert!(exp_neg(EXP_NEG_CUTOFF - 0.1) > 0.0);
    }
}
