//! Eight-lane arithmetic for the soft-step kernels: one lane per contact manifold.
//!
//! [`F8`] is eight `f32` lanes held as two glam `Vec4`s, each a 128-bit SIMD register on x86-64
//! (SSE2) and aarch64 (NEON) and four plain floats elsewhere; it is what contacts are prepared
//! and stored in. The kernels are generic over the [`Lane`] trait, and on x86-64 CPUs with AVX
//! they run with the 256-bit type of the private `lanes_avx` module instead, reading the same
//! storage in place (one instruction per operation instead of two, identical results). Eight
//! lanes rather than four because a batch's points are solved one after the other, each
//! depending on the velocities the previous one left: one four-lane chain keeps the CPU waiting
//! on latency, eight independent lanes keep it busy. [`V3x8`] is eight 3-vectors stored by
//! component (x of the eight lanes, then y, then z), so a dot product of eight lanes is three
//! multiplies and two adds and a cross product six multiplies and three subtractions, with no
//! shuffles. [`Q8`] is eight quaternions stored the same way. Every operation is lane-wise IEEE
//! arithmetic, so results do not depend on the lane a contact lands in.

use jostle_math::glam::{BVec4A, Vec4};
use jostle_math::{Quat, Vec3};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Index, IndexMut, Mul, Neg, Sub, SubAssign};

/// Number of lanes.
pub const WIDTH: usize = 8;

/// Eight `f32` lanes, aligned to 32 bytes so that structures of them have the layout of
/// their 256-bit counterparts (the private `lanes_avx` module).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F8([Vec4; 2]);

/// Eight-lane boolean mask (result of a lane-wise comparison).
#[derive(Clone, Copy, Debug)]
pub struct M8([BVec4A; 2]);

/// Applies a `Vec4` operation to both halves.
macro_rules! halves {
    (|$a:ident| $e:expr, $x:expr) => {{
        let f = |$a: Vec4| $e;
        F8([f($x.0[0]), f($x.0[1])])
    }};
    (|$a:ident, $b:ident| $e:expr, $x:expr, $y:expr) => {{
        let f = |$a: Vec4, $b: Vec4| $e;
        F8([f($x.0[0], $y.0[0]), f($x.0[1], $y.0[1])])
    }};
}

/// A `Vec4` comparison applied to both halves.
macro_rules! compare {
    ($name:ident) => {
        #[inline(always)]
        fn $name(self, o: Self) -> M8 {
            M8([self.0[0].$name(o.0[0]), self.0[1].$name(o.0[1])])
        }
    };
}

impl F8 {
    /// The largest lane.
    #[inline(always)]
    pub fn max_element(self) -> f32 {
        self.0[0].max(self.0[1]).max_element()
    }
}

impl M8 {
    /// Bit `i` set for each set lane `i`.
    #[inline(always)]
    pub fn bitmask(self) -> u32 {
        self.0[0].bitmask() | (self.0[1].bitmask() << 4)
    }
}

impl BitAnd for M8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        Self([self.0[0] & o.0[0], self.0[1] & o.0[1]])
    }
}

impl BitOr for M8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        Self([self.0[0] | o.0[0], self.0[1] | o.0[1]])
    }
}

impl Index<usize> for F8 {
    type Output = f32;
    #[inline(always)]
    fn index(&self, i: usize) -> &f32 {
        &self.0[i / 4][i % 4]
    }
}

impl IndexMut<usize> for F8 {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i / 4][i % 4]
    }
}

macro_rules! binary {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F8 {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                halves!(|a, b| a $op b, self, o)
            }
        }
    };
}
binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Neg for F8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        halves!(|a| -a, self)
    }
}

