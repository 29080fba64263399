//! Contacts of flat-faced convex shapes (convex hulls; a hull or a cylinder with a box or a
//! cylinder; also as compounds' parts) checked against their separating axes (the faces'
//! normals and the cross products of their edges).
//!
//! parry 0.31 finds the contact of two such shapes from the closest points of its GJK (or its
//! EPA's deepest penetration), whose direction is the rounding error of the difference of two
//! nearly equal points when the shapes are within a few micrometres of touching: two hull cubes
//! stacked 10⁻⁶ of their size apart got one point with a normal along x, or no contact at all;
//! exactly touching, a diagonal normal (a 5 m hull cube reported 14 m deep along it); turned
//! 0.1° about the vertical, four points along a normal 35° off it; coins the same. A stack of
//! hulls built touching, or resting at the solver's slop, then has its contacts missing or
//! pointing sideways (a column of five 7.5 mm hull cubes fell 13 mm into itself before their
//! contacts appeared). Compounds of such shapes the same, part by part. Two boxes are
//! unaffected: parry separates them by their faces' axes; so are shapes on a triangle mesh.
//!
//! [`check`] keeps parry's answer unless it contradicts what the shapes' support points prove
//! (the distance of two convex shapes is at least their gap along any axis): no contact where
//! the best separating axis leaves the shapes within the prediction distance and their support
//! features along it overlap there; a normal along which the shapes do not lie as the answer's
//! closest point says; a closest point nearer than the gap along an axis allows. The
//! disagreement must exceed 5% of the smaller shape's size ([`AGREEMENT`]): parry's errors
//! here are of the order of the size, while a cylinder's square caps and an EPA normal make
//! sound answers differ by millimetres. A contradicted answer is replaced by the contact along
//! the best separating axis (the face normals of both shapes, a cylinder's two caps, and the
//! cross products of an edge of each, which decide where two hulls meet edge across edge),
//! clipped from the two support features with parry's own clipping. The line of centres is
//! looked at first (two support points), so a sound answer costs four support points and the
//! axes are scanned only for suspect ones.

use crate::narrow_phase::manifold_pos12;
use jostle_math::Vec3;
use parry3d::math::Pose;
use parry3d::query::ContactManifold;
use parry3d::shape::{
    Compound, ConvexPolyhedron, Cuboid, Cylinder, PolygonalFeature, PolygonalFeatureMap, Shape,
    ShapeType, SupportMap,
};

