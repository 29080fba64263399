//! Contact preparation: everything the two passes need about a contact, computed once per step
//! (Cyclone's `calculateInternals`): the contact basis, the lever arms, the closing velocity in
//! contact space (its tangential part with a chord term that Cyclone does not have: how far
//! each body's turn carries its point off the tangent within the step) and the desired
//! velocity change of the micro-collision rule.

use super::change::NO_BODY;
use crate::{Contact, STATIC_BODY, SolverBody};
use jostle_math::{Mat3, Vec3, contact_basis};

/// A contact as the passes see it. Fields are public so tests and tools can build or inspect
/// one; [`prepare`] is the normal way to get one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedContact {
    /// Contact → world rotation; columns (n, t1, t2) with n the unit normal from B toward A
    /// ([`jostle_math::contact_basis`]).
    pub basis: Mat3,
    /// Lever arms r = point − body position for side A and side B (m), fixed for the step as in
    /// Cyclone (they are not recomputed after projection moves the bodies).
    pub r: [Vec3; 2],
    /// Closing velocity of A relative to B at the contact, in contact space (m/s); x < 0 when
    /// approaching. It includes the velocity this step's integration just added
    /// (`last_acceleration · dt`): the resolver integrates velocities before it resolves.
    pub velocity: Vec3,
    /// Velocity along the normal produced by the last step's acceleration (m/s), the lecture's
    /// v_acc: ((a_A − a_B) · dt) · n.
    pub acc_velocity: f32,
    /// How fast the contact slid before this step's accelerations (m/s): the planar part of
    /// `velocity` less that of (a_A − a_B) · dt. Coulomb's rule: a contact that was not sliding
    /// is held by static friction, so where its pick leaves the friction cone it keeps the
    /// direction of the static solution ([`super::velocity::coulomb_accumulated`]).
    pub sliding_before: f32,
    /// Closing speed (m/s, ≥ 0) the contact gained after its surfaces met: a contact found
    /// overlapping by d, closing at v_r at the start of the step under a closing acceleration
    /// a_n, has been accelerating for d/|v_r| and met at |v_r| − |a_n|·d/|v_r|. The bounce is
    /// that speed's, since the position pass puts the bodies back where they met; bounced at
    /// |v_r| from there, a restitution-1 box rose m·g·d higher at every bounce (benches/
    /// RESULTS.md, "Restitution 1 never raises a bounce"). See [`impact_speed_gain`].
    pub impact_speed_gain: f32,
    /// Normal velocity change the velocity pass aims for (m/s): `target_velocity` − the
    /// current normal velocity; see [`desired_delta_velocity`].
    pub desired_delta_velocity: f32,
    /// The normal velocity (m/s) the velocity pass aims for, decided from the closing velocity
    /// after the position pass ([`desired_delta_velocity`] added to it). Picks of contacts
    /// between the same two bodies leave it as it is, so the points of one impact are
    /// resolved together and a pick may take back part of what the contact pushed
    /// (accumulated clamping); recomputed after each of them, as the lecture does, the rule
    /// bounced what a neighbouring point's pick had driven into the surface, and a box landing
    /// on an edge gained energy at every impact (benches/RESULTS.md, "Restitution 1 never
    /// raises a bounce"). A pick of another pair that drives the contact together is a new
    /// collision for it: its target is decided again from the velocity that pick left
    /// ([`super::velocity::update_velocity`]), so an impact passed on through touching bodies
    /// (Newton's cradle) travels pair by pair. Driven apart, a resting contact (a target of at
    /// most 0) keeps its target and may take back its push; a bouncing one keeps the
    /// separation it was given.
    pub target_velocity: f32,
    /// For a speculative contact (negative penetration: a gap), the closing speed the gap
    /// absorbs within the step, gap/dt (m/s); zero for touching or overlapping contacts. Set
    /// after the position pass, which may change the gap.
    pub gap_velocity: f32,
    /// Current penetration (m), positive on overlap; the position pass updates it.
    pub penetration: f32,
    /// Combined friction μ.
    pub friction: f32,
    /// Combined restitution e.
    pub restitution: f32,
    /// Velocity change along the normal per unit normal impulse (m/(N·s)), Σ 1/m +
    /// ((I⁻¹(r×n))×r)·n over the sides that move. Zero means the contact cannot be resolved
    /// (both bodies immovable) and both passes skip it.
    pub normal_inertia: f32,
    /// Sum of the inverse masses of the moving sides (1/kg); the total inertia of linear
    /// projection.
    pub linear_inertia: f32,
    /// Body index of each side, or [`NO_BODY`] when that side never moves (the static entry or
    /// an immovable body). Only these indices are ever written.
    pub body: [u32; 2],
    /// Impulse applied so far this step, contact space, on A (N·s): the sum of every pick's
    /// impulse in this step's velocity pass. With friction, the Coulomb test of a pick is made
    /// against this total plus the pick's impulse ([`super::velocity::coulomb_accumulated`]).
    pub impulse: Vec3,
    /// Whether the last friction pick of this contact ended on the edge of its friction cone
    /// (dynamic friction, possibly with μ lowered by the denominator guard) or could not apply
    /// friction at all (singular K, non-finite solve). A saturated contact's sliding is no
    /// reason to pick it again ([`super::velocity::velocity_key`]) until picks of other
    /// contacts change its sliding velocity by more than the velocity epsilon
    /// ([`super::velocity::reopen_friction`]); its next pick recomputes the flag. Always
    /// `false` for μ = 0.
    pub friction_saturated: bool,
    /// The sliding velocity (contact space, x = 0) right after the pick that saturated the
    /// contact; meaningful only while `friction_saturated`.
    pub saturated_sliding: Vec3,
    /// How many times this step's picks have shared the friction of this contact's manifold by
    /// load ([`super::velocity::share_manifold_friction`], which does so a bounded number of
    /// times a step).
    pub friction_shared: u8,
    /// Penetration (m, ≥ 0) this contact's own picks have resolved so far this step: the sum
    /// of their projection depths. A pick may take back part of it, never more
    /// ([`super::position::projection_depth`]): the position pass's accumulated clamp, as the
    /// velocity pass clamps `impulse`.
    pub projected: f32,
    /// Warm started ([`super::MillingtonSettings::warm_start`]): a resting contact that
    /// applied its carried impulse before the first pick. Its target stays for the step
    /// (picks of other pairs do not decide it again, [`super::velocity::update_velocity`]).
    pub held: bool,
}

