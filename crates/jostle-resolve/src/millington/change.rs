//! What resolving one contact did to its (at most two) bodies: the record both passes hand to
//! the neighbours of the resolved contact so they can update themselves without collision
//! detection (seed lecture, "Updating Penetration Depths").

use jostle_math::Vec3;

/// Marks a contact side that no pass moves: the static entry, or a body that is immovable
/// (zero inverse mass and no [`crate::SolverBody::ROTATES`] flag). Never a valid body index in
/// the sense of the passes, so it matches no other contact's side.
pub const NO_BODY: u32 = u32::MAX;

/// The change one resolution made to each side's body.
///
/// In the position pass `linear` is the translation (m) and `angular` the rotation vector
/// (rad) applied by projection; in the velocity pass they are Δv (m/s) and Δω (rad/s).
/// A side whose `body` is [`NO_BODY`] was not changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyChange {
    /// Body index of side A and side B, or [`NO_BODY`].
    pub body: [u32; 2],
    /// Linear change of each side.
    pub linear: [Vec3; 2],
    /// Angular change of each side (zero for bodies that do not rotate).
    pub angular: [Vec3; 2],
}

impl BodyChange {
    /// A change that touches nothing.
    pub const NONE: BodyChange = BodyChange {
        body: [NO_BODY; 2],
        linear: [Vec3::ZERO; 2],
        angular: [Vec3::ZERO; 2],
    };

    /// Adds `other`, a change of the same two bodies, side by side.
    #[inline]
    pub fn add(&mut self, other: &BodyChange) {
        debug_assert_eq!(self.body, other.body, "changes of different bodies");
        for side in 0..2 {
            self.linear[side] += other.linear[side];
            self.angular[side] += other.angular[side];
        }
    }

    /// The change of the material point at lever arm `r` of body `body`, summed over the
    /// sides that changed it (a contact may touch the same body twice only in degenerate
    /// input, where summing is still the right answer). `None` when `body` is unchanged.
    ///
    /// Δ = linear + angular × r: for the position pass the displacement of the point
    /// (first order in the rotation), for the velocity pass the change of its velocity.
    #[inline]
    pub fn point_change(&self, body: u32, r: Vec3) -> Option<Vec3> {
        if body == NO_BODY {
            return None;
        }
        let mut out: Option<Vec3> = None;
        for d in 0..2 {
            if self.body[d] == body {
                let delta = self.linear[d] + self.angular[d].cross(r);
                out = Some(out.map_or(delta, |o| o + delta));
            }
        }
        out
    }

    /// Whether the change touches `body`.
    #[inline]
    pub fn touches(&self, body: u32) -> bool {
        body != NO_BODY && (self.body[0] == body || self.body[1] == body)
    }
}
