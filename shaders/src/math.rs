//! Elementary functions written once, so that the CPU and the GPU run the same arithmetic.
//!
//! Vulkan leaves the precision of `sin`, `cos`, `exp2`, `log2` and `pow` to the driver
//! (Vulkan 1.3 spec, "Precision and Operation of SPIR-V Instructions": sin/cos only to an
//! absolute 2⁻¹¹ on [−π, π], exp2/log2 to 3 + 2|x| ULP), and drivers differ: Mesa's
//! lavapipe uses its own polynomials, NVIDIA its special-function unit. Those functions
//! are therefore implemented here from additions, multiplications, `floor` and `sqrt`
//! (which IEEE 754 and Vulkan both require to be correctly rounded), so a bake agrees
//! between backends to a few ULP instead of to 2⁻¹¹.
//!
//! Methods (all f32, all branch-light so they suit SIMT hardware):
//! - [`sin_cos_turns`]: exact Cody–Waite style reduction in *turns* (t·2π), where the
//!   reduction by quarter turns is exact in binary, then Taylor polynomials on |x| ≤ π/4
//!   (truncation below 3·10⁻⁹, under half an ULP).
//! - [`atan2`]: octant reduction and the Cephes `atanf` minimax polynomial on
//!   |z| ≤ tan(π/8) (relative error about 2·10⁻⁷).
//! - [`exp2`], [`log2`]: exponent/mantissa split by bit manipulation, Taylor series of
//!   e^(f·ln2) on |f| ≤ ½ and of 2·atanh((m−1)/(m+1)) on m ∈ [√½, √2].

use spirv_std::glam::Vec4;
use spirv_std::num_traits::Float;

/// Largest radiance the bake takes in; larger input values are clamped to it when an
/// environment is read (and counted). Every sum in the pipeline has at most 2³² terms of
/// weight ≤ 1 and products with BRDF peaks stay below 10¹⁵ (GGX at the minimum direct
/// roughness times a sun), so with inputs ≤ 10²⁰ nothing reaches f32::MAX ≈ 3.4·10³⁸.
pub const MAX_RADIANCE: f32 = 1e20;

/// The largest value a result is held to, in place of `f32::MAX`: naga writes `f32::MAX`
/// for WGSL as `340282350000000000000000000000000000000f`, which exceeds `f32::MAX` before
/// rounding and which browsers' WGSL compilers (Chromium's Tint) refuse ("value cannot be
/// represented as 'f32'"); 3.4·10³⁸ is written as a literal they take, and every value the
/// bake makes stays far below it (inputs are clamped at [`MAX_RADIANCE`]).
pub const LARGEST: f32 = 3.4e38;

/// π in f32.
pub const PI: f32 = core::f32::consts::PI;
/// 1/π in f32.
pub const FRAC_1_PI: f32 = core::f32::consts::FRAC_1_PI;
/// 2π in f32.
pub const TAU: f32 = core::f32::consts::TAU;

// Taylor coefficients of sin(2πf) and cos(2πf) in powers of f, (2π)^k / k! with signs.
const S1: f32 = core::f32::consts::TAU;
const S3: f32 = -41.341_702_240_399_76;
const S5: f32 = 81.605_249_276_075_04;
const S7: f32 = -76.705_859_753_061_4;
const S9: f32 = 42.058_693_944_897_65;
const C2: f32 = -19.739_208_802_178_716;
const C4: f32 = 64.939_394_022_668_29;
const C6: f32 = -85.456_817_206_693_72;
const C8: f32 = 60.244_641_371_876_66;
const C10: f32 = -26.426_256_783_374_39;

/// √x, correctly rounded on both backends (IEEE 754; Vulkan's OpExtInst Sqrt).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    Float::sqrt(x)
}

/// ⌊x⌋ (exact on both backends).
///
/// On the GPU, OpExtInst Floor. Natively, `Float::floor` is a call into libm's software
/// `floorf` (x86-64's baseline has no SSE4.1 `roundss` to inline), which was a tenth of a
/// CPU bake; here it is truncation through `i32` and one step down for a negative
/// non-integer, the same value: every `|x| < 2²³` fits an `i32` and truncates exactly,
/// every larger `|x|` is already an integer, and NaN, ±∞ and ±0 are returned as they are.
#[inline]
pub fn floor(x: f32) -> f32 {
    #[cfg(target_arch = "spirv")]
    {
        Float::floor(x)
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        if !(abs(x) < 8_388_608.0) || x == 0.0 {
            return x;
        }
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    }
}

