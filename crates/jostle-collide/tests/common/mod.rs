//! Shared scene builder for the collision tests: bodies with one collider each, stepped
//! through the broad and narrow phases.
#![allow(dead_code)]

use jostle_body::{BodyHandle, BodySet, RigidBody};
use jostle_collide::{
    BodyContact, BroadPhase, CollideSettings, Collider, ColliderHandle, ColliderSet, Material,
    NarrowPhase, NarrowStats, ShapeDesc,
};
use jostle_math::{Mat3, Quat, Vec3};

pub struct Scene {
    pub bodies: BodySet,
    pub colliders: ColliderSet,
    pub broad: BroadPhase,
    pub narrow: NarrowPhase,
    pub settings: CollideSettings,
}

impl Scene {
    pub fn new() -> Self {
        Self {
            bodies: BodySet::new(),
            colliders: ColliderSet::new(),
            broad: BroadPhase::new(),
            narrow: NarrowPhase::new(),
            settings: CollideSettings::default(),
        }
    }

    pub fn add(
        &mut self,
        desc: &ShapeDesc,
        position: Vec3,
        orientation: Quat,
        fixed: bool,
    ) -> (BodyHandle, ColliderHandle) {
        let body = if fixed {
            RigidBody::fixed()
        } else {
            RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap()
        };
        let handle = self.bodies.insert(body.with_pose(position, orientation));
        let shape = desc.build().unwrap();
        let c = self
            .colliders
            .insert(Collider::new(shape, handle).with_material(Material::new(0.5, 0.1)));
        (handle, c)
    }

    pub fn dynamic(&mut self, desc: &ShapeDesc, position: Vec3) -> BodyHandle {
        self.add(desc, position, Quat::IDENTITY, false).0
    }

    pub fn fixed(&mut self, desc: &ShapeDesc, position: Vec3) -> BodyHandle {
        self.add(desc, position, Quat::IDENTITY, true).0
    }

    pub fn step(&mut self) -> NarrowStats {
        let pairs = self
            .broad
            .update(&self.colliders, &self.bodies, self.settings.prediction);
        self.narrow
            .update(pairs, &self.colliders, &self.bodies, &self.settings)
    }

    pub fn contacts(&self) -> &[BodyContact] {
        self.narrow.contacts()
    }

    pub fn move_by(&mut self, body: BodyHandle, delta: Vec3) {
        self.bodies.get_mut(body).unwrap().position += delta;
    }

    pub fn turn_by(&mut self, body: BodyHandle, turn: jostle_math::Quat) {
        let body = self.bodies.get_mut(body).unwrap();
        body.orientation = (turn * body.orientation).normalize();
    }
}

pub fn ground() -> ShapeDesc {
    ShapeDesc::HalfSpace { normal: Vec3::Y }
}

pub fn unit_cube() -> ShapeDesc {
    ShapeDesc::Cuboid {
        half_extents: Vec3::ONE,
    }
}

/// A convex hull of an octahedron-like cloud with a flat bottom face at y = −0.5 and
/// the top at y = +0.5 (a square prism, 1 m wide).
pub fn hull_prism() -> ShapeDesc {
    let mut points = Vec::new();
    for &y in &[-0.5f32, 0.5] {
        for &(x, z) in &[(-0.5f32, -0.5f32), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            points.push(Vec3::new(x, y, z));
        }
    }
    ShapeDesc::ConvexHull { points }
}

/// A flat 20 × 20 m square of two triangles in the plane y = 0, normals up.
pub fn mesh_floor() -> ShapeDesc {
    ShapeDesc::TriMesh {
        vertices: vec![
            Vec3::new(-10.0, 0.0, -10.0),
            Vec3::new(10.0, 0.0, -10.0),
            Vec3::new(10.0, 0.0, 10.0),
            Vec3::new(-10.0, 0.0, 10.0),
        ],
        // Counter-clockwise seen from above (+Y): normal +Y.
        indices: vec![[0, 2, 1], [0, 3, 2]],
    }
}

/// A cube of half size `h` as the convex hull of its eight corners.
pub fn hull_cube(h: f32) -> ShapeDesc {
    let corners = (0..8)
        .map(|i| {
            let sign = |bit: u32| if i & bit == 0 { -h } else { h };
            Vec3::new(sign(1), sign(2), sign(4))
        })
        .collect();
    ShapeDesc::ConvexHull { points: corners }
}
