//! Contacts with a triangle much larger than the shape on it, recomputed against a patch of the
//! triangle around the shape.
//!
//! parry 0.31 finds the contact of a triangle and a rounded or flat-faced convex shape
//! (cylinder, capsule, convex hull) with its GJK, on the Minkowski difference of the two: with
//! a triangle thousands of times the shape's size its vertices lie that far from the shape,
//! and the closest points come out wrong by a fraction of the shape. A cylinder of 1 cm radius
//! lying exactly on a mesh of two 200 m triangles got its points 7 mm off its lowest line and
//! 2.9 mm "apart"; it rolled with growing speed and fell through the mesh. A 10 cm cylinder on
//! a 2 km mesh sank 4 cm into it, a capsule of 5 cm radius 1.3 cm (on a half-space: 0.2 and
//! 0.7 mm).
//!
//! Where the shape's bounding sphere, grown by the prediction distance, lies over the
//! triangle's interior, away from its edges, only the triangle's plane can touch the shape, so
//! [`refine`] asks parry again with an equilateral triangle in the same plane that covers that
//! sphere's shadow: the same contact, from vertices near the shape. Where the sphere's shadow
//! crosses one edge of the triangle (two large triangles meeting under the shape), the patch
//! is a triangle on that edge whose other sides stay outside the shadow. The query takes the
//! mesh's pseudo-normals; the patch's face has the triangle's face id, so points on it keep
//! their carried impulses (a point on the edge takes the patch's edge id). Where the sphere
//! cannot reach the triangle at all (farther from its plane, or beyond one of its edges, than
//! its radius) the manifold is emptied: whatever parry found there is its error. Near a large
//! triangle's vertex (two edges in the shadow) parry's answer is kept.
//!
//! Then, on every triangle, large or not, a flat-faced shape (box, cylinder, hull) whose
//! contact normal is the face's gets its points clipped along the face normal ([`on_face`]):
//! within a micrometre of touching parry took the shape's support feature along a direction
//! turned by rounding, and a cylinder lying on a 20 m floor rolled away.

use crate::polytope::take_contact;
use jostle_math::Vec3;
use parry3d::math::Pose;
use parry3d::query::details::NormalConstraints;
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{Shape, ShapeType, TriMesh, Triangle};

/// A triangle is refined when its longest edge is at least this many times the radius of the
/// shape's neighbourhood (its bounding sphere plus the prediction distance). parry's answers
/// were measured wrong from about 5,000 (a 1 cm cylinder on 200 m triangles, 5,400; 10 cm
/// shapes on 2 km triangles, 8,000 to 18,000) and right at 840 and below; the patch costs a
/// second query, so it is asked from 1,000.
const LARGE: f32 = 1000.0;

/// Recomputes each of `manifolds` (a mesh and a convex shape other than a ball, `pos12` shape
/// 2's pose in shape 1's frame) whose triangle is [`LARGE`] beside the shape against a patch of
/// the triangle around the shape, and clips a flat-faced shape's points on a face along its
/// normal ([`on_face`]; the module docs). Other pairs of shapes are left as they are.
pub(crate) fn refine<D: Default + Copy + Send + Sync + 'static>(
    pos12: &Pose,
    shape1: &dyn Shape,
    shape2: &dyn Shape,
    prediction: f32,
    manifolds: &mut [ContactManifold<(), D>],
) {
    let (mesh, other, mesh_first) = match (trimesh(shape1), trimesh(shape2)) {
        (Some(m), None) => (m, shape2, true),
        (None, Some(m)) => (m, shape1, false),
        _ => return,
    };
    if !other.is_convex() || other.shape_type() == ShapeType::Ball {
        // A ball's contact with a triangle is exact in parry; composites and meshes are
        // handled part by part there.
        return;
    }
    // The other shape's pose in the mesh's frame (a mesh's triangles carry no pose of their
    // own).
    let in_mesh = if mesh_first { *pos12 } else { pos12.inverse() };
    let sphere = other.compute_local_bounding_sphere();
    let centre = in_mesh * sphere.center;
    let reach = sphere.radius + prediction.max(0.0);
    // A flat-faced shape without a rounded border, for the face contacts below.
    let flat = other
        .as_polygonal_feature_map()
        .filter(|(_, border)| *border == 0.0)
        .map(|(features, _)| features);
    for m in manifolds.iter_mut() {
        let index = if mesh_first { m.subshape1 } else { m.subshape2 };
        if index as usize >= mesh.num_triangles() {
            continue;
        }
        let triangle = mesh.triangle(index);
        // The triangle whose face the points lie on: the mesh's, or the patch standing in.
        let face = match patch(&triangle, centre, reach) {
            Patch::Keep => triangle,
            Patch::Apart => {
                m.points.clear();
                continue;
            }
            Patch::Over(patch) => {
                let constraints = mesh.triangle_normal_constraints(index);
                let constraints = constraints.as_ref().map(|c| c as &dyn NormalConstraints);
                let mut fresh: ContactManifold<(), D> = ContactManifold::new();
                let answer = if mesh_first {
                    DefaultQueryDispatcher.contact_manifold_convex_convex(
                        pos12,
                        &patch,
                        other,
                        constraints,
                        None,
                        prediction,
                        &mut fresh,
                    )
                } else {
                    DefaultQueryDispatcher.contact_manifold_convex_convex(
                        pos12,
                        other,
                        &patch,
                        None,
                        constraints,
                        prediction,
                        &mut fresh,
                    )
                };
                if answer.is_err() {
                    continue;
                }
                // The manifold keeps its triangle and its data; the points are the patch's.
                take_contact(m, fresh);
                patch
            }
        };
        if let Some(features) = flat {
            on_face(m, &face, features, pos12, mesh_first, prediction);
        }
    }
}

