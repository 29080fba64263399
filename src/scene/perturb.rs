//! Seeded perturbation of generated layouts: the "perturbed start" of the stability family
//! (issue 15). A generator places its boxes exactly; a scene's `perturb` shifts each generated
//! body sideways by a few millimetres and turns it by a few tenths of a degree, from a seeded
//! generator, so the same file always gives the same start and a family of seeds gives a
//! family of starts.
//!
//! Each body is lifted in proportion to its height so that no two turned boxes overlap at the
//! start: a box of half extents h turned by at most `angle` about a horizontal axis reaches at
//! most max(h)·sin(angle) lower, so raising every height y to y·(1 + sin(angle)·max(h)/h_y)
//! opens a gap of at least 2·max(h)·sin(angle) between stacked boxes, enough for both.

use crate::body_desc::BodyDesc;
use jostle_collide::ShapeDesc;
use jostle_math::{Quat, Vec3};
use serde::{Deserialize, Serialize};

fn default_position() -> f32 {
    0.003
}
fn default_angle() -> f32 {
    0.3
}

/// `perturb: Perturb(seed: 7, position: 0.003, angle: 0.3)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Perturb", deny_unknown_fields)]
pub struct Perturb {
    /// Seed of the generator (any u64). Required.
    pub seed: u64,
    /// Largest sideways shift along x and along z (m). Default 0.003.
    #[serde(default = "default_position")]
    pub position: f32,
    /// Largest turn about a horizontal axis, and about the vertical (degrees), in [0, 10).
    /// Default 0.3.
    #[serde(default = "default_angle")]
    pub angle: f32,
}

impl Perturb {
    /// Checks the fields; the error is (field, message).
    pub fn validate(&self) -> Result<(), (String, String)> {
        if !(self.position.is_finite() && self.position >= 0.0 && self.position <= 1.0) {
            return Err((
                "perturb.position".into(),
                format!("must be in [0, 1] m, got {}", self.position),
            ));
        }
        if !(self.angle.is_finite() && self.angle >= 0.0 && self.angle < 10.0) {
            return Err((
                "perturb.angle".into(),
                format!("must be in [0, 10) degrees, got {}", self.angle),
            ));
        }
        Ok(())
    }

    /// Perturbs `bodies` in place: body `i` draws from the generator seeded by (seed, i).
    pub fn apply(&self, bodies: &mut [BodyDesc]) {
        let angle = self.angle.to_radians();
        for (i, body) in bodies.iter_mut().enumerate() {
            let mut rng =
                SplitMix64::new(self.seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let shift = Vec3::new(rng.symmetric(), 0.0, rng.symmetric()) * self.position;
            let heading = rng.symmetric() * std::f32::consts::PI;
            let axis = Vec3::new(heading.cos(), 0.0, heading.sin());
            let tilt = Quat::from_axis_angle(axis, rng.unit() * angle);
            let yaw = Quat::from_rotation_y(rng.symmetric() * angle);
            let lift = 1.0 + angle.sin() * height_ratio(&body.shape);
            body.position =
                Vec3::new(body.position.x, body.position.y * lift, body.position.z) + shift;
            body.rotation = (tilt * yaw * body.rotation).normalize();
        }
    }
}

/// max(h)/h_y for a cuboid of half extents h; 1 for other shapes.
fn height_ratio(shape: &ShapeDesc) -> f32 {
    match shape {
        ShapeDesc::Cuboid { half_extents } if half_extents.y > 0.0 => {
            half_extents.max_element() / half_extents.y
        }
        _ => 1.0,
    }
}

/// SplitMix64 (Steele, Lea and Flood, 2014): a tiny, well-mixed generator, enough for
/// reproducible layouts; not for anything statistical.
struct SplitMix64(u64);

impl SplitMix64 {
    fn new(seed: u64) -> Self {
        Self(seed)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [−1, 1).
    fn symmetric(&mut self) -> f32 {
        2.0 * self.unit() - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column() -> Vec<BodyDesc> {
        (0..10)
            .map(|i| {
                BodyDesc::dynamic(
                    format!("b{i}"),
                    ShapeDesc::Cuboid {
                        half_extents: Vec3::splat(0.5),
                    },
                )
                .at(Vec3::new(0.0, 0.5 + i as f32, 0.0))
            })
            .collect()
    }

    #[test]
    fn the_same_seed_gives_the_same_start_and_another_seed_another() {
        let p = Perturb {
            seed: 7,
            position: 0.003,
            angle: 0.3,
        };
        let (mut a, mut b, mut c) = (column(), column(), column());
        p.apply(&mut a);
        p.apply(&mut b);
        Perturb {
            seed: 8,
            ..p.clone()
        }
        .apply(&mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
        for (body, i) in a.iter().zip(0..) {
            let nominal = Vec3::new(0.0, 0.5 + i as f32, 0.0);
            let d = body.position - nominal;
            assert!(d.x.abs() <= 0.003 && d.z.abs() <= 0.003, "{d}");
            let up = body.rotation * Vec3::Y;
            assert!(up.angle_between(Vec3::Y) <= 0.3f32.to_radians() * 1.001);
        }
    }

    #[test]
    fn turned_boxes_start_apart() {
        let p = Perturb {
            seed: 3,
            position: 0.0,
            angle: 2.0,
        };
        let mut boxes = column();
        p.apply(&mut boxes);
        for pair in boxes.windows(2) {
            // The lowest corner of the upper box stays above the highest corner of the lower.
            let corners = |b: &BodyDesc| -> Vec<f32> {
                (0..8)
                    .map(|k| {
                        let c = Vec3::new(
                            if k & 1 == 0 { -0.5 } else { 0.5 },
                            if k & 2 == 0 { -0.5 } else { 0.5 },
                            if k & 4 == 0 { -0.5 } else { 0.5 },
                        );
                        (b.position + b.rotation * c).y
                    })
                    .collect()
            };
            let top = corners(&pair[0]).into_iter().fold(f32::MIN, f32::max);
            let bottom = corners(&pair[1]).into_iter().fold(f32::MAX, f32::min);
            assert!(bottom > top, "{bottom} <= {top}");
        }
    }

    #[test]
    fn out_of_range_fields_are_named() {
        let bad = Perturb {
            seed: 1,
            position: -1.0,
            angle: 0.3,
        };
        assert_eq!(bad.validate().unwrap_err().0, "perturb.position");
        let bad = Perturb {
            seed: 1,
            position: 0.0,
            angle: f32::NAN,
        };
        assert_eq!(bad.validate().unwrap_err().0, "perturb.angle");
    }
}