/// |x|.
#[inline]
pub fn abs(x: f32) -> f32 {
    Float::abs(x)
}

/// The smaller of `a` and `b`; `b` if either is NaN (the same on every backend, unlike `fmin`).
#[inline]
pub fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The larger of `a` and `b`; `b` if either is NaN (the same on every backend, unlike `fmax`).
#[inline]
pub fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `x` clamped to `[lo, hi]`; NaN becomes `lo`.
#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x > lo { if x < hi { x } else { hi } } else { lo }
}

/// `(sin 2πt, cos 2πt)` for any finite `t` (an angle in turns).
///
/// The reduction `t − ⌊t + ½⌋` and the quarter-turn split are exact in binary floating
/// point (Sterbenz), so only the polynomial rounds.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn sin_cos_turns(t: f32) -> (f32, f32) {
    let r = t - floor(t + 0.5); // r ∈ [−½, ½], exact
    let q = floor(r * 4.0 + 0.5); // quadrant ∈ {−2, …, 2}
    let f = r - q * 0.25; // f ∈ [−⅛, ⅛], exact
    let f2 = f * f;
    let s = f * (S1 + f2 * (S3 + f2 * (S5 + f2 * (S7 + f2 * S9))));
    let c = 1.0 + f2 * (C2 + f2 * (C4 + f2 * (C6 + f2 * (C8 + f2 * C10))));
    match (q as i32) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `(sin x, cos x)` for an angle `x` in radians.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    sin_cos_turns(x * (0.5 * FRAC_1_PI))
}

/// Four-quadrant arctangent of `y/x` in radians, in [−π, π]; `atan2(0, 0) = 0`.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let hi = if ax > ay { ax } else { ay };
    let lo = if ax > ay { ay } else { ax };
    if hi == 0.0 {
        return 0.0;
    }
    let a = lo / hi; // a ∈ [0, 1]
    // atan(a) = π/4 + atan((a − 1)/(a + 1)) brings the argument to |z| ≤ tan(π/8).
    let big = a > 0.414_213_57;
    let z = if big { (a - 1.0) / (a + 1.0) } else { a };
    let z2 = z * z;
    let p = ((8.053_744_5e-2 * z2 - 1.387_768_6e-1) * z2 + 1.997_771_1e-1) * z2 - 3.333_295e-1;
    let mut r = z + z * z2 * p;
    if big {
        r += core::f32::consts::FRAC_PI_4;
    }
    if ay > ax {
        r = core::f32::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 { -r } else { r }
}

/// 2^x, exact at integers; `0` below the subnormal range. For `x ≥ 128` it saturates to
/// [`LARGEST`] rather than overflowing (and naga rejects infinite constants in shaders).
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn exp2(x: f32) -> f32 {
    if x >= 128.0 {
        return LARGEST;
    }
    if x < -150.0 {
        return 0.0;
    }
    let n = floor(x + 0.5);
    let f = x - n; // f ∈ [−½, ½], exact
    let g = f * core::f32::consts::LN_2;
    // e^g, Taylor to degree 7 (truncation < 6·10⁻⁹ relative on |g| ≤ ln2/2).
    let p = 1.0 + g * (1.0 + g * (0.5 + g * (1.666_666_7e-1 + g * (4.166_666_6e-2 + g * (8.333_333e-3 + g * (1.388_888_9e-3 + g * 1.984_127e-4))))));
    let ni = n as i32;
    if ni >= -126 {
        p * f32::from_bits(((ni + 127) as u32) << 23)
    } else {
        // Subnormal result: scale in two exact steps.
        p * f32::from_bits(((ni + 127 + 64) as u32) << 23) * f32::from_bits(((127 - 64) as u32) << 23)
    }
}

