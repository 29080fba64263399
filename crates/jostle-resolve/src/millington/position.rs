//! Penetration resolution of one contact by projection, and the update of a neighbour's
//! penetration afterwards. Seed lecture: "Choosing a Resolution Method" (methods 1, 3 and 4),
//! "Nonlinear Projection: Implementation", "Avoiding Excessive Rotation" and "Updating
//! Penetration Depths"; Cyclone's `applyPositionChange`.

use super::change::{BodyChange, NO_BODY};
use super::prepare::{PreparedContact, angular_inertia};
use super::settings::{MillingtonSettings, Projection};
use crate::SolverBody;
use jostle_math::{Mat3, Vec3, integrate_orientation};

/// How far each side moves along the normal to resolve a contact (m), and the rotation that
/// produces the angular part.
///
/// Signs follow the lecture's (−1)^(i+1): side A moves +`linear[0]` along n, side B moves
/// `linear[1]` (negative) along n; A's and B's moves sum (in absolute value) to the resolved
/// penetration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PenetrationMoves {
    /// Linear move of each side's centre of mass along the normal (m; a body with a
    /// translation lock moves as [`SolverBody::linear_direction`] says, by this much along
    /// the normal).
    pub linear: [f32; 2],
    /// Move of each side's contact point along the normal produced by rotation (m).
    pub angular: [f32; 2],
    /// Rotation vector of each side (rad): (Δθ)_i · (Δa)_i / (I_a)_i.
    pub rotation: [Vec3; 2],
}

/// The penetration (m) a pick of `p` resolves: `relaxation · penetration`, with the contact's
/// total over the step ([`PreparedContact::projected`]) kept ≥ 0. A contact that a
/// neighbour's projection has since lifted clear (negative penetration) takes back part of
/// its own earlier push, never more: the points of one face then share the push as the
/// geometry asks. Projected one after the other without it, the first of an edge's two
/// points tipped the body onto the second, whose projection then tipped the first clear, and
/// the first could not give anything back (the lecture's cube ended turned about its edge).
#[inline]
pub fn projection_depth(p: &PreparedContact, relaxation: f32) -> f32 {
    (p.projected + p.penetration * relaxation).max(0.0) - p.projected
}

/// What a pick of `p` would resolve, as the position pass ranks it (m): the penetration
/// while there is one, else how far the contact may still back off towards touching
/// (|penetration|, at most its accumulated projection over the relaxation); for a clear
/// contact with nothing to take back, its (negative) penetration.
#[inline]
pub fn position_key(p: &PreparedContact, relaxation: f32) -> f32 {
    if p.penetration >= 0.0 || !(p.projected > 0.0) || !(relaxation > 0.0) {
        p.penetration
    } else {
        (-p.penetration).min(p.projected / relaxation)
    }
}

/// The nonlinear projection of `p` (lecture method 3 with relaxation, method 4): the resolved
/// penetration ([`projection_depth`]: `relaxation · penetration` on a contact's first pick)
/// is shared between the linear inertia 1/m and the
/// angular inertia ((I⁻¹(r×n))×r)·n of each moving side; each angular move is limited to
/// `angular_limit · |r − (r·n)n|` and the excess given to the linear move (Cyclone's limit,
/// the lecture's "scale the angular move by the size of the object").
///
/// `None` when the total inertia is zero (both bodies immovable): nothing can move, and
/// Cyclone's division by zero is avoided.
pub fn nonlinear_moves(
    p: &PreparedContact,
    bodies: &[SolverBody],
    angular_limit: f32,
    relaxation: f32,
) -> Option<PenetrationMoves> {
    let n = p.normal();
    let mut lin = [0.0f32; 2];
    let mut ang = [0.0f32; 2];
    let mut total = 0.0f32;
    for side in 0..2 {
        if let Some(b) = p.side_body(bodies, side) {
            lin[side] = b.inv_mass_along(n);
            ang[side] = angular_inertia(b, p.r[side], n);
            total += lin[side] + ang[side];
        }
    }
    if !(total > 0.0) {
        return None;
    }
    let depth = projection_depth(p, relaxation);
    let mut moves = PenetrationMoves::default();
    for side in 0..2 {
        let Some(b) = p.side_body(bodies, side) else {
            continue;
        };
        let sign = if side == 0 { 1.0 } else { -1.0 };
        let mut angular_move = sign * depth * (ang[side] / total);
        let mut linear_move = sign * depth * (lin[side] / total);
        let r = p.r[side];
        let max = angular_limit * (r - n * r.dot(n)).length();
        if angular_move.abs() > max {
            let whole = angular_move + linear_move;
            angular_move = max.copysign(angular_move);
            linear_move = whole - angular_move;
        }
        moves.linear[side] = linear_move;
        moves.angular[side] = angular_move;
        if angular_move != 0.0 && ang[side] > 0.0 {
            // Rotation per unit move of the contact point, times the move (lecture, three stages).
            let per_unit_impulse = b.inv_inertia * r.cross(n);
            moves.rotation[side] = per_unit_impulse * (angular_move / ang[side]);
        }
    }
    Some(moves)
}

