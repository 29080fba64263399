//! The same scene, stepped the same way, gives bit-identical contacts.

mod common;

use common::*;
use jostle_collide::ShapeDesc;
use jostle_math::{Quat, Vec3};

/// A contact as bits: body indices, point, impulse, penetration.
type ContactBits = (u32, u32, [u32; 3], [u32; 3], u32);

fn run() -> Vec<ContactBits> {
    let mut scene = Scene::new();
    scene.fixed(&ground(), Vec3::ZERO);
    scene.fixed(&mesh_floor(), Vec3::new(0.0, 0.02, 0.0));
    let shapes = [
        ShapeDesc::Ball { radius: 0.5 },
        unit_cube(),
        ShapeDesc::Capsule {
            half_height: 0.3,
            radius: 0.2,
        },
        ShapeDesc::Cylinder {
            half_height: 0.5,
            radius: 0.4,
        },
        hull_prism(),
    ];
    let mut bodies = Vec::new();
    for i in 0..60 {
        let p = Vec3::new(
            (i % 5) as f32 * 0.9,
            0.5 + (i / 25) as f32 * 0.9,
            ((i / 5) % 5) as f32 * 0.9,
        );
        bodies.push(
            scene
                .add(
                    &shapes[i % 5],
                    p,
                    Quat::from_rotation_y(i as f32 * 0.3),
                    false,
                )
                .0,
        );
    }
    let mut out = Vec::new();
    for step in 0..20 {
        for (k, &b) in bodies.iter().enumerate() {
            let d = Vec3::new(
                ((k * 7 + step) % 5) as f32 - 2.0,
                -1.0,
                ((k * 3 + step) % 5) as f32 - 2.0,
            ) * 1e-3;
            scene.move_by(b, d);
        }
        scene.step();
        let impulses: Vec<Vec3> = scene
            .contacts()
            .iter()
            .map(|c| c.normal * c.penetration)
            .collect();
        scene.narrow.store_impulses(&impulses);
        for c in scene.contacts() {
            out.push((
                c.a.index(),
                c.b.index(),
                c.point.to_array().map(f32::to_bits),
                c.impulse.to_array().map(f32::to_bits),
                c.penetration.to_bits(),
            ));
        }
    }
    out
}

#[test]
fn two_runs_are_bit_identical() {
    let a = run();
    assert!(
        a.len() > 500,
        "the scene must produce contacts, got {}",
        a.len()
    );
    assert_eq!(a, run());
}
