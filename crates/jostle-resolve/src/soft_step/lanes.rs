//! Eight-lane arithmetic for the soft-step kernels: one lane per contact manifold.
//!
//! [`F8`] is eight `f32` lanes held as two glam `Vec4`s, each a 128-bit SIMD register on
//! x86-64 (SSE2) and aarch64 (NEON) and four plain floats elsewhere. Eight lanes rather than
//! four because a batch's points are solved one after the other, each depending on the
//! velocities the previous one left: one four-lane chain keeps the CPU waiting on latency,
//! two independent halves interleaved keep it busy. [`V3x8`] is eight 3-vectors stored by
//! component (x of the eight lanes, then y, then z), so a dot product of eight lanes is three
//! multiplies and two adds per half and a cross product six multiplies and three
//! subtractions, with no shuffles. [`Q8`] is eight quaternions stored the same way. Every
//! operation is lane-wise IEEE arithmetic, so results do not depend on the lane a contact
//! lands in.

use jostle_math::glam::{BVec4A, Vec4};
use jostle_math::{Quat, Vec3};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Index, IndexMut, Mul, Neg, Sub, SubAssign};

/// Number of lanes.
pub const WIDTH: usize = 8;

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
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

/// Applies a `Vec4` comparison to both halves.
macro_rules! compare {
    ($name:ident) => {
        #[doc = concat!("Lane-wise `", stringify!($name), "`.")]
        #[inline]
        pub fn $name(self, o: Self) -> M8 {
            M8([self.0[0].$name(o.0[0]), self.0[1].$name(o.0[1])])
        }
    };
}

impl F8 {
    /// All lanes zero.
    pub const ZERO: Self = Self([Vec4::ZERO; 2]);
    /// All lanes one.
    pub const ONE: Self = Self([Vec4::ONE; 2]);

    /// All lanes `x`.
    #[inline]
    pub fn splat(x: f32) -> Self {
        Self([Vec4::splat(x); 2])
    }

    /// Lane i from `a[i]`.
    #[inline]
    pub fn from_array(a: [f32; WIDTH]) -> Self {
        Self([
            Vec4::new(a[0], a[1], a[2], a[3]),
            Vec4::new(a[4], a[5], a[6], a[7]),
        ])
    }

    /// Lane-wise `if mask { t } else { f }`.
    #[inline]
    pub fn select(mask: M8, t: Self, f: Self) -> Self {
        Self([
            Vec4::select(mask.0[0], t.0[0], f.0[0]),
            Vec4::select(mask.0[1], t.0[1], f.0[1]),
        ])
    }

    /// Lane-wise maximum (glam's: the second operand when either is NaN).
    #[inline]
    pub fn max(self, o: Self) -> Self {
        halves!(|a, b| a.max(b), self, o)
    }

    /// Lane-wise square root.
    #[inline]
    pub fn sqrt(self) -> Self {
        halves!(|a| a.sqrt(), self)
    }

    /// Lane-wise 1/x.
    #[inline]
    pub fn recip(self) -> Self {
        halves!(|a| a.recip(), self)
    }

    /// Lane-wise |x|.
    #[inline]
    pub fn abs(self) -> Self {
        halves!(|a| a.abs(), self)
    }

    /// The largest lane.
    #[inline]
    pub fn max_element(self) -> f32 {
        self.0[0].max(self.0[1]).max_element()
    }

    /// Lanes that are finite.
    #[inline]
    pub fn is_finite_mask(self) -> M8 {
        M8([self.0[0].is_finite_mask(), self.0[1].is_finite_mask()])
    }

    compare!(cmpgt);
    compare!(cmplt);
    compare!(cmple);
    compare!(cmpeq);
}

impl M8 {
    /// Whether any lane is set.
    #[inline]
    pub fn any(self) -> bool {
        self.0[0].any() || self.0[1].any()
    }
}

impl BitAnd for M8 {
    type Output = Self;
    #[inline]
    fn bitand(self, o: Self) -> Self {
        Self([self.0[0] & o.0[0], self.0[1] & o.0[1]])
    }
}

impl BitOr for M8 {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        Self([self.0[0] | o.0[0], self.0[1] | o.0[1]])
    }
}

impl Index<usize> for F8 {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        &self.0[i / 4][i % 4]
    }
}

impl IndexMut<usize> for F8 {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i / 4][i % 4]
    }
}

macro_rules! binary {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F8 {
            type Output = Self;
            #[inline]
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
    #[inline]
    fn neg(self) -> Self {
        halves!(|a| -a, self)
    }
}

/// Eight 3-vectors, one per lane, stored by component.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct V3x8 {
    /// The x components of the eight lanes.
    pub x: F8,
    /// The y components.
    pub y: F8,
    /// The z components.
    pub z: F8,
}

impl V3x8 {
    /// All lanes zero.
    pub const ZERO: Self = Self {
        x: F8::ZERO,
        y: F8::ZERO,
        z: F8::ZERO,
    };

    /// Packs eight vectors, lane i from `v[i]`.
    #[inline]
    pub fn from_lanes(v: [Vec3; WIDTH]) -> Self {
        Self {
            x: F8::from_array(v.map(|v| v.x)),
            y: F8::from_array(v.map(|v| v.y)),
            z: F8::from_array(v.map(|v| v.z)),
        }
    }

    /// Lane `i` as a vector.
    #[inline]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets lane `i` to `v`.
    #[inline]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        self.x[i] = v.x;
        self.y[i] = v.y;
        self.z[i] = v.z;
    }

    /// Lane-wise dot product.
    #[inline]
    pub fn dot(self, o: Self) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Lane-wise cross product.
    #[inline]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

impl Add for V3x8 {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3x8 {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Mul<F8> for V3x8 {
    type Output = Self;
    #[inline]
    fn mul(self, s: F8) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl AddAssign for V3x8 {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl SubAssign for V3x8 {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

/// Eight unit quaternions, one per lane, stored by component.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Q8 {
    /// The vector parts (x, y, z) of the eight lanes.
    pub v: V3x8,
    /// The scalar parts (w).
    pub w: F8,
}

impl Q8 {
    /// All lanes the identity rotation.
    pub const IDENTITY: Self = Self {
        v: V3x8::ZERO,
        w: F8::ONE,
    };

    /// Sets lane `i` to `q`.
    #[inline]
    pub fn set_lane(&mut self, i: usize, q: Quat) {
        self.v.set_lane(i, Vec3::new(q.x, q.y, q.z));
        self.w[i] = q.w;
    }

    /// Rotates `r` by each lane's quaternion: r + w·t + v × t with t = 2·(v × r), the
    /// expansion of q·r·q* for a unit q.
    #[inline]
    pub fn rotate(&self, r: V3x8) -> V3x8 {
        let t = self.v.cross(r) * F8::splat(2.0);
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
        let (wa, wb) = (V3x8::from_lanes(a), V3x8::from_lanes(b));
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
        let mut packed = Q8::IDENTITY;
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