/// The linear projection of `p` (lecture method 1, with relaxation; the depth of
/// [`projection_depth`]): both sides translate
/// along the normal in proportion to their inverse masses; nothing rotates. `None` when
/// neither side can translate.
pub fn linear_moves(
    p: &PreparedContact,
    bodies: &[SolverBody],
    relaxation: f32,
) -> Option<PenetrationMoves> {
    let total = p.linear_inertia;
    if !(total > 0.0) {
        return None;
    }
    let depth = projection_depth(p, relaxation);
    let n = p.normal();
    let mut moves = PenetrationMoves::default();
    for side in 0..2 {
        if let Some(b) = p.side_body(bodies, side) {
            let sign = if side == 0 { 1.0 } else { -1.0 };
            moves.linear[side] = sign * depth * (b.inv_mass_along(n) / total);
        }
    }
    Some(moves)
}

/// Moves both bodies by `moves`: the centre of mass along the normal, the orientation by
/// [`integrate_orientation`] (the lecture's θ' = θ + ½[0, Δθ]θ).
///
/// A rotated body's world inverse inertia is rotated with it (Cyclone recomputes it after every
/// projection, `calculateDerivedData`), and so is its angular velocity: projection re-places the
/// body rigidly, spin included. Leaving ω fixed in world space while the inertia turns changed
/// ½·ωᵀ·I·ω — a spinning body knocked by a projection gained kinetic energy (found by the
/// property tests in `tests/properties.rs`); turned with the body, both |L| and the energy are
/// kept exactly.
pub fn apply_moves(
    p: &PreparedContact,
    moves: &PenetrationMoves,
    bodies: &mut [SolverBody],
) -> BodyChange {
    let n = p.normal();
    let mut change = BodyChange {
        body: p.body,
        ..BodyChange::NONE
    };
    for side in 0..2 {
        let Some(b) = p.side_body_mut(bodies, side) else {
            change.body[side] = NO_BODY;
            continue;
        };
        // Along n, or as near it as a translation lock allows, advancing `moves.linear`
        // along n all the same; but no farther than the move itself, which a normal nearly
        // along a locked axis (a direction of length 1/sin of their angle) could make
        // arbitrarily long.
        let mut linear = b.linear_direction(n) * moves.linear[side];
        if b.flags & SolverBody::LOCKS != 0 {
            let length = linear.length();
            let most = moves.linear[side].abs();
            if length > most {
                linear *= most / length;
            }
        }
        b.position += linear;
        change.linear[side] = linear;
        let rotation = moves.rotation[side];
        if b.rotates() && rotation != Vec3::ZERO {
            let before = b.orientation;
            b.orientation = integrate_orientation(before, rotation);
            let turn = Mat3::from_quat(b.orientation * before.inverse());
            b.angular_velocity = turn * b.angular_velocity;
            b.inv_inertia = turn * b.inv_inertia * turn.transpose();
            change.angular[side] = rotation;
        }
    }
    change
}

/// Resolves the penetration of `p` with the projection chosen in `settings` and moves the
/// bodies, adding the depth resolved to `p.projected` ([`projection_depth`]).
/// `p.penetration` itself is **not** updated here; the pass updates it like any other
/// contact sharing a body ([`update_penetration`]), as Cyclone does. `None` when nothing can
/// move.
pub fn resolve_penetration(
    p: &mut PreparedContact,
    bodies: &mut [SolverBody],
    settings: &MillingtonSettings,
) -> Option<BodyChange> {
    let moves = match settings.projection {
        Projection::Nonlinear => {
            nonlinear_moves(p, bodies, settings.angular_limit, settings.relaxation)
        }
        Projection::Linear => linear_moves(p, bodies, settings.relaxation),
    }?;
    p.projected += projection_depth(p, settings.relaxation);
    Some(apply_moves(p, &moves, bodies))
}

/// Updates the penetration of `p` after `change` moved bodies it may share: the contact point
/// of a side moved by d = Δlinear + Δangular × r, so Δpen = −d·n for side A (A moving along n
/// separates) and +d·n for side B. Returns whether `p` shared a body with the change.
pub fn update_penetration(p: &mut PreparedContact, change: &BodyChange) -> bool {
    let n = p.normal();
    let mut touched = false;
    if let Some(d) = change.point_change(p.body[0], p.r[0]) {
        p.penetration -= d.dot(n);
        touched = true;
    }
    if let Some(d) = change.point_change(p.body[1], p.r[1]) {
        p.penetration += d.dot(n);
        touched = true;
    }
    touched
}

/// Whether the position pass can resolve `p` with this projection (non-zero total inertia).
#[inline]
pub fn resolvable(p: &PreparedContact, projection: Projection) -> bool {
    match projection {
        Projection::Nonlinear => p.normal_inertia > 0.0,
        Projection::Linear => p.linear_inertia > 0.0,
    }
}
