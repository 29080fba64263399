//! The shock sweep: what the worst-first picks leave of a load that a light body carries,
//! resolved from the ground up with each lower body held still (shock propagation).
//!
//! Worst-first picks move both bodies of a contact by their inverse masses. A heavy body
//! resting on a light one is held up only when its weight reaches the ground through the
//! light body's contacts, and each pick passes on only about m/M of it: a 1 kg box under
//! 10⁶ kg needs about a million picks where a step has a few hundred. The rest of the heavy
//! body's fall goes into the light body, which is squeezed out sideways (by up to 10 m) or
//! pushed into the floor (benches/RESULTS.md, "The shock sweep, and the Millington resolver
//! warm started by default").
//!
//! So after a pass's picks, when some contact is still above the pass's epsilon, in each
//! island that holds a contact between two movable bodies whose masses differ by
//! [`SHOCK_MASS_RATIO`] or more, every body gets a level: 1 when it touches something that
//! cannot move, one more than the lowest neighbour otherwise (contacts of the step, breadth
//! first). The island's contacts are then swept by the lower of their two levels, ground
//! contacts first: a contact with something immovable is resolved as usual, a contact
//! between two levels with the lower body held still (only the upper body moves), each level
//! a few times over ([`SHOCK_SWEEPS`]) before the next. A body thus ends resolved against
//! what lies below it, which nothing above it moves again, and a load reaches the ground in
//! one sweep, whatever the mass ratio. Contacts between bodies of one level (side by side)
//! are left to the picks, and so is a bounce in the velocity pass. Where the picks
//! converged, the sweep does nothing and costs nothing.
//!
//! Held still, the lower body gives up the reaction to what the sweep resolves: the ground
//! takes it instead, which is where a converged solve would have sent it. A resolution that
//! would give the upper body kinetic energy (a body thrown onto one moving towards it) is
//! therefore not made: the held body could not pay for it.

use super::change::NO_BODY;
use super::islands::Islands;
use super::prepare::PreparedContact;
use super::worst_first::{Pass, PickScratch, for_each_neighbour};
use crate::SolverBody;

/// Sweeps over the contacts of one level before the next, at most (a level ends when no
/// contact of it is above the epsilon): the points of a face share their load through the
/// upper body's rotation, which one sweep leaves partly unresolved. With four, a 1:1,000 pair
/// stepped at `dt` 1.0 s left the heavy box rising at 8 mm/s, 8 mm of height and 77 J gained
/// in a step; eight, sixteen and sixty-four sweeps give the same result there.
pub const SHOCK_SWEEPS: u32 = 8;

/// Mass ratio (dimensionless) between two movable bodies in contact from which their island
/// is swept. Below it the worst-first picks pass a load on at a useful rate (about 1 − m/M
/// of what is missing stays per pick), and warm started they converge on resting stacks
/// within their budget; the sweep there would only disturb them: one-sided resolutions left a
/// warm-started 20-row pyramid far from converged at every step (33 ms a step against 0.8).
/// The soft step's direct solve starts at the same ratio.
pub const SHOCK_MASS_RATIO: f32 = 10.0;

/// No side is held: the contact is with something that cannot move.
const NONE_HELD: u8 = 2;

/// The bodies' levels and the order of the sweep, built once per step when a pass first needs
/// them (reused buffers).
#[derive(Clone, Debug, Default)]
pub(crate) struct Shock {
    /// Level of each body (1 on the ground), `u32::MAX` when not connected to the ground.
    level: Vec<u32>,
    /// Breadth-first queue (scratch).
    queue: Vec<u32>,
    /// (lower level, contact, side held or [`NONE_HELD`]), sorted.
    order: Vec<(u32, u32, u8)>,
    /// Whether `order` is this step's.
    built: bool,
    /// Whether each contact's island is swept (it holds a mass ratio).
    swept: Vec<bool>,
}

/// Whether the contacts `island` (indices into `contacts`) join two movable bodies whose
/// masses are [`SHOCK_MASS_RATIO`] or more apart.
pub(crate) fn holds_mass_ratio(
    island: &[u32],
    contacts: &[PreparedContact],
    bodies: &[SolverBody],
) -> bool {
    island.iter().any(|&c| match contacts[c as usize].body {
        [a, b] if a != NO_BODY && b != NO_BODY => {
            let mass = |k: u32| bodies.get(k as usize).map_or(0.0, |b| b.inv_mass);
            let (ia, ib) = (mass(a), mass(b));
            ia.max(ib) >= SHOCK_MASS_RATIO * ia.min(ib)
        }
        _ => false,
    })
}

impl Shock {
    /// Forgets the last step's order.
    pub(crate) fn reset(&mut self) {
        self.built = false;
    }

