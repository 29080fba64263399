//! Synthetic contact sets for benchmarking and testing resolvers without collision detection
//! (so that a solver researcher benchmarks the resolver alone).
//!
//! Two families, both deterministic functions of their arguments (a tiny built-in PRNG, no
//! dependency): **stacks** (columns of unit boxes resting on the static ground, four contacts
//! per touching pair, many small islands) and **random piles** (boxes on a jittered grid with
//! contacts between grid neighbours and the ground, one large connected island). Bodies carry
//! the velocity and `last_acceleration` a step of gravity would have left, so both passes of a
//! resolver have real work. Shared by this crate's benches and tests and by the facade's
//! benches.

use crate::{Contact, STATIC_BODY, SolverBody};
use jostle_math::{InertiaShape, Mat3, Quat, Vec3, inverse_principal, world_inverse_inertia};

/// Gravity the synthetic scenes assume (m/s²).
pub const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);

/// Step length the synthetic scenes assume (s).
pub const DT: f32 = 1.0 / 60.0;

/// Bodies (index 0 is [`SolverBody::STATIC`]) and the contacts between them.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticScene {
    /// Solver bodies; index 0 is the static entry.
    pub bodies: Vec<SolverBody>,
    /// Contacts referring to `bodies` by index.
    pub contacts: Vec<Contact>,
}

/// A small deterministic PRNG (xorshift64*), so scenes need no dependency and are identical on
/// every platform.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (any value; zero is remapped).
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform integer in [0, n) (n > 0).
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * u64::from(n)) >> 32) as u32
    }

    /// A vector with components uniform in [−a, a).
    pub fn vec(&mut self, a: f32) -> Vec3 {
        Vec3::new(self.range(-a, a), self.range(-a, a), self.range(-a, a))
    }
}

/// A solid box body of `mass` kg and half extents `half` at the given pose, with the world
/// inverse inertia of that pose.
pub fn box_body(position: Vec3, orientation: Quat, mass: f32, half: Vec3) -> SolverBody {
    let inv_body = Mat3::from_diagonal(inverse_principal(
        InertiaShape::Cuboid { half_extents: half }.principal_inertia(mass),
    ));
    SolverBody::new(
        position,
        orientation,
        1.0 / mass,
        world_inverse_inertia(orientation, inv_body),
    )
}

/// How far above a plane a corner still yields a (speculative) contact, in metres: the collision
/// layer's default prediction margin (`jostle_collide::CollideSettings::prediction`), so that
/// synthetic contacts look like the ones the engine hands the resolver.
pub const SPECULATIVE_MARGIN: f32 = 0.02;

/// Contacts of the eight corners of box `body` (pose, half extents) against the plane
/// {x : x·normal = offset}, for corners below it or less than [`SPECULATIVE_MARGIN`] above it:
/// body A is the box, B the static entry, the point midway between corner and plane, the
/// penetration the corner's depth (negative for a gap).
pub fn box_plane_contacts(
    body: u32,
    position: Vec3,
    orientation: Quat,
    half: Vec3,
    normal: Vec3,
    offset: f32,
    out: &mut Vec<Contact>,
) {
    for i in 0..8 {
        let sign = Vec3::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { -1.0 } else { 1.0 },
        );
        let corner = position + orientation * (half * sign);
        let depth = offset - corner.dot(normal);
        if depth >= -SPECULATIVE_MARGIN {
            out.push(Contact::new(
                body,
                STATIC_BODY,
                corner + normal * (0.5 * depth),
                normal,
                depth,
            ));
        }
    }
}

/// Columns of `height` unit boxes (1 kg) resting on the static ground, each box touching the one
/// below at the four corners of the face between them (four contacts per pair, four against
/// the ground): `4 × height` contacts per column, columns added until there are `contacts`
/// (the last column is cut short). Penetrations are uniform in [0, 2 cm), velocities those one
/// step of gravity leaves plus a little noise, friction 0.5. Every column is its own island.
pub fn stacks(contacts: usize, height: usize, seed: u64) -> SyntheticScene {
    let height = height.max(1);
    let mut rng = Rng::new(seed);
    let mut bodies = vec![SolverBody::STATIC];
    let mut out = Vec::with_capacity(contacts);
    let half = Vec3::splat(0.5);
    let columns = contacts.div_ceil(4 * height).max(1);
    let side = (columns as f32).sqrt().ceil() as usize;
    'columns: for column in 0..columns {
        let base = Vec3::new(
            (column % side) as f32 * 2.0,
            0.0,
            (column / side) as f32 * 2.0,
        );
        for level in 0..height {
            let index = bodies.len() as u32;
            let mut body = box_body(
                base + Vec3::new(0.0, 0.5 + level as f32, 0.0),
                Quat::IDENTITY,
                1.0,
                half,
            );
            body.linear_velocity = GRAVITY * DT + rng.vec(0.02);
            body.angular_velocity = rng.vec(0.02);
            body.last_acceleration = GRAVITY;
            bodies.push(body);
            let below = if level == 0 { STATIC_BODY } else { index - 1 };
            for corner in 0..4 {
                if out.len() == contacts {
                    break 'columns;
                }
                let x = if corner & 1 == 0 { -0.5 } else { 0.5 };
                let z = if corner & 2 == 0 { -0.5 } else { 0.5 };
                let point = base + Vec3::new(x, level as f32, z);
                let c = Contact::new(index, below, point, Vec3::Y, rng.range(0.0, 0.02))
                    .with_friction(0.5);
                out.push(c);
            }
        }
    }
    SyntheticScene {
        bodies,
        contacts: out,
    }
}

