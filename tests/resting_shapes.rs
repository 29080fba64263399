//! Every shape dropped on the ground (a half-space) and on a triangle-mesh floor comes to rest
//! at the height its geometry gives, within 1 cm, and nothing falls through, with each
//! resolver.

mod common;
use common::*;
use jostle::{BodyDesc, Quat, ResolverChoice, ShapeDesc, Vec3, World};

/// (name, shape, rest height of the body's origin above the floor, rotation).
fn shapes() -> Vec<(&'static str, ShapeDesc, f32, Quat)> {
    let hull = ShapeDesc::ConvexHull {
        points: vec![
            Vec3::new(-0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, 0.5),
            Vec3::new(-0.5, 0.0, 0.5),
            Vec3::new(0.0, 0.6, 0.0),
        ],
    };
    vec![
        ("ball", ShapeDesc::Ball { radius: 0.3 }, 0.3, Quat::IDENTITY),
        (
            "cuboid",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.4, 0.25, 0.3),
            },
            0.25,
            Quat::IDENTITY,
        ),
        // A capsule lying on its side rests on its radius.
        (
            "capsule",
            ShapeDesc::Capsule {
                half_height: 0.4,
                radius: 0.2,
            },
            0.2,
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ),
        (
            "cylinder",
            ShapeDesc::Cylinder {
                half_height: 0.3,
                radius: 0.4,
            },
            0.3,
            Quat::IDENTITY,
        ),
        // A square pyramid on its base: the base is at the origin of its frame.
        ("hull", hull, 0.0, Quat::IDENTITY),
    ]
}

fn mesh_floor() -> ShapeDesc {
    // A 20 m square of 8 triangles, counter-clockwise seen from above (+Y is the free side).
    let mut vertices = Vec::new();
    for z in [-10.0, 0.0, 10.0] {
        for x in [-10.0, 0.0, 10.0] {
            vertices.push(Vec3::new(x, 0.0, z));
        }
    }
    let mut indices = Vec::new();
    for row in 0..2u32 {
        for col in 0..2u32 {
            let i = row * 3 + col;
            indices.push([i, i + 3, i + 1]);
            indices.push([i + 1, i + 3, i + 4]);
        }
    }
    ShapeDesc::TriMesh { vertices, indices }
}

fn rest_height(
    resolver: &ResolverChoice,
    floor: ShapeDesc,
    shape: ShapeDesc,
    rotation: Quat,
    dt: f32,
) -> (f32, f32) {
    let mut w: World = world_with(Vec3::new(0.0, -9.81, 0.0), resolver);
    w.add_body(BodyDesc::fixed("floor", floor).with_material(0.8, 0.0))
        .unwrap();
    let start = Vec3::new(0.3, 1.0, -0.2);
    let h = w
        .add_body(
            BodyDesc::dynamic("body", shape)
                .at(start)
                .rotated(rotation)
                .with_material(0.8, 0.0),
        )
        .unwrap();
    // The body's position is its centre of mass; measure its shape origin's height instead.
    let com_offset = w.body(h).unwrap().position - start;
    let mut lowest = f32::MAX;
    run(&mut w, dt, 3.0, |w| {
        lowest = lowest.min(w.body(h).unwrap().position.y)
    });
    let b = w.body(h).unwrap();
    let origin_y = b.position.y - (b.orientation * (rotation.inverse() * com_offset)).y;
    (origin_y, lowest - com_offset.y)
}

#[test]
fn every_shape_rests_at_its_geometric_height_on_both_floors() {
    for r in resolvers() {
        let r_name = r.name();
        for dt in STEPS {
            for (floor_name, floor) in [
                ("half-space", ShapeDesc::HalfSpace { normal: Vec3::Y }),
                ("mesh", mesh_floor()),
            ] {
                for (name, shape, expected, rot) in shapes() {
                    let (y, lowest) = rest_height(&r, floor.clone(), shape, rot, dt);
                    assert!(
                        (y - expected).abs() < 0.01,
                        "{r_name}: {name} on {floor_name} at dt {dt}: rests at {y}, expected {expected}"
                    );
                    assert!(
                        lowest > expected - 0.1,
                        "{r_name}: {name} on {floor_name} at dt {dt}: sank to {lowest}"
                    );
                }
            }
        }
    }
}
