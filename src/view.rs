//! Read-only views of a [`World`] for drawing it: every body's display mesh with its pose and
//! state, and the unbounded half-spaces as planes.
//!
//! In: the world's bodies and colliders. Out: [`BodyView`]s and [`PlaneView`]s of plain glam
//! types, so a renderer depends on the facade alone and never on parry. A collider's display
//! mesh is tessellated the first time it is viewed and kept with the collider (a world that is
//! never drawn pays nothing), so drawing a frame never re-tessellates. Nothing here changes
//! the simulation.

use crate::world::World;
use jostle_body::BodyHandle;
use jostle_collide::DisplayMesh;
use jostle_math::{Quat, Vec3};

/// One body as a renderer sees it.
#[derive(Clone, Copy, Debug)]
pub struct BodyView<'a> {
    /// The body.
    pub handle: BodyHandle,
    /// Position of the body's centre of mass (m): the origin of the mesh's frame.
    pub position: Vec3,
    /// Orientation of the body.
    pub rotation: Quat,
    /// Whether the body is fixed (immovable).
    pub fixed: bool,
    /// Whether the body is dynamic and asleep.
    pub sleeping: bool,
    /// The body's shape as triangles, in the body's frame.
    pub mesh: &'a DisplayMesh,
}

impl BodyView<'_> {
    /// A point of the body's frame (a mesh vertex) in world space.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.rotation * local + self.position
    }
}

/// An unbounded half-space (a ground) as the plane that bounds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneView {
    /// The fixed body the half-space belongs to.
    pub handle: BodyHandle,
    /// A point of the plane (m): the body's position.
    pub point: Vec3,
    /// Unit outward normal: it points to the free side.
    pub normal: Vec3,
}

impl World {
    /// Every body with a finite shape (all but half-spaces), with its pose, state and display
    /// mesh, in a deterministic order (collider slot order).
    pub fn body_views(&self) -> impl Iterator<Item = BodyView<'_>> {
        self.colliders.iter().filter_map(|(_, collider)| {
            let body = self.bodies.get(collider.body)?;
            let mesh = collider.display()?;
            Some(BodyView {
                handle: collider.body,
                position: body.position,
                rotation: body.orientation,
                fixed: body.is_fixed(),
                sleeping: !body.is_fixed() && !body.sleep.awake,
                mesh,
            })
        })
    }

    /// Every half-space, as the plane that bounds it, in collider slot order.
    pub fn half_space_views(&self) -> impl Iterator<Item = PlaneView> + '_ {
        self.colliders.iter().filter_map(|(_, collider)| {
            let normal = collider.shape().as_halfspace()?.normal;
            let body = self.bodies.get(collider.body)?;
            let pose = collider.world_pose(body);
            Some(PlaneView {
                handle: collider.body,
                point: pose.translation,
                normal: pose.rotation * normal,
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};

    #[test]
    fn views_follow_the_bodies_and_skip_half_spaces() {
        let mut world = World::new(WorldSettings::default());
        let ground = world
            .add_body(
                BodyDesc::fixed(
                    "ground",
                    ShapeDesc::HalfSpace {
                        normal: Vec3::Y * 3.0,
                    },
                )
                .at(Vec3::new(0.0, -1.0, 0.0)),
            )
            .unwrap();
        let cube = world
            .add_body(
                BodyDesc::dynamic(
                    "cube",
                    ShapeDesc::Cuboid {
                        half_extents: Vec3::splat(0.5),
                    },
                )
                .at(Vec3::new(0.0, 3.0, 0.0)),
            )
            .unwrap();
        let planes: Vec<_> = world.half_space_views().collect();
        assert_eq!(planes.len(), 1);
        assert_eq!(planes[0].handle, ground);
        assert_eq!(planes[0].normal, Vec3::Y);
        assert_eq!(planes[0].point, Vec3::new(0.0, -1.0, 0.0));

        let first: *const _ = {
            let views: Vec<_> = world.body_views().collect();
            assert_eq!(views.len(), 1);
            assert_eq!(views[0].handle, cube);
            assert!(!views[0].fixed && !views[0].sleeping);
            assert_eq!(views[0].mesh.indices.len(), 12);
            views[0].mesh
        };
        world.step(1.0 / 60.0).unwrap();
        let view = world.body_views().next().unwrap();
        assert!(view.position.y < 3.0, "the view follows the falling body");
        assert!(std::ptr::eq(first, view.mesh), "the mesh is built once");
        let top = view.to_world(Vec3::new(0.0, 0.5, 0.0));
        assert!((top - view.position - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6);
    }
}