impl PreparedContact {
    /// The unit contact normal (world space), from B toward A.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.basis.x_axis
    }

    /// The body on `side` (0 = A, 1 = B), when that side moves.
    #[inline]
    pub fn side_body<'a>(&self, bodies: &'a [SolverBody], side: usize) -> Option<&'a SolverBody> {
        match self.body[side] {
            NO_BODY => None,
            index => bodies.get(index as usize),
        }
    }

    /// The body on `side`, mutably, when that side moves.
    #[inline]
    pub fn side_body_mut<'a>(
        &self,
        bodies: &'a mut [SolverBody],
        side: usize,
    ) -> Option<&'a mut SolverBody> {
        match self.body[side] {
            NO_BODY => None,
            index => bodies.get_mut(index as usize),
        }
    }

    /// A contact that takes part in nothing (invalid body indices): zero inertia, no bodies.
    pub fn inert(penetration: f32) -> Self {
        Self {
            basis: Mat3::IDENTITY,
            r: [Vec3::ZERO; 2],
            velocity: Vec3::ZERO,
            acc_velocity: 0.0,
            sliding_before: 0.0,
            impact_speed_gain: 0.0,
            desired_delta_velocity: 0.0,
            target_velocity: 0.0,
            gap_velocity: 0.0,
            penetration,
            friction: 0.0,
            restitution: 0.0,
            normal_inertia: 0.0,
            linear_inertia: 0.0,
            body: [NO_BODY; 2],
            impulse: Vec3::ZERO,
            friction_saturated: false,
            saturated_sliding: Vec3::ZERO,
            friction_shared: 0,
            projected: 0.0,
            held: false,
        }
    }

    /// Whether at least one side moves.
    #[inline]
    pub fn is_active(&self) -> bool {
        self.body[0] != NO_BODY || self.body[1] != NO_BODY
    }

    /// This contact with the body on `side` (0 = A, 1 = B) held still, as the shock sweep
    /// resolves it ([`super::shock`]): that side is [`NO_BODY`] and the inertias are the
    /// other side's alone.
    pub fn with_side_held(&self, side: usize, bodies: &[SolverBody]) -> Self {
        let mut held = *self;
        held.body[side] = NO_BODY;
        let other = 1 - side;
        let n = held.normal();
        (held.normal_inertia, held.linear_inertia) = held
            .side_body(bodies, other)
            .map_or((0.0, 0.0), |b| side_inertias(b, held.r[other], n));
        held
    }

    /// Takes what resolving `held` (this contact with a side held,
    /// [`PreparedContact::with_side_held`]) changed, keeping this contact's own sides and
    /// inertias.
    pub fn take_resolved(&mut self, held: &Self) {
        let (body, normal_inertia, linear_inertia) =
            (self.body, self.normal_inertia, self.linear_inertia);
        *self = *held;
        self.body = body;
        self.normal_inertia = normal_inertia;
        self.linear_inertia = linear_inertia;
    }
}