/// A convex shape with flat faces whose normals parry lists (a cylinder's two caps).
#[derive(Clone, Copy)]
enum Polytope<'a> {
    Cuboid(&'a Cuboid),
    Hull(&'a ConvexPolyhedron),
    Cylinder(&'a Cylinder),
}

impl<'a> Polytope<'a> {
    fn of(shape: &'a dyn Shape) -> Option<Self> {
        match shape.shape_type() {
            ShapeType::Cuboid => shape.as_cuboid().map(Self::Cuboid),
            ShapeType::ConvexPolyhedron => shape.as_convex_polyhedron().map(Self::Hull),
            ShapeType::Cylinder => shape.as_cylinder().map(Self::Cylinder),
            _ => None,
        }
    }

    fn support(&self) -> &dyn SupportMap {
        match self {
            Self::Cuboid(c) => *c,
            Self::Hull(h) => *h,
            Self::Cylinder(c) => *c,
        }
    }

    fn features(&self) -> &dyn PolygonalFeatureMap {
        match self {
            Self::Cuboid(c) => *c,
            Self::Hull(h) => *h,
            Self::Cylinder(c) => *c,
        }
    }

    /// The outward unit normals of the faces, in the shape's frame (a box's six).
    fn for_each_normal(&self, mut f: impl FnMut(Vec3)) {
        match self {
            Self::Cuboid(_) => {
                for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
                    f(axis);
                    f(-axis);
                }
            }
            Self::Hull(h) => h.faces().iter().for_each(|face| f(face.normal)),
            Self::Cylinder(_) => {
                f(Vec3::Y);
                f(-Vec3::Y);
            }
        }
    }

    /// The directions of the edges, in the shape's frame (a box's three; none for a cylinder,
    /// whose rims are curves).
    fn for_each_edge(&self, mut f: impl FnMut(Vec3)) {
        match self {
            Self::Cuboid(_) => [Vec3::X, Vec3::Y, Vec3::Z].into_iter().for_each(f),
            Self::Hull(h) => h.edges().iter().for_each(|edge| f(edge.dir)),
            Self::Cylinder(_) => {}
        }
    }

    /// Half the largest side of the bounding box (m).
    fn size(&self) -> f32 {
        match self {
            Self::Cuboid(c) => c.half_extents.max_element(),
            Self::Hull(h) => h.local_aabb().half_extents().max_element(),
            Self::Cylinder(c) => c.half_height.max(c.radius),
        }
    }
}

/// How far apart shape 2 lies from shape 1 along the unit direction `axis` of shape 1's frame
/// (negative: overlap along it), with shape 2 at `pos12`.
pub(crate) fn separation(
    s1: &dyn SupportMap,
    s2: &dyn SupportMap,
    pos12: &Pose,
    axis: Vec3,
) -> f32 {
    axis.dot(s2.support_point(pos12, -axis)) - axis.dot(s1.local_support_point(axis))
}

/// The face normal of either shape (in shape 1's frame, pointing from shape 1 toward shape
/// 2) along which the shapes lie furthest apart, with that separation.
fn best_face_axis(p1: Polytope, p2: Polytope, pos12: &Pose) -> (Vec3, f32) {
    let (s1, s2) = (p1.support(), p2.support());
    let mut best = (Vec3::Y, f32::NEG_INFINITY);
    let mut consider = |axis: Vec3| {
        let gap = separation(s1, s2, pos12, axis);
        if gap > best.1 {
            best = (axis, gap);
        }
    };
    p1.for_each_normal(&mut consider);
    p2.for_each_normal(|n| consider(-(pos12.rotation * n)));
    best
}

/// The cross product of an edge of each shape (in shape 1's frame, either way along it) along
/// which the shapes lie furthest apart, with that separation (−∞ where no two edges cross: a
/// cylinder's rims are curves). Two cubes meeting edge across edge are separated along one.
fn best_edge_axis(p1: Polytope, p2: Polytope, pos12: &Pose) -> (Vec3, f32) {
    let (s1, s2) = (p1.support(), p2.support());
    let mut best = (Vec3::Y, f32::NEG_INFINITY);
    p1.for_each_edge(|e1| {
        p2.for_each_edge(|e2| {
            if let Some(axis) = e1.cross(pos12.rotation * e2).try_normalize() {
                for axis in [axis, -axis] {
                    let gap = separation(s1, s2, pos12, axis);
                    if gap > best.1 {
                        best = (axis, gap);
                    }
                }
            }
        });
    });
    best
}

/// The contact of two polytopes at `pos12` along the unit `axis` of shape 1's frame (from
/// shape 1 toward shape 2), clipped from their support features with parry's clipping; `None`
/// unless its closest point is the shapes' `gap` along the axis (within `tolerance`): where the
/// features do not overlap along the axis (shapes corner to corner, say), or not where the
/// shapes come closest.
fn contact_along<D: Default + Copy>(
    p1: Polytope,
    p2: Polytope,
    pos12: &Pose,
    (axis, gap): (Vec3, f32),
    prediction: f32,
    tolerance: f32,
) -> Option<ContactManifold<(), D>> {
    let contact = clip_along(p1.features(), p2.features(), pos12, axis, prediction);
    let closest = contact
        .points
        .iter()
        .map(|p| p.dist)
        .fold(f32::MAX, f32::min);
    if (closest - gap).abs() > tolerance {
        return None;
    }
    Some(contact)
}

/// The contact of two shapes at `pos12` along the unit `axis` of shape 1's frame (from shape
/// 1 toward shape 2): their support features along it clipped against each other with
/// parry's clipping, the points within `prediction`, the normals the axis.
pub(crate) fn clip_along<D: Default + Copy>(
    f1: &dyn PolygonalFeatureMap,
    f2: &dyn PolygonalFeatureMap,
    pos12: &Pose,
    axis: Vec3,
    prediction: f32,
) -> ContactManifold<(), D> {
    let mut contact = ContactManifold::<(), D>::with_data(0, 0, ());
    let mut feature1 = PolygonalFeature::default();
    let mut feature2 = PolygonalFeature::default();
    let axis2 = pos12.rotation.inverse() * -axis;
    f1.local_support_feature(axis, &mut feature1);
    f2.local_support_feature(axis2, &mut feature2);
    PolygonalFeature::contacts(
        pos12,
        &pos12.inverse(),
        axis,
        axis2,
        &feature1,
        &feature2,
        &mut contact,
        false,
    );
    contact.points.retain(|p| p.dist <= prediction);
    contact.local_n1 = axis;
    contact.local_n2 = axis2;
    contact
}

/// How much further apart (relative to the smaller shape's size) the shapes must lie along an
/// edge–edge axis than along every face normal for the edges to decide the contact: faces
/// give the steadier contacts, and stacked boxes have edge axes along their faces' normals.
const EDGE_MARGIN: f32 = 1e-3;

/// The tolerance (relative to the smaller shape's size) within which parry's answer is taken
/// to agree with the support points. parry's errors here are of the order of the shapes' size
/// (a sideways or diagonal normal). At 10⁻³ the check also overruled 11,411 answers in 300
/// steps of `assets/rain_1000.ron` (tumbling tetrahedra and cylinders, millimetres apart
/// between the clipped features and the exact support points, where a face axis is not
/// always the right normal); at 5% it overrules 51 there: 5 answers with no contact where the
/// shapes touch, 46 whose normal contradicts their closest point by more than 5% of the size.
const AGREEMENT: f32 = 0.05;

/// Checks parry's contact manifolds of two shapes at `pos12` (shape 2's pose in shape 1's
/// frame) against their separating axes ([`best_face_axis`], [`best_edge_axis`]), and corrects
/// them where they contradict them (see the module's header): the pair's one manifold for two convex shapes, each part
/// pair's for compounds. Pairs that are not both polytopes, and two boxes, are left alone.
pub(crate) fn check<D: Default + Copy>(
    pos12: &Pose,
    shape1: &dyn Shape,
    shape2: &dyn Shape,
    prediction: f32,
    manifolds: &mut Vec<ContactManifold<(), D>>,
) {
    let compounds = (compound(shape1), compound(shape2));
    if compounds.0.is_none() && compounds.1.is_none() {
        if manifolds.len() > 1 {
            return;
        }
        let (Some(p1), Some(p2)) = (Polytope::of(shape1), Polytope::of(shape2)) else {
            return;
        };
        match verdict(pos12, p1, p2, prediction, manifolds.first()) {
            Verdict::Keep => {}
            Verdict::Clear => manifolds.iter_mut().for_each(|m| m.points.clear()),
            Verdict::Replace(face) => {
                manifolds.clear();
                manifolds.push(face);
            }
        }
        return;
    }
    for m in manifolds.iter_mut() {
        let (Some(part1), Some(part2)) = (
            part(compounds.0, shape1, m.subshape1).and_then(Polytope::of),
            part(compounds.1, shape2, m.subshape2).and_then(Polytope::of),
        ) else {
            continue;
        };
        let pose = manifold_pos12(m, pos12);
        match verdict(&pose, part1, part2, prediction, Some(m)) {
            Verdict::Keep => {}
            Verdict::Clear => m.points.clear(),
            // The part pair's manifold keeps its parts and their poses.
            Verdict::Replace(face) => take_contact(m, face),
        }
    }
}

/// Puts `contact`'s points and normals in `m`, which keeps its sub-shapes, their poses and its
/// data.
pub(crate) fn take_contact<D>(m: &mut ContactManifold<(), D>, contact: ContactManifold<(), D>) {
    m.points = contact.points;
    m.local_n1 = contact.local_n1;
    m.local_n2 = contact.local_n2;
}

/// `shape` as a compound, if it is one.
fn compound(shape: &dyn Shape) -> Option<&Compound> {
    match shape.shape_type() {
        ShapeType::Compound => shape.as_compound(),
        _ => None,
    }
}

/// Part `index` of `compound`, or `whole` where the shape is no compound.
fn part<'a>(
    compound: Option<&'a Compound>,
    whole: &'a dyn Shape,
    index: u32,
) -> Option<&'a dyn Shape> {
    match compound {
        Some(c) => c.shapes().get(index as usize).map(|(_, part)| &*part.0),
        None => Some(whole),
    }
}

