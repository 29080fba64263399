//! Collision groups: which colliders may touch which, by membership and filter bits.

/// Which colliders meet: a collider is a member of the groups set in `memberships` and meets
/// the groups set in `filter`; two colliders meet (make contacts, or report sensor events)
/// when each one's memberships share a bit with the other's filter. The default is a member of
/// every group that meets every group.
///
/// ```
/// use jostle_collide::CollisionGroups;
///
/// const PLAYER: u32 = 1;
/// const DEBRIS: u32 = 2;
/// let player = CollisionGroups::new(PLAYER, !DEBRIS); // passes through debris
/// let debris = CollisionGroups::new(DEBRIS, u32::MAX);
/// assert!(!player.meets(&debris));
/// assert!(player.meets(&CollisionGroups::default()));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CollisionGroups {
    /// The groups the collider belongs to (one bit each).
    pub memberships: u32,
    /// The groups it meets.
    pub filter: u32,
}

impl Default for CollisionGroups {
    fn default() -> Self {
        Self::ALL
    }
}

impl CollisionGroups {
    /// A member of every group, meeting every group (the default).
    pub const ALL: Self = Self {
        memberships: u32::MAX,
        filter: u32::MAX,
    };

    /// Groups from membership and filter bits.
    pub const fn new(memberships: u32, filter: u32) -> Self {
        Self {
            memberships,
            filter,
        }
    }

    /// Whether colliders with these groups and `other` meet: each one's memberships share a
    /// bit with the other's filter.
    #[inline]
    pub fn meets(&self, other: &Self) -> bool {
        self.memberships & other.filter != 0 && other.memberships & self.filter != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_sides_must_accept() {
        let a = CollisionGroups::new(0b01, 0b10);
        let b = CollisionGroups::new(0b10, 0b01);
        let c = CollisionGroups::new(0b10, 0b10);
        assert!(a.meets(&b) && b.meets(&a));
        // c accepts a's membership? a is 0b01, c's filter 0b10: no.
        assert!(!a.meets(&c) && !c.meets(&a));
        assert!(CollisionGroups::default().meets(&a));
        assert!(!CollisionGroups::new(0, u32::MAX).meets(&CollisionGroups::ALL));
    }
}
