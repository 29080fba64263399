//! The position and velocity passes as [`Pass`] implementations: what "worst" means for each,
//! how a contact is resolved, and how a neighbour is updated.

use super::change::BodyChange;
use super::position::{position_key, resolvable, resolve_penetration, update_penetration};
use super::prepare::PreparedContact;
use super::settings::MillingtonSettings;
use super::velocity::{reopen_friction, resolve_velocity, update_velocity, velocity_key};
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
}

impl Pass for VelocityPass<'_> {
    /// [`velocity_key`]: the desired normal change, or the sliding speed while the contact's
    /// friction can still remove it (fix of the original; see its rustdoc).
    #[inline]
    fn key(&self, contact: u32) -> f32 {
        velocity_key(&self.contacts[contact as usize])
    }

    fn resolve(&mut self, contact: u32) -> Option<BodyChange> {
        self.picked = contact;
        Some(resolve_velocity(
            &mut self.contacts[contact as usize],
            self.bodies,
        ))
    }

    /// [`update_velocity`], then [`reopen_friction`] for a contact that shares a body with
    /// the change.
    #[inline]
    fn update(&mut self, contact: u32, change: &BodyChange) {
        let p = &mut self.contacts[contact as usize];
        if update_velocity(p, change, self.velocity_limit) {
            reopen_friction(p, contact == self.picked, self.velocity_epsilon);
        }
    }
}