/// How close (cosine) parry's normal must be to a triangle's face normal for the contact to be
/// taken as one on the face ([`on_face`]): 0.1°.
const ON_FACE: f32 = 0.999_998_5;

/// Where `m`, the contact of a triangle and a flat-faced shape, is one on the triangle's face
/// (parry's normal within [`ON_FACE`] of the face normal), its points clipped again from the
/// shape's support feature along the face normal: parry takes that feature along its GJK's
/// direction, which within a micrometre of touching is the rounding error of two nearly equal
/// points; the normal comes out as the face's (the mesh's pseudo-normals project it there) but
/// the feature is turned. A cylinder of 1 cm radius lying on a mesh got its two points 48 µm
/// behind its lowest line, and the push there rolled it faster each step (0.4 m in 5 s). The
/// points of the face clipping are exact on a face; the normal is unchanged.
fn on_face<D: Default + Copy>(
    m: &mut ContactManifold<(), D>,
    triangle: &Triangle,
    features: &dyn parry3d::shape::PolygonalFeatureMap,
    pos12: &Pose,
    mesh_first: bool,
    prediction: f32,
) {
    if m.points.is_empty() {
        return;
    }
    let Some(face) = (triangle.b - triangle.a)
        .cross(triangle.c - triangle.a)
        .try_normalize()
    else {
        return;
    };
    // parry's normal out of the triangle, in the mesh's frame.
    let normal = if mesh_first { m.local_n1 } else { m.local_n2 };
    let face = if face.dot(normal) >= 0.0 { face } else { -face };
    if face.dot(normal) < ON_FACE {
        return;
    }
    let fresh: ContactManifold<(), D> = if mesh_first {
        crate::polytope::clip_along(triangle, features, pos12, face, prediction)
    } else {
        let in_other = pos12.rotation * -face;
        crate::polytope::clip_along(features, triangle, pos12, in_other, prediction)
    };
    if !fresh.points.is_empty() {
        take_contact(m, fresh);
    }
}

/// `shape` as a triangle mesh, if it is one.
fn trimesh(shape: &dyn Shape) -> Option<&TriMesh> {
    match shape.shape_type() {
        ShapeType::TriMesh => shape.as_trimesh(),
        _ => None,
    }
}

/// What to do with a large triangle's manifold ([`patch`]).
enum Patch {
    /// Keep parry's answer: the triangle is not large beside the shape, or the shape lies near
    /// one of its vertices.
    Keep,
    /// The shape cannot reach the triangle: no points.
    Apart,
    /// Recompute against this patch.
    Over(Triangle),
}