/// The desired normal velocity change of the micro-collision rule (seed lecture, "Remove
/// Accelerated Velocity" and "Lower the Restitution"):
/// Δv = −v − e′·(v − v_acc + g), with e′ = 0 when |v| < `velocity_limit`, else `restitution`,
/// and g the closing speed gained since the surfaces met ([`impact_speed_gain`]; the bounced
/// term is never allowed to turn into a separating one).
///
/// `v` is the normal closing velocity (negative when approaching). The lecture's slide tests
/// `contactVelocity.magnitude()`; the limit is about the bounce, so jostle (like Cyclone's
/// shipped code) tests the normal component only: a fast-sliding resting box must not bounce.
#[inline]
pub fn desired_delta_velocity(
    v: f32,
    acc_velocity: f32,
    impact_speed_gain: f32,
    restitution: f32,
    velocity_limit: f32,
    gap_velocity: f32,
) -> f32 {
    // Speculative contact: a gap closing slower than gap/dt stays open this step, and nothing
    // is done; an inelastic one may close it exactly (v' = −gap/dt, so the bodies meet at the
    // end of the step instead of hovering). A bouncing contact bounces from the surface.
    // For touching contacts (gap 0) this is the lecture's rule unchanged.
    if v + gap_velocity >= 0.0 {
        return -(v + gap_velocity);
    }
    let e = if v.abs() < velocity_limit {
        0.0
    } else {
        restitution
    };
    if e == 0.0 {
        -(v + gap_velocity)
    } else {
        -v - e * (v - acc_velocity + impact_speed_gain).min(0.0)
    }
}

/// The closing speed (m/s, ≥ 0) a contact overlapping by `penetration` gained after its
/// surfaces met: with v_r the closing velocity at the start of the step (negative when
/// approaching) and a_n = `acc_velocity`/`dt` the normal relative acceleration, the surfaces
/// met d/|v_r| ago, at a speed a_n·d/v_r lower. Zero unless the contact overlaps, approaches
/// and is accelerated into itself: the correction only ever lowers a bounce.
///
/// To first order this is exactly the potential energy the position pass adds by moving the
/// bodies back out: a point with effective inverse mass K bounced at a speed lower by
/// δ = |a_n|·d/|v_r| loses |v_r|·δ/K of kinetic energy, and lifting it by d raises its centre
/// of mass by d/(m·K), which costs m·|a_n|·d/(m·K): the same.
#[inline]
pub fn impact_speed_gain(
    closing_velocity: f32,
    acc_velocity: f32,
    penetration: f32,
    dt: f32,
) -> f32 {
    if !(penetration > 0.0 && closing_velocity < 0.0 && acc_velocity < 0.0 && dt > 0.0) {
        return 0.0;
    }
    let gain = (acc_velocity / dt) * penetration / closing_velocity;
    if gain.is_finite() { gain } else { 0.0 }
}

/// Whether side body `index` of a contact moves in the passes.
#[inline]
fn moving_side(bodies: &[SolverBody], index: u32) -> u32 {
    if index == STATIC_BODY {
        return NO_BODY;
    }
    match bodies.get(index as usize) {
        Some(b) if b.is_movable() => index,
        _ => NO_BODY,
    }
}

/// ((I⁻¹(r×n))×r)·n, written as u·(I⁻¹u) with u = r×n (equal by the scalar triple product,
/// and never negative for a positive semi-definite I⁻¹): the velocity (or displacement) along
/// n of the point at r per unit impulse (or unit "push") along n, through rotation alone.
#[inline]
pub fn angular_inertia(body: &SolverBody, r: Vec3, n: Vec3) -> f32 {
    if !body.rotates() {
        return 0.0;
    }
    let u = r.cross(n);
    u.dot(body.inv_inertia * u)
}

/// One moving side's part of a contact's inertias along `n` at lever arm `r`:
/// ([`PreparedContact::normal_inertia`], [`PreparedContact::linear_inertia`]).
#[inline]
fn side_inertias(body: &SolverBody, r: Vec3, n: Vec3) -> (f32, f32) {
    let along = body.inv_mass_along(n);
    (along + angular_inertia(body, r, n), along)
}