/// What [`check`] does with parry's answer for one pair of convex shapes.
enum Verdict<D> {
    /// The answer agrees with the support points.
    Keep,
    /// An axis separates the shapes by more than the prediction distance.
    Clear,
    /// The contact along the best separating axis, in place of a contradicted answer.
    Replace(ContactManifold<(), D>),
}

/// The [`Verdict`] on parry's `answer` for two polytopes at `pos12` (`None`: no manifold).
fn verdict<D: Default + Copy>(
    pos12: &Pose,
    p1: Polytope,
    p2: Polytope,
    prediction: f32,
    answer: Option<&ContactManifold<(), D>>,
) -> Verdict<D> {
    if matches!((p1, p2), (Polytope::Cuboid(_), Polytope::Cuboid(_))) {
        return Verdict::Keep;
    }
    let (s1, s2) = (p1.support(), p2.support());
    let tolerance = AGREEMENT * p1.size().min(p2.size());
    // parry's answer: its closest point's distance, and whether the shapes lie along its
    // normal as that distance says.
    let answer = answer.filter(|m| !m.points.is_empty()).map(|m| {
        let closest = m.points.iter().map(|p| p.dist).fold(f32::MAX, f32::min);
        let consistent = m
            .local_n1
            .try_normalize()
            .is_some_and(|n| (separation(s1, s2, pos12, n) - closest).abs() <= tolerance);
        (closest, consistent)
    });
    // A first look along the line of centres: the shapes' distance is at least their gap
    // along any axis, so no answer may come closer than that, and beyond the prediction
    // distance along it an empty answer is right.
    let centres = pos12.translation.try_normalize().unwrap_or(Vec3::Y);
    let gap_centres = separation(s1, s2, pos12, centres);
    match answer {
        Some((closest, true)) if closest >= gap_centres - tolerance => return Verdict::Keep,
        None if gap_centres > prediction => return Verdict::Keep,
        _ => {}
    }
    // The faces first: where the shapes lie apart along the best face normal and their features
    // meet there, the shapes' distance is that gap, and no other axis can show them further
    // apart.
    let faces = best_face_axis(p1, p2, pos12);
    if faces.1 > prediction {
        // Apart along a face normal: no contact, whatever was answered.
        return Verdict::Clear;
    }
    let agrees = |gap: f32| matches!(answer, Some((closest, true)) if closest >= gap - tolerance);
    if agrees(faces.1) {
        return Verdict::Keep;
    }
    let on_faces = contact_along(p1, p2, pos12, faces, prediction, tolerance);
    if faces.1 >= 0.0
        && let Some(contact) = on_faces
    {
        return Verdict::Replace(contact);
    }
    // Overlapping along every face normal, or no contact there: the edges decide if they show
    // the shapes further apart by the margin.
    let edges = best_edge_axis(p1, p2, pos12);
    if edges.1 <= faces.1 + EDGE_MARGIN * p1.size().min(p2.size()) {
        return on_faces.map_or(Verdict::Keep, Verdict::Replace);
    }
    if edges.1 > prediction {
        return Verdict::Clear;
    }
    if agrees(edges.1) {
        return Verdict::Keep;
    }
    contact_along(p1, p2, pos12, edges, prediction, tolerance)
        .map_or(Verdict::Keep, Verdict::Replace)
}