/// log₂ x for `x > 0`, subnormals included. Outside that domain it saturates instead of
/// returning ±∞ or NaN (naga rejects such constants in shaders): `x ≤ 0` and NaN give
/// [`LOG2_FLOOR`], `x = +∞` gives 128.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn log2(x: f32) -> f32 {
    if !(x > 0.0) {
        return LOG2_FLOOR;
    }
    if x > LARGEST {
        return 128.0;
    }
    let mut bits = x.to_bits();
    let mut e: i32 = 0;
    if bits < 0x0080_0000 {
        // Subnormal: multiply by 2²³ (exact) first.
        bits = (x * 8_388_608.0).to_bits();
        e = -23;
    }
    e += ((bits >> 23) as i32) - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // m ∈ [1, 2)
    if m > core::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    // log₂ m = (2/ln2)·atanh(z), z = (m−1)/(m+1) ∈ [−0.172, 0.172]; series to z⁹.
    let z = (m - 1.0) / (m + 1.0);
    let z2 = z * z;
    let s = z * (2.0 + z2 * (0.666_666_7 + z2 * (0.4 + z2 * (0.285_714_3 + z2 * 0.222_222_22))));
    e as f32 + s * core::f32::consts::LOG2_E
}

/// ln(1 + x) for `x ≥ 0`, accurate to a few ulp where `1 + x` would round `x` away: below
/// 0.01 by `2·atanh(x/(2 + x))` to the seventh power (truncation below 10⁻¹⁹), else through
/// [`log2`].
#[inline]
pub fn ln_1p(x: f32) -> f32 {
    if x < 0.01 {
        let z = x / (2.0 + x);
        let z2 = z * z;
        2.0 * z * (1.0 + z2 * (1.0 / 3.0 + z2 * (0.2 + z2 * (1.0 / 7.0))))
    } else {
        log2(1.0 + x) * core::f32::consts::LN_2
    }
}

/// What [`log2`] returns for `x ≤ 0`: below log₂ of the smallest subnormal (−149).
pub const LOG2_FLOOR: f32 = -150.0;

/// x^y for `x ≥ 0` as exp2(y·log2 x), with `0^y = 0` for `y > 0` and `x^0 = 1`.
#[inline]
pub fn pow(x: f32, y: f32) -> f32 {
    if y == 0.0 {
        return 1.0;
    }
    if x <= 0.0 {
        return 0.0;
    }
    exp2(y * log2(x))
}

/// x⁵ by multiplication (Schlick's Fresnel term).
#[inline]
pub fn pow5(x: f32) -> f32 {
    let x2 = x * x;
    x2 * x2 * x
}

/// Clamps to [0, 1]; NaN becomes 0.
#[inline]
pub fn saturate(x: f32) -> f32 {
    clamp(x, 0.0, 1.0)
}

/// `v` with every channel above [`LARGEST`] (an infinity born of rounding in a weighted
/// mean of values near `f32::MAX`) brought back to [`LARGEST`]. A weighted mean of finite
/// inputs is mathematically at most their maximum; this keeps it finite when rounding says
/// otherwise.
#[inline]
pub fn finite4(v: Vec4) -> Vec4 {
    let c = |x: f32| if x > LARGEST { LARGEST } else { x };
    Vec4::new(c(v.x), c(v.y), c(v.z), c(v.w))
}

/// Terms per block of [`CompensatedSum`].
pub const SUM_BLOCK: u32 = 1024;

/// One step of Kahan's compensated addition of `x` into `(sum, carry)`.
macro_rules! kahan {
    ($sum:expr, $carry:expr, $x:expr) => {{
        let y = $x - $carry;
        let t = $sum + y;
        $carry = (t - $sum) - y;
        $sum = t;
    }};
}

/// What a [`Compensated`] sum adds: `f32`, or `Vec4` for four channels at once.
pub trait Summand: Copy + core::ops::Add<Output = Self> + core::ops::Sub<Output = Self> {
    /// Zero.
    const ZERO: Self;
}

impl Summand for f32 {
    const ZERO: Self = 0.0;
}

impl Summand for Vec4 {
    const ZERO: Self = Vec4::ZERO;
}

/// Summation of 2²⁴ and more f32 terms without the O(N·ε) drift of naive accumulation:
/// Kahan-compensated sums of blocks of [`SUM_BLOCK`] terms, themselves added with Kahan's
/// compensation (Kahan 1965; Higham, *Accuracy and Stability of Numerical Algorithms*
/// §4.3–4.4). The blocks matter where a GPU compiler reassociates the compensation away
/// (Mesa's lavapipe does): what is left is then a blocked sum with error O((B + N/B)·ε)
/// instead of O(N·ε). Branch-light, no arrays: cheap in registers.
#[derive(Copy, Clone)]
pub struct Compensated<T: Summand> {
    block: T,
    block_carry: T,
    count: u32,
    sum: T,
    carry: T,
}