    /// Levels and sweep order for this step's `contacts` over `bodies`: the contacts of the
    /// islands that hold a mass ratio of [`SHOCK_MASS_RATIO`] or more.
    fn build(&mut self, contacts: &[PreparedContact], islands: &Islands, bodies: &[SolverBody]) {
        self.built = true;
        self.swept.clear();
        self.swept.resize(contacts.len(), false);
        for i in 0..islands.len() {
            let island = islands.island(i);
            if holds_mass_ratio(island, contacts, bodies) {
                for &c in island {
                    self.swept[c as usize] = true;
                }
            }
        }
        self.order.clear();
        if !self.swept.contains(&true) {
            return;
        }
        self.level.clear();
        self.level.resize(bodies.len(), u32::MAX);
        self.queue.clear();
        // Levels only in the swept islands: each island's contacts touch its bodies alone.
        for (c, _) in contacts
            .iter()
            .zip(&self.swept)
            .filter(|&(c, &swept)| swept && c.normal_inertia > 0.0)
        {
            let on_ground = match c.body {
                [NO_BODY, b] | [b, NO_BODY] => b,
                _ => continue,
            };
            if let Some(level) = self.level.get_mut(on_ground as usize)
                && *level == u32::MAX
            {
                *level = 1;
                self.queue.push(on_ground);
            }
        }
        let mut next = 0;
        while let Some(&body) = self.queue.get(next) {
            next += 1;
            let up = self.level[body as usize] + 1;
            for &c in islands.contacts_of(body) {
                for other in contacts[c as usize].body {
                    if other != NO_BODY
                        && let Some(level) = self.level.get_mut(other as usize)
                        && *level == u32::MAX
                    {
                        *level = up;
                        self.queue.push(other);
                    }
                }
            }
        }
        for (i, c) in contacts.iter().enumerate() {
            if !(c.normal_inertia > 0.0 && self.swept[i]) {
                continue;
            }
            let level = |b: u32| self.level.get(b as usize).copied().unwrap_or(u32::MAX);
            let entry = match c.body {
                [NO_BODY, b] | [b, NO_BODY] if level(b) != u32::MAX => (0, NONE_HELD),
                [a, b] if a != NO_BODY && b != NO_BODY => {
                    let (la, lb) = (level(a), level(b));
                    if la == lb || la == u32::MAX || lb == u32::MAX {
                        continue;
                    }
                    if la < lb { (la, 0) } else { (lb, 1) }
                }
                _ => continue,
            };
            self.order.push((entry.0, i as u32, entry.1));
        }
        self.order.sort_unstable();
    }

    /// Whether this step's sweep has nothing to resolve (no island holds a mass ratio).
    pub(crate) fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Builds the levels and the order for this step's `contacts` over `bodies` bodies,
    /// unless this step's are built already.
    pub(crate) fn prepare(
        &mut self,
        contacts: &[PreparedContact],
        islands: &Islands,
        bodies: &[SolverBody],
    ) {
        if !self.built {
            self.build(contacts, islands, bodies);
        }
    }

    /// The shock sweep of one pass ([`Shock::prepare`]d for this step); returns the contacts
    /// resolved, and leaves the largest key left in [`PickScratch::residual`].
    pub(crate) fn sweep<P: Pass>(
        &self,
        pass: &mut P,
        islands: &Islands,
        scratch: &mut PickScratch,
        epsilon: f32,
    ) -> u32 {
        debug_assert!(self.built, "the sweep's order is this step's");
        let resolved = run(pass, &self.order, islands, scratch, epsilon);
        scratch.residual = (0..islands.len())
            .flat_map(|i| islands.island(i))
            .map(|&c| pass.key(c))
            .fold(0.0, f32::max);
        resolved
    }
}

/// Runs the shock sweep over `order` ([`Shock`]'s): each level's contacts up to
/// [`SHOCK_SWEEPS`] times, those still above `epsilon` resolved with their lower side held.
fn run<P: Pass>(
    pass: &mut P,
    order: &[(u32, u32, u8)],
    islands: &Islands,
    scratch: &mut PickScratch,
    epsilon: f32,
) -> u32 {
    let mut resolved = 0;
    let mut start = 0;
    while start < order.len() {
        let level = order[start].0;
        let end = start + order[start..].iter().take_while(|o| o.0 == level).count();
        for _ in 0..SHOCK_SWEEPS {
            let mut any = false;
            for &(_, c, held) in &order[start..end] {
                if !(pass.key(c) > epsilon) || !pass.sweeps_held(c) {
                    continue;
                }
                let change = if held == NONE_HELD {
                    pass.resolve(c)
                } else {
                    pass.resolve_held(c, held as usize)
                };
                let Some(change) = change else {
                    continue;
                };
                any = true;
                resolved += 1;
                for_each_neighbour(islands, &mut scratch.stamps, &change, |n| {
                    pass.update(n, &change);
                });
            }
            if !any {
                break;
            }
        }
        start = end;
    }
    resolved
}
