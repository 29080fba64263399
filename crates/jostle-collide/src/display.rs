//! Display meshes: a collider's shape as triangles, for renderers and exporters.
//!
//! In: a [`Collider`] (its parry shape and local pose). Out: a [`DisplayMesh`] of plain glam
//! vertices and index triples in the frame of the body the collider is attached to, so that
//! `body.orientation * v + body.position` is the vertex in world space. Curved shapes are
//! tessellated with parry's `to_trimesh` family at a fixed, modest resolution; half-spaces have
//! no finite mesh (a renderer draws them as a plane). Nothing here is used by the simulation.

use crate::collider::Collider;
use jostle_math::Vec3;
use parry3d::math::Pose;
use parry3d::shape::Shape;

/// Segments around the axis of a tessellated ball, capsule or cylinder.
const AROUND: u32 = 20;
/// Segments from pole to pole of a tessellated ball (half of them per capsule cap).
const POLE_TO_POLE: u32 = 10;

/// A shape as triangles, ready to draw.
///
/// Triangles run counter-clockwise seen from outside. For a `closed` mesh (every shape that
/// encloses a volume) a renderer may cull faces seen from behind; an open mesh (a triangle
/// mesh shape, a surface) must be drawn two-sided.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DisplayMesh {
    /// Vertex positions in the body's frame (m).
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`.
    pub indices: Vec<[u32; 3]>,
    /// Whether the mesh bounds a volume (its back faces are never visible).
    pub closed: bool,
}

impl DisplayMesh {
    /// Radius of the smallest origin-centred sphere holding every vertex (m).
    pub fn bounding_radius(&self) -> f32 {
        self.vertices.iter().map(|v| v.length()).fold(0.0, f32::max)
    }

    /// Appends a convex part placed at `pose`, turning every triangle to face away from the
    /// part's centroid. parry's tessellations are counter-clockwise from outside, but the
    /// orientation is re-derived here because backface culling depends on it and a convex part
    /// makes the check exact and cheap.
    fn push_convex(&mut self, pose: &Pose, (vertices, indices): (Vec<Vec3>, Vec<[u32; 3]>)) {
        let base = self.vertices.len() as u32;
        let placed: Vec<Vec3> = vertices.iter().map(|v| pose.transform_point(*v)).collect();
        let centroid = placed.iter().copied().sum::<Vec3>() / placed.len().max(1) as f32;
        for [a, b, c] in indices {
            let [pa, pb, pc] = [a, b, c].map(|i| placed[i as usize]);
            let n = (pb - pa).cross(pc - pa);
            if n.length_squared() <= f32::EPSILON * (pb - pa).length_squared().max(1e-12) {
                continue; // the poles of parry's spheres have zero-area fan triangles
            }
            let outward = n.dot((pa + pb + pc) / 3.0 - centroid) >= 0.0;
            let tri = if outward { [a, b, c] } else { [a, c, b] };
            self.indices.push(tri.map(|i| i + base));
        }
        self.vertices.extend(placed);
    }

    /// Appends an open surface placed at `pose`, triangles as given.
    fn push_surface(&mut self, pose: &Pose, vertices: &[Vec3], indices: &[[u32; 3]]) {
        let base = self.vertices.len() as u32;
        self.vertices
            .extend(vertices.iter().map(|v| pose.transform_point(*v)));
        self.indices
            .extend(indices.iter().map(|t| t.map(|i| i + base)));
        self.closed = false;
    }

    /// Appends `shape` placed at `pose`; `false` if the shape has no finite mesh.
    fn push_shape(&mut self, pose: &Pose, shape: &dyn Shape) -> bool {
        if let Some(s) = shape.as_ball() {
            self.push_convex(pose, s.to_trimesh(AROUND, POLE_TO_POLE));
        } else if let Some(s) = shape.as_cuboid() {
            self.push_convex(pose, s.to_trimesh());
        } else if let Some(s) = shape.as_capsule() {
            self.push_convex(pose, s.to_trimesh(AROUND, POLE_TO_POLE));
        } else if let Some(s) = shape.as_cylinder() {
            self.push_convex(pose, s.to_trimesh(AROUND));
        } else if let Some(s) = shape.as_cone() {
            self.push_convex(pose, s.to_trimesh(AROUND));
        } else if let Some(s) = shape.as_convex_polyhedron() {
            self.push_convex(pose, s.to_trimesh());
        } else if let Some(s) = shape.as_triangle() {
            self.push_surface(pose, &[s.a, s.b, s.c], &[[0, 1, 2]]);
        } else if let Some(s) = shape.as_trimesh() {
            self.push_surface(pose, s.vertices(), s.indices());
        } else if let Some(s) = shape.as_compound() {
            let mut any = false;
            for (part_pose, part) in s.shapes() {
                any |= self.push_shape(&(*pose * *part_pose), part.as_ref());
            }
            return any;
        } else {
            // Half-spaces (unbounded) and shapes no scene can describe.
            return false;
        }
        true
    }
}

impl Collider {
    /// The collider's shape as triangles in its body's frame (the local pose applied), or
    /// `None` for a shape with no finite surface (a half-space).
    ///
    /// Balls, capsules and cylinders are tessellated with 20 segments around and 10 from pole
    /// to pole; boxes and convex hulls are exact; a compound gives all its parts. The result
    /// does not change while the collider does: compute it once and keep it.
    pub fn display_mesh(&self) -> Option<DisplayMesh> {
        let mut mesh = DisplayMesh {
            closed: true,
            ..DisplayMesh::default()
        };
        (mesh.push_shape(&self.local_pose, self.shape.as_ref()) && !mesh.indices.is_empty())
            .then_some(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::{CompoundPart, ShapeDesc};
    use jostle_body::{BodySet, RigidBody};
    use jostle_math::Quat;

    fn mesh_of(desc: ShapeDesc, local: Pose) -> Option<DisplayMesh> {
        let mut bodies = BodySet::new();
        let body = bodies.insert(RigidBody::fixed());
        Collider::new(desc.build().unwrap(), body)
            .with_local_pose(local)
            .display_mesh()
    }

    /// Every triangle of a closed convex mesh faces away from `inside`, and every vertex lies
    /// on the shape's surface as `on_surface` measures it.
    fn check_convex(m: &DisplayMesh, inside: Vec3, on_surface: impl Fn(Vec3) -> bool) {
        assert!(m.closed && !m.indices.is_empty());
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.dot((a + b + c) / 3.0 - inside) > 0.0, "inward face {t:?}");
        }
        for v in &m.vertices {
            assert!(on_surface(*v), "vertex {v} is off the surface");
        }
    }

    #[test]
    fn convex_shapes_are_closed_outward_and_on_their_surface() {
        let cube = mesh_of(
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(1.0, 2.0, 3.0),
            },
            Pose::IDENTITY,
        )
        .unwrap();
        assert_eq!((cube.vertices.len(), cube.indices.len()), (8, 12));
        check_convex(&cube, Vec3::ZERO, |v| {
            (v.abs() - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-6
        });

        let ball = mesh_of(ShapeDesc::Ball { radius: 0.5 }, Pose::IDENTITY).unwrap();
        check_convex(&ball, Vec3::ZERO, |v| (v.length() - 0.5).abs() < 1e-5);
        assert!((ball.bounding_radius() - 0.5).abs() < 1e-5);

        let capsule = mesh_of(
            ShapeDesc::Capsule {
                half_height: 1.0,
                radius: 0.5,
            },
            Pose::IDENTITY,
        )
        .unwrap();
        check_convex(&capsule, Vec3::ZERO, |v| {
            let axis = Vec3::new(0.0, v.y.clamp(-1.0, 1.0), 0.0);
            ((v - axis).length() - 0.5).abs() < 1e-5
        });

        let cylinder = mesh_of(
            ShapeDesc::Cylinder {
                half_height: 1.0,
                radius: 0.5,
            },
            Pose::IDENTITY,
        )
        .unwrap();
        check_convex(&cylinder, Vec3::ZERO, |v| {
            (v.y.abs() - 1.0).abs() < 1e-5 || (Vec3::new(v.x, 0.0, v.z).length() - 0.5).abs() < 1e-5
        });
    }

    #[test]
    fn the_local_pose_and_compound_parts_are_applied() {
        let offset = Vec3::new(0.0, 0.0, -2.0);
        let ball = mesh_of(
            ShapeDesc::Ball { radius: 1.0 },
            Pose::from_translation(offset),
        )
        .unwrap();
        check_convex(&ball, offset, |v| {
            ((v - offset).length() - 1.0).abs() < 1e-5
        });

        let part = |x: f32| CompoundPart {
            shape: ShapeDesc::Cuboid {
                half_extents: Vec3::splat(0.5),
            },
            position: Vec3::new(x, 0.0, 0.0),
            rotation: Quat::from_rotation_y(0.4),
        };
        let compound = mesh_of(
            ShapeDesc::Compound {
                parts: vec![part(-2.0), part(2.0)],
            },
            Pose::IDENTITY,
        )
        .unwrap();
        assert!(compound.closed);
        assert_eq!((compound.vertices.len(), compound.indices.len()), (16, 24));
        // Each part's eight corners sit around its own centre.
        for (k, centre) in [(0, -2.0), (1, 2.0)] {
            let corners = &compound.vertices[k * 8..k * 8 + 8];
            let mean = corners.iter().copied().sum::<Vec3>() / 8.0;
            assert!(
                (mean - Vec3::new(centre, 0.0, 0.0)).length() < 1e-5,
                "{mean}"
            );
        }
    }

    #[test]
    fn half_spaces_have_no_mesh_and_surfaces_are_open() {
        assert!(mesh_of(ShapeDesc::HalfSpace { normal: Vec3::Y }, Pose::IDENTITY).is_none());
        let surface = mesh_of(
            ShapeDesc::TriMesh {
                vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                indices: vec![[0, 2, 1]],
            },
            Pose::IDENTITY,
        )
        .unwrap();
        assert!(!surface.closed);
        assert_eq!(surface.indices.len(), 1);
        // parry may renumber the vertices; the face must keep its orientation (+Y here).
        let [a, b, c] = surface.indices[0].map(|i| surface.vertices[i as usize]);
        assert!((b - a).cross(c - a).normalize().abs_diff_eq(Vec3::Y, 1e-6));
    }
}