/// A compensated sum of scalars.
pub type CompensatedSum = Compensated<f32>;
/// A compensated sum of four channels at once.
pub type CompensatedSum4 = Compensated<Vec4>;

impl<T: Summand> Default for Compensated<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Summand> Compensated<T> {
    /// An empty sum.
    pub fn new() -> Self {
        Self { block: T::ZERO, block_carry: T::ZERO, count: 0, sum: T::ZERO, carry: T::ZERO }
    }

    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: T) {
        kahan!(self.block, self.block_carry, x);
        self.count += 1;
        if self.count == SUM_BLOCK {
            self.flush();
        }
    }

    #[inline]
    fn flush(&mut self) {
        kahan!(self.sum, self.carry, self.block);
        self.block = T::ZERO;
        self.block_carry = T::ZERO;
        self.count = 0;
    }

    /// The compensated total.
    #[inline]
    pub fn total(&self) -> T {
        let mut s = *self;
        s.flush();
        s.sum
    }

    /// A sum that continues from `parts()` of an earlier one (a previous chunk).
    #[inline]
    pub fn resume(sum: T, carry: T) -> Self {
        Self { block: T::ZERO, block_carry: T::ZERO, count: 0, sum, carry }
    }

    /// `(sum, carry)` after flushing the current block: all a later chunk needs.
    #[inline]
    pub fn parts(&self) -> (T, T) {
        let mut s = *self;
        s.flush();
        (s.sum, s.carry)
    }
}

/// Most loop iterations one shader invocation runs: long sums are split into chunks of
/// at most this many terms, one dispatch each, carrying their compensated partial sums
/// between dispatches. Mesa's llvmpipe/lavapipe stops *all* loops of an invocation after
/// 65 535 iterations in total (`LP_MAX_TGSI_LOOP_ITERATIONS`, "shared between every loop
/// in a shader"); without chunks a 1024-sample prefilter came out as NaN there. Each
/// sample of a prefilter is a trilinear lookup, two bilinear ones of four taps each run as
/// a loop (`cubemap::sample_bilinear`, so that a browser's compiler sees each tap once):
/// at most 1 + 2·(1 + 4) = 11 iterations per sample, each loop entered counting, so a
/// chunk of 4096 samples stays under the budget (45 056) where 16 384 did not. A multiple
/// of `SUM_BLOCK`, so chunk boundaries fall on block boundaries and chunked sums are the
/// same arithmetic as one long sum.
pub const CHUNK: u32 = 4 * SUM_BLOCK;

/// The compensated partial sums of a weighted mean `Σ L·w / Σ w`, carried from chunk to
/// chunk (see [`CHUNK`]): the value sum and its carry, and the weight sum and carry in
/// `weight.xy`.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct MeanPartial {
    /// Σ L·w.
    pub sum: Vec4,
    /// Its compensation.
    pub carry: Vec4,
    /// Σ w in `x`, its compensation in `y`.
    pub weight: Vec4,
}

impl MeanPartial {
    /// The mean (0 when no term had weight), kept finite (see [`finite4`]).
    #[inline]
    pub fn resolve(&self) -> Vec4 {
        if self.weight.x > 0.0 { finite4(self.sum / self.weight.x) } else { Vec4::ZERO }
    }

    /// The mean of a sum of `terms` terms run as `add(start, count, partial)` over chunks of
    /// [`CHUNK`], in the order the GPU's dispatches run them. For the CPU paths: in a
    /// shader, a closure that holds a storage-buffer slice does not validate (naga).
    #[inline]
    pub fn chunked(terms: u32, add: impl Fn(u32, u32, MeanPartial) -> MeanPartial) -> Vec4 {
        MeanPartial::default().then_chunked(terms, add).resolve()
    }

    /// These sums continued by a sum of `terms` terms run as [`MeanPartial::chunked`] runs
    /// them: the next dispatches on the same sums.
    #[inline]
    pub fn then_chunked(self, terms: u32, add: impl Fn(u32, u32, MeanPartial) -> MeanPartial) -> MeanPartial {
        let mut p = self;
        let mut start = 0u32;
        while start < terms {
            let c = if terms - start < CHUNK { terms - start } else { CHUNK };
            p = add(start, c, p);
            start += c;
        }
        p
    }
}