/// Eight-lane arithmetic as the kernels use it: [`F8`] (two 128-bit halves) everywhere, and on
/// x86-64 CPUs with AVX a 256-bit type (the private `lanes_avx` module) inside kernels compiled
/// for it. Every operation is lane-wise IEEE arithmetic with the same semantics in both, so the
/// kernels give bit-identical results with either.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Index<usize, Output = f32>
    + IndexMut<usize>
{
    /// The result of a lane-wise comparison.
    type Mask: LaneMask;
    /// All lanes zero.
    const ZERO: Self;
    /// All lanes one.
    const ONE: Self;
    /// All lanes `x`.
    fn splat(x: f32) -> Self;
    /// Lane i from `a[i]`.
    fn from_array(a: [f32; WIDTH]) -> Self;
    /// Lane-wise `if mask { t } else { f }`.
    fn select(mask: Self::Mask, t: Self, f: Self) -> Self;
    /// Lane-wise maximum: `self` where it is greater, else `o` (so `o` when either is NaN,
    /// x86's `maxps`).
    fn max(self, o: Self) -> Self;
    /// Lane-wise square root.
    fn sqrt(self) -> Self;
    /// Lane-wise 1/x.
    fn recip(self) -> Self;
    /// Lane-wise |x|.
    fn abs(self) -> Self;
    /// Lanes that are finite.
    fn is_finite_mask(self) -> Self::Mask;
    /// Lane-wise `>`.
    fn cmpgt(self, o: Self) -> Self::Mask;
    /// Lane-wise `<`.
    fn cmplt(self, o: Self) -> Self::Mask;
    /// Lane-wise `<=`.
    fn cmple(self, o: Self) -> Self::Mask;
    /// Lane-wise `==`.
    fn cmpeq(self, o: Self) -> Self::Mask;

    /// Eight rows of eight floats, transposed: lane `i` of `result[j]` is `rows[i][j]`.
    #[inline(always)]
    fn load_transposed(rows: [&[f32; WIDTH]; WIDTH]) -> [Self; WIDTH] {
        std::array::from_fn(|j| Self::from_array(std::array::from_fn(|i| rows[i][j])))
    }

    /// The transpose of eight vectors: lane `j` of `result[i]` is lane `i` of `cols[j]`.
    #[inline(always)]
    fn transpose(cols: [Self; WIDTH]) -> [Self; WIDTH] {
        std::array::from_fn(|i| Self::from_array(std::array::from_fn(|j| cols[j][i])))
    }

    /// Writes lanes 0–2 and 4–6 to `dst`, leaving `dst[3]` and `dst[7]` as they are (a
    /// [`super::BodyState`] velocity row keeps its 1/m and flags).
    #[inline(always)]
    fn store_skipping_3_and_7(self, dst: &mut [f32; WIDTH]) {
        for i in [0, 1, 2, 4, 5, 6] {
            dst[i] = self[i];
        }
    }
}

/// A lane-wise boolean mask of a [`Lane`] type.
pub trait LaneMask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> {
    /// Whether any lane is set.
    fn any(self) -> bool;
}

impl Lane for F8 {
    type Mask = M8;
    const ZERO: Self = Self([Vec4::ZERO; 2]);
    const ONE: Self = Self([Vec4::ONE; 2]);

    #[inline(always)]
    fn splat(x: f32) -> Self {
        Self([Vec4::splat(x); 2])
    }

    #[inline(always)]
    fn from_array(a: [f32; WIDTH]) -> Self {
        Self([
            Vec4::new(a[0], a[1], a[2], a[3]),
            Vec4::new(a[4], a[5], a[6], a[7]),
        ])
    }

    #[inline(always)]
    fn select(mask: M8, t: Self, f: Self) -> Self {
        Self([
            Vec4::select(mask.0[0], t.0[0], f.0[0]),
            Vec4::select(mask.0[1], t.0[1], f.0[1]),
        ])
    }

    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // glam's `Vec4::max` is x86's `maxps`, exactly the trait's rule; on other targets it
        // may pass NaN through (NEON's `vmaxq_f32`), so the rule is spelled out there.
        #[cfg(target_arch = "x86_64")]
        {
            halves!(|a, b| a.max(b), self, o)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Self::select(self.cmpgt(o), self, o)
        }
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        halves!(|a| a.sqrt(), self)
    }

    #[inline(always)]
    fn recip(self) -> Self {
        halves!(|a| a.recip(), self)
    }

    #[inline(always)]
    fn abs(self) -> Self {
        halves!(|a| a.abs(), self)
    }

    #[inline(always)]
    fn is_finite_mask(self) -> M8 {
        M8([self.0[0].is_finite_mask(), self.0[1].is_finite_mask()])
    }

    compare!(cmpgt);
    compare!(cmplt);
    compare!(cmple);
    compare!(cmpeq);
}

impl LaneMask for M8 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0[0].any() || self.0[1].any()
    }
}

