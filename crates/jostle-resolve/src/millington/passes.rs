//! The position and velocity passes as [`Pass`] implementations: what "worst" means for each,
//! how a contact is resolved, and how a neighbour is updated.

use super::change::BodyChange;
use super::position::{position_key, resolvable, resolve_penetration, update_penetration};
use super::prepare::PreparedContact;
use super::settings::MillingtonSettings;
use super::velocity::{
    normal_key, reopen_friction, resolve_manifold_normals, resolve_velocity,
    share_manifold_friction, update_velocity_for, velocity_key,
};
use super::worst_first::Pass;
use crate::SolverBody;

/// The position pass: worst = deepest penetration, or the most a contact lifted clear may
/// take back of its own projection ([`position_key`]).
pub(crate) struct PositionPass<'a> {
    pub(crate) contacts: &'a mut [PreparedContact],
    pub(crate) bodies: &'a mut [SolverBody],
    pub(crate) settings: &'a MillingtonSettings,
}

impl Pass for PositionPass<'_> {
    fn contacts(&self) -> &[PreparedContact] {
        self.contacts
    }

    fn bodies(&self) -> &[SolverBody] {
        self.bodies
    }

    #[inline]
    fn key(&self, contact: u32) -> f32 {
        let p = &self.contacts[contact as usize];
        if resolvable(p, self.settings.projection) {
            position_key(p, self.settings.relaxation)
        } else {
            f32::NEG_INFINITY
        }
    }

    fn resolve(&mut self, contact: u32) -> Option<BodyChange> {
        resolve_penetration(
            &mut self.contacts[contact as usize],
            self.bodies,
            self.settings,
        )
    }

    fn resolve_held(&mut self, contact: u32, side: usize) -> Option<BodyChange> {
        let p = &mut self.contacts[contact as usize];
        let mut held = p.with_side_held(side, self.bodies);
        let change = resolve_penetration(&mut held, self.bodies, self.settings);
        p.take_resolved(&held);
        change
    }

    #[inline]
    fn update(&mut self, contact: u32, change: &BodyChange) {
        update_penetration(&mut self.contacts[contact as usize], change);
    }
}

/// The velocity pass: worst = largest velocity a pick would remove: the desired normal change,
/// or the sliding speed of a contact whose friction can still act ([`velocity_key`]).
pub(crate) struct VelocityPass<'a> {
    pub(crate) contacts: &'a mut [PreparedContact],
    pub(crate) bodies: &'a mut [SolverBody],
    pub(crate) velocity_limit: f32,
    pub(crate) velocity_epsilon: f32,
    /// The contact resolved by the last pick (its own update records its saturation).
    pub(crate) picked: u32,
    /// Its two bodies, as the contact has them: the pair the last pick was made for, even
    /// where it held one of them still ([`update_velocity_for`]).
    pub(crate) picked_pair: [u32; 2],
    /// Each contact's manifold, `start..end` in `contacts`, when picks are by manifold
    /// ([`MillingtonSettings::manifold_picks`]); empty otherwise.
    pub(crate) manifolds: &'a [[u32; 2]],
}

impl Pass for VelocityPass<'_> {
    fn contacts(&self) -> &[PreparedContact] {
        self.contacts
    }

    fn bodies(&self) -> &[SolverBody] {
        self.bodies
    }

    /// [`velocity_key`]: the desired normal change, or the sliding speed while the contact's
    /// friction can still remove it (fix of the original; see its rustdoc).
    #[inline]
    fn key(&self, contact: u32) -> f32 {
        velocity_key(&self.contacts[contact as usize])
    }

    /// With [`MillingtonSettings::manifold_picks`], a contact picked for its normal velocity
    /// resolves its manifold's normal velocities together
    /// ([`resolve_manifold_normals`]) unless that block cannot resolve it; otherwise, and
    /// for sliding, [`resolve_velocity`] alone.
    fn resolve(&mut self, contact: u32) -> Option<BodyChange> {
        self.picked = contact;
        self.picked_pair = self.contacts[contact as usize].body;
        if let Some(&[start, end]) = self.manifolds.get(contact as usize) {
            let p = &self.contacts[contact as usize];
            if end - start >= 2 && velocity_key(p) <= normal_key(p) {
                let range = start as usize..end as usize;
                if let Some(change) = resolve_manifold_normals(
                    &mut self.contacts[range],
                    (contact - start) as usize,
                    self.bodies,
                ) {
                    return Some(change);
                }
            }
        }
        let mut change = resolve_velocity(&mut self.contacts[contact as usize], self.bodies);
        if self.contacts[contact as usize].friction_saturated
            && let Some(&[start, end]) = self.manifolds.get(contact as usize)
            && let Some(shared) = share_manifold_friction(
                &mut self.contacts[start as usize..end as usize],
                self.bodies,
                self.velocity_epsilon,
            )
        {
            // The same two bodies: the picked contact is one of the manifold's points.
            change.add(&shared);
        }
        Some(change)
    }

    /// Not applied (`None`) where it would give the moving body kinetic energy: held
    /// still, the lower body gives none of its own back, so a pick that speeds the upper
    /// body up (a body thrown onto one moving towards it) would create energy.
    fn resolve_held(&mut self, contact: u32, side: usize) -> Option<BodyChange> {
        let p = &mut self.contacts[contact as usize];
        let mut held = p.with_side_held(side, self.bodies);
        let moving = held.body[1 - side] as usize;
        let r = held.r[1 - side];
        let before = self.bodies.get(moving).copied()?;
        let change = resolve_velocity(&mut held, self.bodies);
        // ΔE = J·(u + ½Δu): J the impulse on the moving body at its point, u the point's
        // velocity before and Δu its change.
        let impulse = held.basis * (held.impulse - p.impulse);
        let impulse = if side == 1 { impulse } else { -impulse };
        let u = before.linear_velocity + before.angular_velocity.cross(r);
        let du = change.point_change(moving as u32, r).unwrap_or_default();
        if !(impulse.dot(u + 0.5 * du) <= 0.0) {
            self.bodies[moving] = before;
            return None;
        }
        self.picked = contact;
        self.picked_pair = p.body;
        p.take_resolved(&held);
        Some(change)
    }

    /// A bouncing contact (a target separating speed of at least the velocity limit, below
    /// which no contact bounces) is left to the worst-first picks: held still, its other body
    /// would bounce off a body that does not give.
    #[inline]
    fn sweeps_held(&self, contact: u32) -> bool {
        self.contacts[contact as usize].target_velocity < self.velocity_limit
    }

    /// [`update_velocity`], then [`reopen_friction`] for a contact that shares a body with
    /// the change.
    #[inline]
    fn update(&mut self, contact: u32, change: &BodyChange) {
        let p = &mut self.contacts[contact as usize];
        if update_velocity_for(p, change, self.picked_pair, self.velocity_limit) {
            reopen_friction(p, contact == self.picked, self.velocity_epsilon);
        }
    }
}
