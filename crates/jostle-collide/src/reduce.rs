//! Contact-manifold reduction to at most four points.
//!
//! In: the points of one manifold (parry may clip up to eight for two boxes face to face) and
//! its normal. Out: the same list restricted, in its original order, to at most
//! [`MAX_POINTS`]: the deepest point, the point farthest from it, the point making the largest
//! triangle with those two, and the point adding the most area to that triangle. Four points
//! spanning the largest area support a resting body as well as the full patch does, and keep
//! the resolver's work per manifold bounded (the choice Box2D, Bullet and Jolt make too).

use jostle_math::Vec3;
use parry3d::query::TrackedContact;

/// The most points a reduced manifold keeps.
pub const MAX_POINTS: usize = 4;

/// Restricts `points` to at most [`MAX_POINTS`], keeping the original order. Points are
/// compared in the first shape's frame (`local_p1`), in which `normal` is expressed.
pub fn reduce_manifold<D: Copy>(points: &mut Vec<TrackedContact<D>>, normal: Vec3) {
    if points.len() <= MAX_POINTS {
        return;
    }
    let keep = select(points, normal);
    let mut k = 0;
    points.retain(|_| {
        let kept = keep.contains(&k);
        k += 1;
        kept
    });
}

/// Indices of the points to keep (at most four, possibly fewer if the patch is degenerate).
fn select<D>(points: &[TrackedContact<D>], normal: Vec3) -> Vec<usize> {
    let p = |i: usize| points[i].local_p1;
    // Ties break on the lower index (strict comparisons), so the choice is deterministic.
    let argmax = |score: &dyn Fn(usize) -> f32| {
        (0..points.len()).fold((0, f32::NEG_INFINITY), |best, i| {
            let s = score(i);
            if s > best.1 { (i, s) } else { best }
        })
    };
    let (a, _) = argmax(&|i| -points[i].dist);
    let (b, dab) = argmax(&|i| p(i).distance_squared(p(a)));
    if dab <= 0.0 {
        return vec![a];
    }
    let (c, area) = argmax(&|i| (p(b) - p(a)).cross(p(i) - p(a)).length_squared());
    if area <= 0.0 {
        return vec![a, b];
    }
    // Orient the triangle so its signed area along the normal is positive; a point outside
    // edge (u, v) then has a negative signed area with it, and adds |that| to the hull.
    let signed = |u: Vec3, v: Vec3, w: Vec3| (v - u).cross(w - u).dot(normal);
    let (b, c) = if signed(p(a), p(b), p(c)) >= 0.0 {
        (b, c)
    } else {
        (c, b)
    };
    let (d, gain) = argmax(&|i| {
        let q = p(i);
        -signed(p(a), p(b), q)
            .min(signed(p(b), p(c), q))
            .min(signed(p(c), p(a), q))
    });
    if gain <= 0.0 {
        vec![a, b, c]
    } else {
        vec![a, b, c, d]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::shape::PackedFeatureId;

    fn contact(x: f32, z: f32, dist: f32) -> TrackedContact<u32> {
        let p = Vec3::new(x, 0.0, z);
        TrackedContact::new(
            p,
            p,
            PackedFeatureId::UNKNOWN,
            PackedFeatureId::UNKNOWN,
            dist,
        )
    }

    #[test]
    fn keeps_the_deepest_and_the_widest_quad() {
        // An octagon-like patch (the clip of two rotated boxes) plus an interior point.
        let mut pts = vec![
            contact(0.0, 0.0, -0.05), // deepest, interior
            contact(1.0, 0.2, -0.01),
            contact(1.0, -0.2, -0.01),
            contact(-1.0, 0.2, -0.01),
            contact(-1.0, -0.2, -0.01),
            contact(0.2, 1.0, -0.01),
            contact(-0.2, -1.0, -0.01),
            contact(0.1, 0.1, -0.01),
        ];
        for (i, p) in pts.iter_mut().enumerate() {
            p.data = i as u32;
        }
        reduce_manifold(&mut pts, Vec3::Y);
        let kept: Vec<u32> = pts.iter().map(|p| p.data).collect();
        assert_eq!(kept.len(), 4);
        assert!(
            kept.contains(&0),
            "the deepest point must be kept: {kept:?}"
        );
        assert!(
            kept.windows(2).all(|w| w[0] < w[1]),
            "original order must be kept: {kept:?}"
        );
        assert!(
            !kept.contains(&7),
            "an interior point adds no area: {kept:?}"
        );
    }

    #[test]
    fn four_or_fewer_are_untouched() {
        let mut pts = vec![
            contact(0.0, 0.0, 0.0),
            contact(1.0, 0.0, 0.0),
            contact(0.0, 1.0, 0.0),
        ];
        reduce_manifold(&mut pts, Vec3::Y);
        assert_eq!(pts.len(), 3);
    }

    #[test]
    fn a_square_of_eight_keeps_its_corners() {
        let mut pts: Vec<_> = [
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
        ]
        .iter()
        .map(|&(x, z)| contact(x, z, -0.01))
        .collect();
        reduce_manifold(&mut pts, Vec3::Y);
        assert_eq!(pts.len(), 4);
        for p in &pts {
            assert_eq!(p.local_p1.x.abs(), 1.0, "{:?}", p.local_p1);
            assert_eq!(p.local_p1.z.abs(), 1.0, "{:?}", p.local_p1);
        }
    }
}
