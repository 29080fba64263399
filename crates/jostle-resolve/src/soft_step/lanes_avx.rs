//! Eight `f32` lanes in one 256-bit AVX register, for the kernels compiled for AVX.
//!
//! [`W8`] is the [`Lane`] type the soft-step kernels use inside functions compiled with
//! `#[target_feature(enable = "avx")]` (or AVX-512VL), which run only after the CPU has been
//! detected to support them ([`super::solve`]). One instruction per operation instead of
//! [`F8`]'s two. Its layout is [`F8`]'s (32 bytes, aligned to 32), so a batch prepared with
//! [`F8`] is read as [`W8`] in place. Every operation is the same lane-wise IEEE operation as
//! [`F8`]'s (`maxps` semantics for the maximum, ordered comparisons, exact division and square
//! root, no fused multiply-add), so both give bit-identical results.
//!
//! The intrinsics need AVX, and the operations are safe trait methods, so the invariant of the
//! soft-step module is: **`W8` and `WM8` are used only inside the functions the
//! `with_best_lanes!` dispatch enters after detecting the CPU's features** (the kernels of
//! [`super::solve`] and [`super::prepare::prepare_batches`]). Both types are visible to the
//! soft-step module only, and the one way to reach them from prepared data, [`as_wide`], is an
//! `unsafe fn` whose contract is that detection.

// SAFETY (every `unsafe` block of this file but `as_wide`'s): the AVX intrinsics are sound on a
// CPU with AVX, and `W8`/`WM8` values are only created and used inside the functions entered
// by `with_best_lanes!` after `avx_level()` detected AVX (see the module docs).
use super::batch::{ManifoldLanes, PointLanes};
use super::lanes::{F8, Lane, LaneMask, WIDTH};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Index, IndexMut, Mul, Neg, Sub};

/// Eight `f32` lanes in one AVX register.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(super) struct W8(__m256);

/// Eight-lane mask: all bits set in a lane that holds.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(super) struct WM8(__m256);

const _: () = assert!(size_of::<W8>() == size_of::<F8>() && align_of::<W8>() == align_of::<F8>());

macro_rules! binary {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for W8 {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                // SAFETY: see the file header.
                unsafe { W8($intrinsic(self.0, o.0)) }
            }
        }
    };
}
binary!(Add, add, _mm256_add_ps);
binary!(Sub, sub, _mm256_sub_ps);
binary!(Mul, mul, _mm256_mul_ps);
binary!(Div, div, _mm256_div_ps);

impl Neg for W8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: see the file header.
        unsafe { W8(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))) }
    }
}

impl Index<usize> for W8 {
    type Output = f32;
    #[inline(always)]
    fn index(&self, i: usize) -> &f32 {
        // SAFETY: `W8` is 32 bytes of eight f32 lanes, with no invalid bit patterns.
        let lanes = unsafe { &*(self as *const W8 as *const [f32; WIDTH]) };
        &lanes[i]
    }
}

impl IndexMut<usize> for W8 {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        // SAFETY: as for `index`.
        let lanes = unsafe { &mut *(self as *mut W8 as *mut [f32; WIDTH]) };
        &mut lanes[i]
    }
}

macro_rules! compare {
    ($name:ident, $predicate:ident) => {
        #[inline(always)]
        fn $name(self, o: Self) -> WM8 {
            // SAFETY: see the file header.
            unsafe { WM8(_mm256_cmp_ps::<$predicate>(self.0, o.0)) }
        }
    };
}

impl Lane for W8 {
    type Mask = WM8;
    // SAFETY: plain bit patterns (eight 0.0 or 1.0 lanes); no intrinsic runs.
    const ZERO: Self = unsafe { std::mem::transmute::<[f32; WIDTH], W8>([0.0; WIDTH]) };
    // SAFETY: as for ZERO.
    const ONE: Self = unsafe { std::mem::transmute::<[f32; WIDTH], W8>([1.0; WIDTH]) };

    #[inline(always)]
    fn splat(x: f32) -> Self {
        // SAFETY: see the file header.
        unsafe { W8(_mm256_set1_ps(x)) }
    }

    #[inline(always)]
    fn from_array(a: [f32; WIDTH]) -> Self {
        // SAFETY: see the file header; an unaligned load of eight f32.
        unsafe { W8(_mm256_loadu_ps(a.as_ptr())) }
    }