/// Prepares `contact` for the passes (seed lecture, "Desired Velocity Change"), or `None` when
/// a body index is out of range (such a contact is ignored by the resolver).
///
/// `dt` is the step length, used to turn `last_acceleration` into velocity. A normal that is
/// not unit to within 1e-3 is renormalised (a zero or non-finite one makes the contact inert).
pub fn prepare(
    contact: &Contact,
    bodies: &[SolverBody],
    dt: f32,
    velocity_limit: f32,
) -> Option<PreparedContact> {
    let body_a = bodies.get(contact.a as usize)?;
    let body_b = bodies.get(contact.b as usize)?;
    let mut n = contact.normal;
    if (n.length_squared() - 1.0).abs() > 1e-3 {
        match n.try_normalize() {
            Some(unit) => n = unit,
            None => return Some(PreparedContact::inert(contact.penetration)),
        }
    }
    let basis = contact_basis(n);
    let r = [
        contact.point - body_a.position,
        contact.point_b - body_b.position,
    ];
    let body = [
        moving_side(bodies, contact.a),
        moving_side(bodies, contact.b),
    ];

    // Closing velocity: A's material point minus B's (equation (A) of the lecture), skipping
    // ω × r for bodies that do not rotate.
    let point_velocity = |b: &SolverBody, r: Vec3| {
        if b.rotates() {
            b.linear_velocity + b.angular_velocity.cross(r)
        } else {
            b.linear_velocity
        }
    };
    let world_velocity = point_velocity(body_a, r[0]) - point_velocity(body_b, r[1]);
    let mut velocity = basis.transpose() * world_velocity;
    // The chord term: the poses advance with the resolved velocities for the whole step, each
    // centre straight on and each point turned about it, so a point at r on a body turning at
    // ω moves on average ω × (ω × r)·dt/2 faster than its velocity at the start says. Friction
    // holds the sliding velocity plus this (A's less B's, on the tangents) at zero, so that a
    // sticking point follows the other body's point along its arc instead of along the tangent
    // (a box on a turntable moved outward by r·(ω·dt)²/2 every step). Both points are taken
    // at the turn of the immovable body of the pair (a kinematic one), as a sticking point
    // turns with it, and only there: as in the soft step (`soft_step::batch::PointLanes::chord`).
    let turn = if body_a.inv_mass == 0.0 {
        body_a.angular_velocity
    } else if body_b.inv_mass == 0.0 {
        body_b.angular_velocity
    } else {
        Vec3::ZERO
    };
    if turn != Vec3::ZERO {
        let chord = basis.transpose() * (turn.cross(turn.cross(r[0] - r[1])) * (0.5 * dt));
        velocity.y += chord.y;
        velocity.z += chord.z;
    }
    let acc = basis.transpose() * ((body_a.last_acceleration - body_b.last_acceleration) * dt);
    // Cyclone adds the planar part of a·dt to the closing velocity here because it integrates
    // poses with the velocity *before* resolution, so friction must pre-empt the a·dt the next
    // integration adds. jostle integrates velocities, resolves, then integrates poses with the
    // resolved velocity: the a·dt is already in `velocity`, and adding it again would make a box
    // on a slope creep uphill by a·dt² per step. So the planar term is deliberately left out.

    let mut normal_inertia = 0.0;
    let mut linear_inertia = 0.0;
    for (side, b) in [body_a, body_b].into_iter().enumerate() {
        if body[side] != NO_BODY {
            let (normal, linear) = side_inertias(b, r[side], n);
            linear_inertia += linear;
            normal_inertia += normal;
        }
    }

    // The closing velocity at the start of the step, where the contact was detected.
    let gain = impact_speed_gain(velocity.x - acc.x, acc.x, contact.penetration, dt);
    let desired = desired_delta_velocity(
        velocity.x,
        acc.x,
        gain,
        contact.restitution,
        velocity_limit,
        0.0,
    );
    Some(PreparedContact {
        basis,
        r,
        velocity,
        acc_velocity: acc.x,
        sliding_before: (velocity.y - acc.y).hypot(velocity.z - acc.z),
        impact_speed_gain: gain,
        desired_delta_velocity: desired,
        target_velocity: velocity.x + desired,
        gap_velocity: 0.0,
        penetration: contact.penetration,
        friction: contact.friction,
        restitution: contact.restitution,
        normal_inertia,
        linear_inertia,
        body,
        impulse: Vec3::ZERO,
        friction_saturated: false,
        saturated_sliding: Vec3::ZERO,
        friction_shared: 0,
        projected: 0.0,
        held: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_math::Quat;

    #[test]
    fn restitution_is_dropped_below_the_velocity_limit() {
        // Slow: e′ = 0, the contact is only stopped.
        assert_eq!(desired_delta_velocity(-0.2, 0.0, 0.0, 0.8, 0.25, 0.0), 0.2);
        // Fast: full bounce.
        assert!((desired_delta_velocity(-1.0, 0.0, 0.0, 0.5, 0.25, 0.0) - 1.5).abs() < 1e-6);
        // The acceleration of the last step is not bounced back.
        assert!((desired_delta_velocity(-1.0, -0.5, 0.0, 0.5, 0.25, 0.0) - 1.25).abs() < 1e-6);
        // A 1 cm gap at 60 Hz absorbs 0.6 m/s: a slower approach is left alone, a faster one
        // is stopped exactly at the surface (inelastic) or bounced (elastic).
        assert!(desired_delta_velocity(-0.5, 0.0, 0.0, 0.0, 0.25, 0.6) < 0.0);
        assert!((desired_delta_velocity(-1.0, 0.0, 0.0, 0.0, 0.25, 0.6) - 0.4).abs() < 1e-6);
        assert!((desired_delta_velocity(-1.0, 0.0, 0.0, 0.5, 0.25, 0.6) - 1.5).abs() < 1e-6);
    }

    /// A box found 57 mm into the floor, closing at 6.703 m/s at the start of a 60 Hz step
    /// (v_acc = −9.81/60): its surfaces met 8.5 ms earlier, at 0.083 m/s less. By energy the
    /// speed there is √(6.703² − 2·9.81·0.057) = 6.6193; the first-order rule gives 6.6196.
    #[test]
    fn the_bounce_is_the_speed_the_surfaces_met_at() {
        let (v, acc, d, dt) = (-6.703f32, -9.81 / 60.0, 0.057, 1.0 / 60.0);
        let gain = impact_speed_gain(v, acc, d, dt);
        assert!((gain - 9.81 * d / 6.703).abs() < 1e-5, "gain {gain}");
        let met = (v * v - 2.0 * 9.81 * d).sqrt();
        assert!(
            ((-v - gain) - met).abs() < 1e-3,
            "{} against {met}",
            -v - gain
        );
        // With e = 1 the bounce is that speed, away from the surface (the velocity the pass
        // sees includes this step's v_acc, which is not bounced).
        let now = v + acc;
        let target = now + desired_delta_velocity(now, acc, gain, 1.0, 0.25, 0.0);
        assert!((target - (-v - gain)).abs() < 1e-4, "target {target}");
        // Nothing for a contact that is not overlapping, separating, or not accelerated in.
        assert_eq!(impact_speed_gain(v, acc, -0.01, dt), 0.0);
        assert_eq!(impact_speed_gain(1.0, acc, d, dt), 0.0);
        assert_eq!(impact_speed_gain(v, 0.1, d, dt), 0.0);
    }

    #[test]
    fn static_and_immovable_sides_are_marked() {
        let mut pinned = SolverBody::new(Vec3::X, Quat::IDENTITY, 0.0, Mat3::ZERO);
        pinned.flags = 0;
        let bodies = [
            SolverBody::STATIC,
            SolverBody::new(Vec3::Y, Quat::IDENTITY, 1.0, Mat3::IDENTITY),
            pinned,
        ];
        let c = Contact::new(1, 0, Vec3::ZERO, Vec3::Y, 0.1);
        let p = prepare(&c, &bodies, 0.01, 0.25).expect("valid indices");
        assert_eq!(p.body, [1, NO_BODY]);
        let c = Contact::new(2, 0, Vec3::ZERO, Vec3::Y, 0.1);
        let p = prepare(&c, &bodies, 0.01, 0.25).expect("valid indices");
        assert!(!p.is_active() && p.normal_inertia == 0.0);
        assert!(
            prepare(
                &Contact::new(7, 0, Vec3::ZERO, Vec3::Y, 0.1),
                &bodies,
                0.01,
                0.25
            )
            .is_none()
        );
    }

    #[test]
    fn acceleration_feeds_v_acc_but_is_not_added_twice_to_the_planar_velocity() {
        let mut b = SolverBody::new(Vec3::Y, Quat::IDENTITY, 1.0, Mat3::ZERO);
        b.last_acceleration = Vec3::new(3.0, -10.0, 0.0);
        let bodies = [SolverBody::STATIC, b];
        let p = prepare(
            &Contact::new(1, 0, Vec3::ZERO, Vec3::Y, 0.0),
            &bodies,
            0.1,
            0.25,
        )
        .expect("valid");
        // Normal part goes to v_acc; the planar part is already in the body's velocity (the
        // resolver integrates velocities first), so Cyclone's planar term is not added again.
        assert!((p.acc_velocity + 1.0).abs() < 1e-6);
        assert_eq!(p.velocity, Vec3::ZERO);
    }
}