/// Eight 3-vectors, one per lane, stored by component.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct V3x8<F = F8> {
    /// The x components of the eight lanes.
    pub x: F,
    /// The y components.
    pub y: F,
    /// The z components.
    pub z: F,
}

impl<F: Lane> V3x8<F> {
    /// Packs eight vectors, lane i from `v[i]`.
    #[inline(always)]
    pub fn from_lanes(v: [Vec3; WIDTH]) -> Self {
        Self {
            x: F::from_array(v.map(|v| v.x)),
            y: F::from_array(v.map(|v| v.y)),
            z: F::from_array(v.map(|v| v.z)),
        }
    }

    /// All lanes zero.
    pub const ZERO: Self = Self {
        x: F::ZERO,
        y: F::ZERO,
        z: F::ZERO,
    };

    /// Lane `i` as a vector.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets lane `i` to `v`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        self.x[i] = v.x;
        self.y[i] = v.y;
        self.z[i] = v.z;
    }

    /// Lane-wise dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> F {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Component-wise product (a per-axis scale of each lane's vector).
    #[inline(always)]
    pub fn scale(self, o: Self) -> Self {
        Self {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// The lanes whose three components are equal (an inverse mass the same along every
    /// axis: no translation lock).
    #[inline(always)]
    pub fn uniform(self) -> F::Mask {
        self.x.cmpeq(self.y) & self.y.cmpeq(self.z)
    }

    /// Lane-wise cross product.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

impl<F: Lane> Add for V3x8<F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<F: Lane> Sub for V3x8<F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl<F: Lane> Mul<F> for V3x8<F> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl<F: Lane> AddAssign for V3x8<F> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<F: Lane> SubAssign for V3x8<F> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

/// Eight unit quaternions, one per lane, stored by component.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Q8<F = F8> {
    /// The vector parts (x, y, z) of the eight lanes.
    pub v: V3x8<F>,
    /// The scalar parts (w).
    pub w: F,
}

impl<F: Lane> Q8<F> {
    /// All lanes the identity rotation.
    pub const IDENTITY: Self = Self {
        v: V3x8::ZERO,
        w: F::ONE,
    };

    /// Sets lane `i` to `q`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, q: Quat) {
        self.v.set_lane(i, Vec3::new(q.x, q.y, q.z));
        self.w[i] = q.w;
    }

    /// Rotates `r` by each lane's quaternion: r + w·t + v × t with t = 2·(v × r), the
    /// expansion of q·r·q* for a unit q.
    #[inline(always)]
    pub fn rotate(&self, r: V3x8<F>) -> V3x8<F> {
        let t = self.v.cross(r) * F::splat(2.0);
        r + t * self.w + self.v.cross(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes() -> [Vec3; WIDTH] {
        std::array::from_fn(|i| {
            let f = i as f32;
            Vec3::new(1.0 + f, 2.0 - 0.5 * f * f, 3.0 - 2.0 * f)
        })
    }

    #[test]
    fn lane_operations_match_the_scalar_ones() {
        let a = lanes();
        let b = a.map(|v| Vec3::new(v.z, -v.x, v.y * 0.5));
        let (wa, wb) = (V3x8::<F8>::from_lanes(a), V3x8::<F8>::from_lanes(b));
        for i in 0..WIDTH {
            assert_eq!(wa.dot(wb)[i], a[i].dot(b[i]));
            assert_eq!(wa.cross(wb).lane(i), a[i].cross(b[i]));
            assert_eq!((wa - wb).lane(i), a[i] - b[i]);
        }
    }

    #[test]
    fn rotation_matches_glam_quaternions() {
        let q: [Quat; WIDTH] = std::array::from_fn(|i| match i {
            0 => Quat::IDENTITY,
            _ => Quat::from_axis_angle(
                Vec3::new(1.0, i as f32, -1.0).normalize(),
                0.9 * i as f32 - 3.0,
            ),
        });
        let r = lanes();
        let mut packed = Q8::<F8>::IDENTITY;
        for (i, q) in q.iter().enumerate() {
            packed.set_lane(i, *q);
        }
        let rotated = packed.rotate(V3x8::from_lanes(r));
        for i in 0..WIDTH {
            let d = rotated.lane(i) - q[i] * r[i];
            assert!(d.length() < 1e-5, "lane {i}: {d}");
        }
    }
}