    #[inline(always)]
    fn select(mask: WM8, t: Self, f: Self) -> Self {
        // SAFETY: see the file header.
        unsafe { W8(_mm256_blendv_ps(f.0, t.0, mask.0)) }
    }

    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: see the file header. `vmaxps` returns the second operand when either is NaN,
        // as SSE's `maxps` does for `F8`.
        unsafe { W8(_mm256_max_ps(self.0, o.0)) }
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: see the file header.
        unsafe { W8(_mm256_sqrt_ps(self.0)) }
    }

    #[inline(always)]
    fn recip(self) -> Self {
        // SAFETY: see the file header. Exact division, as glam's `Vec4::recip`.
        unsafe { W8(_mm256_div_ps(_mm256_set1_ps(1.0), self.0)) }
    }

    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: see the file header.
        unsafe { W8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
    }

    #[inline(always)]
    fn is_finite_mask(self) -> WM8 {
        // |x| < ∞, as glam's `Vec4::is_finite_mask`.
        self.abs().cmplt(W8::splat(f32::INFINITY))
    }

    #[inline(always)]
    fn load_transposed(rows: [&[f32; WIDTH]; WIDTH]) -> [Self; WIDTH] {
        // SAFETY: see the file header; unaligned loads of eight f32 each. Written out, not a
        // closure, which would not be compiled with the kernel's target features.
        let rows = unsafe {
            [
                W8(_mm256_loadu_ps(rows[0].as_ptr())),
                W8(_mm256_loadu_ps(rows[1].as_ptr())),
                W8(_mm256_loadu_ps(rows[2].as_ptr())),
                W8(_mm256_loadu_ps(rows[3].as_ptr())),
                W8(_mm256_loadu_ps(rows[4].as_ptr())),
                W8(_mm256_loadu_ps(rows[5].as_ptr())),
                W8(_mm256_loadu_ps(rows[6].as_ptr())),
                W8(_mm256_loadu_ps(rows[7].as_ptr())),
            ]
        };
        Self::transpose(rows)
    }

    #[inline(always)]
    fn transpose(c: [Self; WIDTH]) -> [Self; WIDTH] {
        // SAFETY: see the file header. The classic 8×8 transpose: interleave pairs of rows,
        // then pairs of pairs within each 128-bit half, then swap the halves.
        unsafe {
            let t0 = _mm256_unpacklo_ps(c[0].0, c[1].0);
            let t1 = _mm256_unpackhi_ps(c[0].0, c[1].0);
            let t2 = _mm256_unpacklo_ps(c[2].0, c[3].0);
            let t3 = _mm256_unpackhi_ps(c[2].0, c[3].0);
            let t4 = _mm256_unpacklo_ps(c[4].0, c[5].0);
            let t5 = _mm256_unpackhi_ps(c[4].0, c[5].0);
            let t6 = _mm256_unpacklo_ps(c[6].0, c[7].0);
            let t7 = _mm256_unpackhi_ps(c[6].0, c[7].0);
            let u0 = _mm256_shuffle_ps::<0x44>(t0, t2);
            let u1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
            let u2 = _mm256_shuffle_ps::<0x44>(t1, t3);
            let u3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
            let u4 = _mm256_shuffle_ps::<0x44>(t4, t6);
            let u5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
            let u6 = _mm256_shuffle_ps::<0x44>(t5, t7);
            let u7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
            [
                W8(_mm256_permute2f128_ps::<0x20>(u0, u4)),
                W8(_mm256_permute2f128_ps::<0x20>(u1, u5)),
                W8(_mm256_permute2f128_ps::<0x20>(u2, u6)),
                W8(_mm256_permute2f128_ps::<0x20>(u3, u7)),
                W8(_mm256_permute2f128_ps::<0x31>(u0, u4)),
                W8(_mm256_permute2f128_ps::<0x31>(u1, u5)),
                W8(_mm256_permute2f128_ps::<0x31>(u2, u6)),
                W8(_mm256_permute2f128_ps::<0x31>(u3, u7)),
            ]
        }
    }

    #[inline(always)]
    fn store_skipping_3_and_7(self, dst: &mut [f32; WIDTH]) {
        // SAFETY: see the file header; an unaligned load and store of eight f32.
        unsafe {
            let old = _mm256_loadu_ps(dst.as_ptr());
            let new = _mm256_blend_ps::<0b1000_1000>(self.0, old);
            _mm256_storeu_ps(dst.as_mut_ptr(), new);
        }
    }

    // SSE's `cmpgt`/`cmplt`/`cmple` are the signalling ordered predicates, `cmpeq` the quiet
    // ordered one; the masks they give are the same for every input.
    compare!(cmpgt, _CMP_GT_OS);
    compare!(cmplt, _CMP_LT_OS);
    compare!(cmple, _CMP_LE_OS);
    compare!(cmpeq, _CMP_EQ_OQ);
}

