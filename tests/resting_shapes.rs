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

/// A square floor of two triangles, `half` metres from its centre to each side.
fn two_triangle_floor(half: f32) -> ShapeDesc {
    let vertices = vec![
        Vec3::new(-half, 0.0, -half),
        Vec3::new(half, 0.0, -half),
        Vec3::new(half, 0.0, half),
        Vec3::new(-half, 0.0, half),
    ];
    ShapeDesc::TriMesh {
        vertices,
        indices: vec![[0, 2, 1], [0, 3, 2]],
    }
}

/// Cylinders (lying and upright), capsules, boxes and hulls of 1 cm, 10 cm and 0.5 m placed
/// resting on floors of two triangles 20 m, 200 m and 2 km across (and on a half-space), beside
/// the triangles' shared edge or away from it, stay put for 5 s with the default resolver: no
/// body moves sideways by 5% of its size, turns by 1° or sinks by 2% of its size plus 1 mm.
/// parry's contacts of a triangle thousands of times larger than the shape were wrong by a
/// fraction of the shape (`jostle-collide`'s `mesh_patch`): a 1 cm cylinder lying on the
/// 200 m floor rolled away with growing speed and fell through it, and a 10 cm one upright on
/// the 2 km floor sank 4 cm (benches/RESULTS.md, "Contacts with huge triangles").
#[test]
fn shapes_rest_on_floors_of_huge_triangles_as_on_a_half_space() {
    let lying = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let mut wrong = Vec::new();
    for size in [0.01f32, 0.1, 0.5] {
        let hull = ShapeDesc::ConvexHull {
            points: (0..8)
                .map(|i| {
                    let sign = |bit: u32| if i & bit == 0 { -size } else { size };
                    Vec3::new(sign(1), sign(2), sign(4))
                })
                .collect(),
        };
        // (name, shape, rest height of the centre, rotation)
        let cases = [
            (
                "cylinder lying",
                ShapeDesc::Cylinder {
                    half_height: 3.0 * size,
                    radius: size,
                },
                size,
                lying,
            ),
            (
                "cylinder upright",
                ShapeDesc::Cylinder {
                    half_height: size,
                    radius: size,
                },
                size,
                Quat::IDENTITY,
            ),
            (
                "capsule lying",
                ShapeDesc::Capsule {
                    half_height: size,
                    radius: size,
                },
                size,
                lying,
            ),
            (
                "box",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(size),
                },
                size,
                Quat::IDENTITY,
            ),
            ("hull", hull, size, Quat::IDENTITY),
        ];
        let floors = [
            ("half-space", ShapeDesc::HalfSpace { normal: Vec3::Y }),
            ("20 m", two_triangle_floor(10.0)),
            ("200 m", two_triangle_floor(100.0)),
            ("2 km", two_triangle_floor(1000.0)),
        ];
        for (floor_name, floor) in &floors {
            // Beside the shared edge (x = z) and 2 m from it.
            for (x, z) in [(0.3f32, 0.2f32), (1.7, -0.6)] {
                for (name, shape, height, rotation) in &cases {
                    let mut w = world_with(Vec3::new(0.0, -9.81, 0.0), &ResolverChoice::default());
                    w.add_body(BodyDesc::fixed("floor", floor.clone()).with_material(0.5, 0.0))
                        .unwrap();
                    let start = Vec3::new(x, *height, z);
                    let h = w
                        .add_body(
                            BodyDesc::dynamic("body", shape.clone())
                                .at(start)
                                .rotated(*rotation)
                                .with_material(0.5, 0.0),
                        )
                        .unwrap();
                    let (mut aside, mut sink, mut turn) = (0.0f32, 0.0f32, 0.0f32);
                    run(&mut w, 1.0 / 60.0, 5.0, |w| {
                        let b = w.body(h).unwrap();
                        aside = aside.max((b.position - start).with_y(0.0).length());
                        sink = sink.max(start.y - b.position.y);
                        turn = turn.max(b.orientation.angle_between(*rotation));
                    });
                    let what = format!(
                        "{name} of {size} m on {floor_name} at ({x}, {z}): {aside:.2e} m aside, \
                         sank {sink:.2e} m, turned {:.2}°",
                        turn.to_degrees()
                    );
                    println!("{what}");
                    if !(aside < 0.05 * size && sink < 0.02 * size + 0.001 && turn < 0.0175) {
                        wrong.push(what);
                    }
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{} wrong: {wrong:#?}", wrong.len());
}