/// The patch of `triangle` that stands in for it within the sphere at `centre` of radius
/// `reach` (the shape's neighbourhood), when the triangle's longest edge is at least [`LARGE`]
/// times `reach`: the sphere's shadow on the triangle's plane is the patch's inscribed circle
/// where it lies inside the triangle farther than `reach` from every edge (an equilateral
/// triangle); where it crosses one edge, the patch is a triangle on that edge reaching
/// `4·reach` along it each way and `4·reach` into the triangle, whose slanted sides pass
/// `2.8·reach` from the shadow's centre. The same winding (face normal) as the triangle.
fn patch(triangle: &Triangle, centre: Vec3, reach: f32) -> Patch {
    let (a, b, c) = (triangle.a, triangle.b, triangle.c);
    let longest = (b - a)
        .length_squared()
        .max((c - b).length_squared())
        .max((a - c).length_squared())
        .sqrt();
    if !(reach > 0.0 && longest >= LARGE * reach) {
        return Patch::Keep;
    }
    let Some(normal) = (b - a).cross(c - a).try_normalize() else {
        return Patch::Keep;
    };
    let height = normal.dot(centre - a);
    if height.abs() > reach {
        return Patch::Apart;
    }
    let foot = centre - height * normal;
    // The edges the shadow reaches: (start, unit direction, inward unit normal, distance of
    // the foot inside).
    let mut near = None;
    for (p, q) in [(a, b), (b, c), (c, a)] {
        let along = (q - p).normalize();
        let inward = normal.cross(along);
        let inside = inward.dot(foot - p);
        if inside < -reach {
            return Patch::Apart;
        }
        if inside <= reach {
            if near.is_some() {
                // Near a vertex.
                return Patch::Keep;
            }
            near = Some((p, along, inward));
        }
    }
    let triangle = match near {
        None => {
            // Vertices at twice the inradius from the centre, a third of a turn apart,
            // counter-clockwise about the normal as the triangle's own.
            let u = (b - a).normalize();
            let v = normal.cross(u);
            let vertex = |turn: f32| {
                let (s, co) = turn.sin_cos();
                foot + 2.0 * reach * (co * u + s * v)
            };
            let third = std::f32::consts::TAU / 3.0;
            Triangle::new(vertex(0.0), vertex(third), vertex(2.0 * third))
        }
        Some((p, along, inward)) => {
            // along × inward = normal: (base − s, base + s, apex) winds as the triangle.
            let base = p + along * along.dot(foot - p);
            let s = 4.0 * reach;
            Triangle::new(base - s * along, base + s * along, base + s * inward)
        }
    };
    Patch::Over(triangle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_patch_keeps_the_plane_and_winding_and_covers_the_shadow() {
        let big = Triangle::new(
            Vec3::new(-1000.0, 0.0, -1000.0),
            Vec3::new(1000.0, 0.0, 1000.0),
            Vec3::new(1000.0, 0.0, -1000.0),
        );
        let centre = Vec3::new(300.0, 0.02, -200.0);
        let Patch::Over(p) = patch(&big, centre, 0.05) else {
            panic!("no patch");
        };
        let n = (p.b - p.a).cross(p.c - p.a).normalize();
        let n0 = (big.b - big.a).cross(big.c - big.a).normalize();
        assert!(n.dot(n0) > 0.9999, "{n} against {n0}");
        for v in [p.a, p.b, p.c] {
            assert!(v.y.abs() < 1e-6, "{v}: off the plane");
            // Circumradius twice the inradius.
            assert!(((v - Vec3::new(300.0, 0.0, -200.0)).length() - 0.1).abs() < 1e-4);
        }
        // Too high above the plane, or beyond an edge: apart. A triangle not large beside the
        // shape, or a shape near a vertex: parry's answer.
        assert!(matches!(
            patch(&big, Vec3::new(300.0, 0.2, -200.0), 0.05),
            Patch::Apart
        ));
        assert!(matches!(
            patch(&big, Vec3::new(1000.1, 0.0, -200.0), 0.05),
            Patch::Apart
        ));
        assert!(matches!(patch(&big, centre, 200.0), Patch::Keep));
        assert!(matches!(
            patch(&big, Vec3::new(999.97, 0.0, -999.98), 0.05),
            Patch::Keep
        ));
        // Over an edge: a patch on it, the same winding, the edge's line as its first side.
        let Patch::Over(e) = patch(&big, Vec3::new(999.97, 0.0, -200.0), 0.05) else {
            panic!("no patch over the edge");
        };
        let ne = (e.b - e.a).cross(e.c - e.a).normalize();
        assert!(ne.dot(n0) > 0.9999, "{ne}");
        assert!(
            (e.a.x - 1000.0).abs() < 1e-3 && (e.b.x - 1000.0).abs() < 1e-3,
            "{e:?}"
        );
        assert!(e.c.x < 1000.0, "{e:?}: the apex outside");
    }
}