impl BitAnd for WM8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        // SAFETY: see the file header.
        unsafe { WM8(_mm256_and_ps(self.0, o.0)) }
    }
}

impl BitOr for WM8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        // SAFETY: see the file header.
        unsafe { WM8(_mm256_or_ps(self.0, o.0)) }
    }
}

impl LaneMask for WM8 {
    #[inline(always)]
    fn any(self) -> bool {
        // SAFETY: see the file header.
        unsafe { _mm256_movemask_ps(self.0) != 0 }
    }
}

/// Which 256-bit kernels the CPU can run.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum AvxLevel {
    /// AVX-512F and AVX-512VL: 256-bit lanes and 32 vector registers.
    Avx512,
    /// AVX: 256-bit lanes, 16 registers.
    Avx,
    /// Neither: the 128-bit kernels.
    None,
}

/// The best [`AvxLevel`] of this CPU. The AVX-512 kernels are compiled with `avx512f`, which
/// lets the compiler use AVX2 and FMA instructions too (it implies them), so those are checked
/// as well rather than trusted to come with AVX-512 (a virtual machine may hide them).
pub(super) fn avx_level() -> AvxLevel {
    use std::arch::is_x86_feature_detected as has;
    let detected =
        if has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("fma") && has!("f16c") {
            AvxLevel::Avx512
        } else if has!("avx") {
            AvxLevel::Avx
        } else {
            AvxLevel::None
        };
    #[cfg(test)]
    {
        // Tests may ask for a lower level than the CPU has, never a higher one.
        let capped = match (CAP.load(std::sync::atomic::Ordering::Relaxed), detected) {
            (1, _) => AvxLevel::None,
            (2, AvxLevel::Avx512) => AvxLevel::Avx,
            _ => detected,
        };
        return capped;
    }
    #[allow(unreachable_code)]
    detected
}

/// Tests only: 0 = the detected level, 1 = the 128-bit lanes, 2 = at most AVX. The paths give
/// identical results, so tests running meanwhile on other threads are unaffected.
#[cfg(test)]
pub(super) static CAP: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

const _: () = {
    assert!(size_of::<PointLanes<W8>>() == size_of::<PointLanes<F8>>());
    assert!(align_of::<PointLanes<W8>>() == align_of::<PointLanes<F8>>());
    assert!(size_of::<ManifoldLanes<W8>>() == size_of::<ManifoldLanes<F8>>());
    assert!(align_of::<ManifoldLanes<W8>>() == align_of::<ManifoldLanes<F8>>());
};

/// The batches viewed with [`W8`] lanes.
///
/// # Safety
///
/// The CPU must support AVX ([`avx_level`] is not [`AvxLevel::None`]): the view's values can
/// only be operated on with AVX instructions, which the caller must run only in functions
/// compiled for the detected features (the module docs' invariant). The cast itself is sound.
#[inline(always)]
pub(super) unsafe fn as_wide<'a>(
    manifolds: &'a mut [ManifoldLanes<F8>],
    points: &'a mut [PointLanes<F8>],
) -> (&'a mut [ManifoldLanes<W8>], &'a mut [PointLanes<W8>]) {
    // SAFETY: `ManifoldLanes` and `PointLanes` are `repr(C)`, and `W8` has `F8`'s size and
    // alignment (asserted above), so both instantiations have the same
    // layout; every bit pattern is a valid `W8`. The borrows are carried over unchanged.
    unsafe {
        (
            std::slice::from_raw_parts_mut(manifolds.as_mut_ptr().cast(), manifolds.len()),
            std::slice::from_raw_parts_mut(points.as_mut_ptr().cast(), points.len()),
        )
    }
}