/// A random pile: about `contacts / 2` boxes (0.5–2 kg, random orientations and velocities) on a
/// jittered cubic grid with spacing 1 m, and `contacts` contacts, each between a random box and
/// one of its grid neighbours (normal along the line of centres) or, one time in ten, the
/// ground. Penetrations are uniform in [0, 3 cm); half the contacts have friction in [0, 0.8),
/// restitution is in [0, 0.5). With about four contacts per box most contacts fall into a few
/// large islands (the rest in small ones: 250 islands for 16 384 contacts), the case where the
/// O(n) rescan hurts most.
pub fn random_pile(contacts: usize, seed: u64) -> SyntheticScene {
    let mut rng = Rng::new(seed);
    let n = (contacts / 2).max(2);
    let side = ((n as f32).cbrt().ceil() as usize).max(2);
    let grid = |i: usize| {
        Vec3::new(
            (i % side) as f32,
            (i / side % side) as f32 + 0.5,
            (i / (side * side)) as f32,
        )
    };
    let mut bodies = vec![SolverBody::STATIC];
    for i in 0..n {
        let axis = rng.vec(1.0).try_normalize().unwrap_or(Vec3::Y);
        let orientation = Quat::from_axis_angle(axis, rng.range(0.0, std::f32::consts::PI));
        let mut body = box_body(
            grid(i) + rng.vec(0.05),
            orientation,
            rng.range(0.5, 2.0),
            Vec3::splat(0.5),
        );
        body.linear_velocity = rng.vec(1.0);
        body.angular_velocity = rng.vec(1.0);
        body.last_acceleration = GRAVITY;
        bodies.push(body);
    }
    let mut out = Vec::with_capacity(contacts);
    while out.len() < contacts {
        let i = rng.below(n as u32) as usize;
        let a = bodies[i + 1];
        let neighbour = match rng.below(7) {
            0 => i.checked_sub(1),
            1 => Some(i + 1),
            2 => i.checked_sub(side),
            3 => Some(i + side),
            4 => i.checked_sub(side * side),
            5 => Some(i + side * side),
            _ => None,
        }
        .filter(|&j| j < n && rng.below(10) != 0);
        let mut contact = match neighbour {
            Some(j) => {
                let b = bodies[j + 1];
                let normal = (a.position - b.position).try_normalize().unwrap_or(Vec3::Y);
                let mid = 0.5 * (a.position + b.position);
                let jitter = rng.vec(0.3);
                let point = mid + jitter - normal * jitter.dot(normal);
                Contact::new(
                    i as u32 + 1,
                    j as u32 + 1,
                    point,
                    normal,
                    rng.range(0.0, 0.03),
                )
            }
            None => {
                let point = a.position - Vec3::new(rng.range(-0.4, 0.4), 0.5, rng.range(-0.4, 0.4));
                Contact::new(
                    i as u32 + 1,
                    STATIC_BODY,
                    point,
                    Vec3::Y,
                    rng.range(0.0, 0.03),
                )
            }
        };
        if out.len() % 2 == 0 {
            contact = contact.with_friction(rng.range(0.0, 0.8));
        }
        out.push(contact.with_restitution(rng.range(0.0, 0.5)));
    }
    SyntheticScene {
        bodies,
        contacts: out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_exact_and_deterministic() {
        for n in [1, 7, 256, 1000] {
            let s = stacks(n, 8, 1);
            assert_eq!(s.contacts.len(), n);
            let p = random_pile(n, 2);
            assert_eq!(p.contacts.len(), n);
            assert_eq!(p, random_pile(n, 2));
            for c in s.contacts.iter().chain(&p.contacts) {
                assert!((c.a as usize) < s.bodies.len().max(p.bodies.len()));
                assert!((c.normal.length() - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn box_plane_contacts_finds_the_bottom_face() {
        let mut out = Vec::new();
        box_plane_contacts(
            1,
            Vec3::new(0.0, 0.49, 0.0),
            Quat::IDENTITY,
            Vec3::splat(0.5),
            Vec3::Y,
            0.0,
            &mut out,
        );
        assert_eq!(out.len(), 4);
        assert!(
            out.iter()
                .all(|c| (c.penetration - 0.01).abs() < 1e-6 && c.b == STATIC_BODY)
        );
    }
}
