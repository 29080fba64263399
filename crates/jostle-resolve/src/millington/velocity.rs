//! Velocity resolution of one contact: the impulse that gives the desired normal velocity
//! change (frictionless 1D when μ = 0, else the full 3×3 contact-space impulse with the
//! static/dynamic Coulomb test), applying it to both bodies, and updating a neighbour's closing
//! velocity afterwards. Seed lecture: "Velocity Change by Unit Impulse" through "Computing
//! Impulse"; Millington ch. 14–15.
//!
//! Four defects of Cyclone's `calculateFrictionImpulse`/`calculateFrictionlessImpulse` (and
//! of the lecture's velocity pass) are fixed here, each with a regression test: a zero total
//! inertia (both bodies immovable) divides by zero; the dynamic-friction denominator
//! K₀₀ + μ(K₀₁ŷ + K₀₂ẑ) can approach zero or go negative (friction coupling that reduces the
//! normal response), giving unbounded or pulling impulses; the normal impulse is never
//! clamped, so a contact can pull; and the Coulomb test limits each pick by its own normal
//! impulse while picks follow the normal velocity change alone, so resting boxes creep down
//! slopes and drift on flat ground. The last is fixed by testing Coulomb against the impulse
//! the contact accumulated this step ([`coulomb_accumulated`], with the normal clamp on that
//! total) and by keying picks on the sliding speed too while friction can still act
//! ([`velocity_key`]).

use super::change::{BodyChange, NO_BODY};
use super::prepare::{PreparedContact, desired_delta_velocity};
use crate::SolverBody;
use jostle_math::{Mat3, Vec3, skew};

/// When friction coupling would leave less than this fraction of the frictionless normal
/// response K₀₀ per unit normal impulse, the dynamic-friction coefficient used for this pick is
/// reduced until exactly this fraction remains. This bounds the normal impulse at
/// `desired / (0.25 · K₀₀)`, four times the frictionless one, and keeps the tangential impulse
/// inside the friction cone. Cyclone divides by the raw denominator, which may be ~0 or < 0.
pub const DYNAMIC_FRICTION_MIN_RESPONSE: f32 = 0.25;

/// The lecture's Δq̇_t: velocity change along the normal per unit impulse along the normal,
/// Σ 1/m + ((I⁻¹(r×n))×r)·n over the moving sides, with n·W·n for 1/m where a side's
/// translation is locked (W its per-axis inverse mass; computed once by
/// [`super::prepare::prepare`]).
#[inline]
pub fn velocity_change_per_unit_impulse(p: &PreparedContact) -> f32 {
    p.normal_inertia
}

/// The contact-space matrix K mapping a contact-space impulse on A to the change of A's
/// closing velocity relative to B (seed lecture, "Computing Impulse"):
/// K = Bᵀ (Σ −\[r\]× I⁻¹ \[r\]× + Σ W) B, summed over the moving sides, B the basis and W
/// the side's inverse mass: (1/m)·𝟙, or diagonal with zeros along translation-locked world
/// axes ([`SolverBody::inv_mass_axes`]).
pub fn impulse_matrix(p: &PreparedContact, bodies: &[SolverBody]) -> Mat3 {
    let mut angular = Mat3::ZERO;
    let mut inv_mass = 0.0;
    let mut locked = Mat3::ZERO;
    for side in 0..2 {
        let Some(b) = p.side_body(bodies, side) else {
            continue;
        };
        if b.flags & SolverBody::LOCKS == 0 {
            inv_mass += b.inv_mass;
        } else {
            // A translation lock: M⁻¹ is diagonal, zero along the locked world axes.
            locked += Mat3::from_diagonal(b.inv_mass_axes());
        }
        if b.rotates() {
            let to_torque = skew(p.r[side]);
            angular -= to_torque * b.inv_inertia * to_torque;
        }
    }
    if locked != Mat3::ZERO {
        angular += locked;
    }
    let mut k = p.basis.transpose() * angular * p.basis;
    k.x_axis.x += inv_mass;
    k.y_axis.y += inv_mass;
    k.z_axis.z += inv_mass;
    k
}

/// The frictionless impulse (contact space): (Δv / Δq̇_t, 0, 0), with the contact's total
/// impulse of the step clamped to a push. Zero when the contact cannot be resolved (total
/// inertia zero).
pub fn frictionless_impulse(p: &PreparedContact) -> Vec3 {
    let k00 = p.normal_inertia;
    if !(k00 > 0.0) {
        // Fix: Cyclone divides by zero here when both bodies are immovable.
        return Vec3::ZERO;
    }
    // Clamped on the step's accumulated impulse: a pick may take back part of its earlier
    // pushes (never pull).
    let g = (p.impulse.x + p.desired_delta_velocity / k00).max(0.0) - p.impulse.x;
    if g.is_finite() {
        Vec3::new(g, 0.0, 0.0)
    } else {
        Vec3::ZERO
    }
}

/// The impulse with friction (contact space) that a pick of `p` applies: solve
/// K g = (Δv, −v_y, −v_z) for the impulse that gives the desired normal change and kills the
/// sliding velocity (seed lecture, "Computing Impulse"), then limit the step's **total**
/// impulse `p.impulse + g` with [`coulomb_accumulated`]. A tangent direction nothing can move
/// along (bodies kept in a plane by their locks) gets no friction and the rest is solved
/// (`without_dead_tangents`). Falls back to [`frictionless_impulse`] when K is otherwise
/// singular or the contact cannot be resolved.
///
/// A contact that has applied no normal impulse this step and wants none (Δv ≤ 0) has no
/// friction to give: the impulse is zero. When it has, a negative desired normal change (it
/// separates, or its restitution target is already met) is replaced by 0 in the solve: such a
/// contact is picked only for its sliding ([`velocity_key`]), and friction must not pull it
/// shut or undo its bounce; it keeps its normal velocity instead. With Δv > 0 and no impulse
/// yet this is exactly the lecture's procedure.
pub fn friction_impulse(p: &PreparedContact, bodies: &[SolverBody]) -> Vec3 {
    friction_pick(p, bodies).applied
}

/// What one friction pick does: the impulse it applies and whether the contact's friction is
/// then saturated (see [`PreparedContact::friction_saturated`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionPick {
    /// Impulse the pick applies, contact space, on A (N·s).
    pub applied: Vec3,
    /// Whether the step's total impulse ended on the edge of the friction cone (dynamic
    /// friction, or static to within [`FRICTION_CAPACITY_TOLERANCE`]) or no friction could be
    /// applied.
    pub saturated: bool,
}

/// [`friction_impulse`] with the saturation flag the velocity pass records.
pub fn friction_pick(p: &PreparedContact, bodies: &[SolverBody]) -> FrictionPick {
    // Nothing here can ever remove sliding: report saturation so the pass does not re-pick.
    let no_friction = |applied| FrictionPick {
        applied,
        saturated: true,
    };
    if !(p.normal_inertia > 0.0) {
        return no_friction(Vec3::ZERO);
    }
    let (k, dead) = without_dead_tangents(impulse_matrix(p, bodies));
    // K's entries are inverse masses: for bodies of 10¹⁴ kg and more its determinant, a cube
    // of them, fell below f32's normal range and its inverse overflowed, so friction was lost
    // and a spinning box of 10¹⁶ kg gained a fifth of its energy. Where the normal response is
    // below [`SMALL_RESPONSE`], K is solved scaled to a unit normal response (K₀₀ > 0:
    // `normal_inertia` above); elsewhere exactly as before.
    let unit = if k.x_axis.x < SMALL_RESPONSE {
        1.0 / k.x_axis.x
    } else {
        1.0
    };
    if !(unit.is_finite() && unit > 0.0) {
        return no_friction(frictionless_impulse(p));
    }
    let k_unit = k * unit;
    let det = k_unit.determinant();
    let scale = k_unit.x_axis.x * k_unit.y_axis.y * k_unit.z_axis.z;
    if !(det.abs() > 1e-6 * scale) {
        return no_friction(frictionless_impulse(p));
    }
    if !(p.desired_delta_velocity > 0.0) && !(p.impulse.x > 0.0) {
        // No normal impulse this step and none wanted: no friction to give.
        return no_friction(Vec3::ZERO);
    }
    // Past its target (Δv < 0) a contact gives back part of what it pushed this step, never
    // more; with nothing pushed, its normal velocity is left as it is.
    let desired = if p.desired_delta_velocity < 0.0 && !(p.impulse.x > 0.0) {
        0.0
    } else {
        p.desired_delta_velocity
    };
    let live = Vec3::new(1.0, f32::from(!dead[0]), f32::from(!dead[1]));
    let target = Vec3::new(desired, -p.velocity.y, -p.velocity.z) * live;
    let g = (k_unit.inverse() * (target * unit)) * live;
    coulomb_accumulated(
        p.impulse,
        g,
        k,
        desired,
        p.friction,
        p.velocity * live,
        p.sliding_before,
    )
}

/// `k` with each tangent direction that no impulse can move (its row and column zero to
/// rounding: both bodies locked against it, as a body kept in a plane is against the plane's
/// normal by its translation and rotation locks) replaced by the identity's, and which ones
/// were: the friction there is zero and the other directions are solved as usual. Without it
/// such a K is singular and the contact got no friction at all.
fn without_dead_tangents(mut k: Mat3) -> (Mat3, [bool; 2]) {
    let trace = k.x_axis.x + k.y_axis.y + k.z_axis.z;
    let mut dead = [false; 2];
    for (i, d) in dead.iter_mut().enumerate() {
        let axis = i + 1;
        if k.col(axis)[axis] <= DEAD_DIRECTION * trace {
            *d = true;
            for j in 0..3 {
                k.col_mut(axis)[j] = 0.0;
                k.col_mut(j)[axis] = 0.0;
            }
            k.col_mut(axis)[axis] = 1.0;
        }
    }
    (k, dead)
}

/// A contact-space direction whose response is below this fraction of K's trace is taken as
/// one no impulse can move ([`without_dead_tangents`]).
const DEAD_DIRECTION: f32 = 1e-9;

/// The seed lecture's static/dynamic Coulomb test ("Friction as Impulses") for a single pick
/// with nothing accumulated: [`coulomb_accumulated`] with a zero accumulated impulse, returning
/// the impulse to apply. Kept as the lecture's formula (and Cyclone's, with its fixes).
/// The sliding direction is not known here, so dynamic friction takes g's planar direction,
/// as Cyclone does.
pub fn coulomb(g: Vec3, k: Mat3, desired: f32, mu: f32) -> Vec3 {
    coulomb_accumulated(Vec3::ZERO, g, k, desired, mu, Vec3::ZERO, 0.0).applied
}

/// Normal response K₀₀ (s/kg) below which a pick's contact matrix is solved scaled (bodies of
/// about 10¹² kg and more).
const SMALL_RESPONSE: f32 = 1e-12;

/// Impulse (N·s) beyond which products of impulses are formed scaled: squares of impulses
/// leave f32's range from about 1.8·10¹⁹ N·s.
const LARGE_IMPULSE: f32 = 1e18;

/// Below this sliding speed (m/s) the sliding direction is taken as undefined and dynamic
/// friction falls back to the planar direction of the stop-dead impulse.
pub const SLIDING_DIRECTION_MIN_SPEED: f32 = 1e-6;

/// The static/dynamic Coulomb test of the seed lecture ("Friction as Impulses"), applied to the
/// contact's **total impulse of this step**: `accumulated` (what earlier picks of this contact
/// applied) plus `g`, the impulse this pick would apply to stop the contact dead (solved with
/// `k` for the normal change `desired`). With g_t = accumulated + g:
/// - static: if |g_t,planar| ≤ μ·g_t,x, the total is inside the friction cone and `g` is
///   applied as solved;
/// - dynamic: otherwise the total tangential impulse is μ·g_t,x along d̂, the direction
///   opposite the contact's `sliding` velocity (contact space, y and z), or g_t,planar's
///   direction when the contact is not sliding (Cyclone always uses the latter): sliding
///   means faster, now and before this step's accelerations (`sliding_before`, m/s), than
///   friction could stop it (see the code), and the total normal X is re-solved so this pick
///   still changes the normal velocity by `desired` (Cyclone's re-solve, shifted by what is
///   already applied):
///   X = (desired + (K·accumulated)ₓ) / (K₀₀ + μ(K₀₁d̂_y + K₀₂d̂_z)), with the denominator
///   guarded by [`DYNAMIC_FRICTION_MIN_RESPONSE`];
/// - the total normal impulse is clamped to ≥ 0 (accumulated clamping: a later pick may
///   reduce an earlier push, never make the total pull); a zero normal leaves no friction.
///
/// Returns the pick's impulse g_t′ − accumulated, and whether the result is saturated
/// (dynamic, a zero total, or static within [`FRICTION_CAPACITY_TOLERANCE`] of the cone's
/// edge). A non-finite result applies nothing.
///
/// Why the total and not the pick alone (fix of the original): the lecture limits each pick's
/// tangential impulse by μ times *that pick's* normal impulse. Resolved one corner at a time,
/// a resting box's corners each get a small normal impulse per pick, so their friction could
/// never hold the box, and once the normal velocities were resolved nothing removed the
/// remaining sliding: a box resting on a 10° slope with μ = 0.5 crept by ≈ g·sinθ·dt per step
/// (0.136 m in 5 s at 60 Hz). The friction a contact may apply in a step is μ times the normal
/// impulse it applied in that step, which is what this test enforces. With a zero
/// `accumulated` it is exactly the lecture's single-pick test.
pub fn coulomb_accumulated(
    accumulated: Vec3,
    g: Vec3,
    k: Mat3,
    desired: f32,
    mu: f32,
    sliding: Vec3,
    sliding_before: f32,
) -> FrictionPick {
    let total = accumulated + g;
    if !total.is_finite() {
        return FrictionPick {
            applied: Vec3::ZERO,
            saturated: true,
        };
    }
    // (Through `hypot` for impulses whose squares leave f32's range: bodies of 10²¹ kg.)
    let planar = if total.y.abs().max(total.z.abs()) > LARGE_IMPULSE {
        total.y.hypot(total.z)
    } else {
        (total.y * total.y + total.z * total.z).sqrt()
    };
    let cone = mu * total.x;
    if planar <= cone {
        // Static (total.x ≥ 0 here): the solved impulse is applied as it is. Saturated when
        // it ends on the cone's edge (to round-off), where turning is all friction can still do.
        return FrictionPick {
            applied: g,
            saturated: !(cone - planar > FRICTION_CAPACITY_TOLERANCE * cone),
        };
    }
    let out = if planar > 0.0 {
        // Fix: dynamic friction opposes the sliding velocity, f = −v̂_planar·μ·|r| (the
        // lecture's own "Dynamic Friction" slide). Cyclone points it along the planar part of
        // the stop-dead impulse K⁻¹·Δv instead, which rotational coupling tilts away from the
        // sliding direction: about 31° at a cube's corner, so a sliding box felt only
        // cos 31° ≈ 0.86 of μ·N (a box on a 35° slope with μ = 0.3 slid 10% too fast).
        // Only a contact that is truly sliding has a direction to oppose: one sliding faster
        // than the planar velocity change (on the tangents' mean response) of μ times the
        // normal impulse it carries: what it has pushed this step plus what this pick's
        // normal change takes alone, desired / K₀₀ (negative where it gives some back); and
        // sliding so before this step's accelerations, Coulomb's rule (a contact at rest is
        // held by static friction). A resting corner that leaves the cone only through
        // rotational coupling keeps Cyclone's direction, the better approximation of the
        // static solution there. (The normal impulse was first the stop-dead total's, whose
        // normal part grows with the sliding speed through the coupling: a box sliding at
        // 9 m/s down a slope with μ = 0.9 then still took Cyclone's direction at its loaded
        // corners, their friction ±33° off the slide and 87% of μ·N along it. Without the
        // test before the accelerations, a box at rest on a slope of 0.9·μ began to slide.
        // Two other tests were tried: whether this pick's change alone would reverse the
        // sliding let contacts that were all but held turn their friction, and the 40-row
        // pyramid of the stability family fell; the normal impulse of the solution along the
        // sliding instead of the frictionless one let a perturbed column of 10 m boxes sway by
        // 0.8 m at a velocity epsilon of 10⁻⁶.)
        let k00 = k.x_axis.x;
        let speed = (sliding.y * sliding.y + sliding.z * sliding.z).sqrt();
        let carried = (accumulated.x + desired / k00).max(0.0);
        let capacity = 0.5 * (k.y_axis.y + k.z_axis.z) * mu * carried;
        let (dy, dz) = if speed.min(sliding_before) > capacity.max(SLIDING_DIRECTION_MIN_SPEED) {
            (-sliding.y / speed, -sliding.z / speed)
        } else {
            (total.y / planar, total.z / planar)
        };
        // Row 0 of K: how a tangential impulse changes the normal velocity.
        let coupling = k.y_axis.x * dy + k.z_axis.x * dz;
        let floor = DYNAMIC_FRICTION_MIN_RESPONSE * k00;
        let mu_eff = if k00 + mu * coupling < floor {
            // coupling < 0 here (k00 > floor); the largest μ' ≤ μ with denominator ≥ floor.
            ((k00 - floor) / -coupling).clamp(0.0, mu)
        } else {
            mu
        };
        // Normal velocity change the accumulated impulse already made; the pick applies
        // (X, μ′X·d̂) − accumulated, whose normal change must be `desired`.
        let already = k00 * accumulated.x + k.y_axis.x * accumulated.y + k.z_axis.x * accumulated.z;
        let gx = (desired + already) / (k00 + mu_eff * coupling);
        Vec3::new(gx, mu_eff * gx * dy, mu_eff * gx * dz)
    } else {
        // No sliding to kill and a pulling total normal: clamped to zero below.
        total
    };
    if !out.is_finite() {
        return FrictionPick {
            applied: Vec3::ZERO,
            saturated: true,
        };
    }
    // Fix: Cyclone never clamps, so a separating contact or a coupled solve could pull. The
    // clamp is on the step's total (accumulated clamping).
    let out = if out.x > 0.0 { out } else { Vec3::ZERO };
    FrictionPick {
        applied: out - accumulated,
        saturated: true,
    }
}

/// Relative tolerance of the friction-capacity test: a static result whose total tangential
/// impulse is within this fraction of μ × its total normal impulse counts as saturated
/// ([`coulomb_accumulated`]), so round-off on the cone's edge never makes a contact worth
/// picking again.
pub const FRICTION_CAPACITY_TOLERANCE: f32 = 1e-4;

/// Whether a pick of `p` could still remove sliding velocity with friction in this step:
/// μ > 0, the contact is not [saturated](PreparedContact::friction_saturated), and it has a
/// normal impulse to carry friction, accumulated (acc_x > 0) or about to be applied (Δv > 0).
/// The flag encodes the cone test: a pick leaves it set when μ·acc_x − |acc_planar| ≤
/// [`FRICTION_CAPACITY_TOLERANCE`] · μ·acc_x (dynamic friction, or static on the edge), and
/// [`reopen_friction`] clears it when the neighbours' picks have turned the sliding since.
/// μ = 0 contacts never have capacity (no friction work at all).
pub fn has_friction_capacity(p: &PreparedContact) -> bool {
    p.friction > 0.0
        && !p.friction_saturated
        && (p.impulse.x > 0.0 || p.desired_delta_velocity > 0.0)
}

/// The velocity pass's pick key of `p` (m/s): how much velocity a pick would remove.
/// max(desired normal change, planar closing speed) when `p` [has friction
/// capacity](has_friction_capacity), else the desired normal change (the lecture's key);
/// −∞ when the contact cannot be resolved (zero normal inertia), NaN stays NaN (never picked).
///
/// Why the sliding term (fix of the original): the lecture picks by normal velocity change
/// alone, so once every corner of a resting box had its normal velocity resolved (below
/// `velocity_epsilon`), the remaining sliding velocity, including the planar
/// last_acceleration·dt compensation of the micro-collision rule, was never removed and boxes
/// crept down slopes (≈ g·sinθ·dt per step) and drifted on flat ground. A contact is picked for
/// its sliding only while its friction can still act; a pick then either stops the sliding
/// (static) or saturates the contact (dynamic), so the key drops below the epsilon and the
/// pass ends by itself, not by its budget.
#[inline]
pub fn velocity_key(p: &PreparedContact) -> f32 {
    if !(p.normal_inertia > 0.0) {
        return f32::NEG_INFINITY;
    }
    let normal = normal_key(p);
    if has_friction_capacity(p) {
        let sliding = (p.velocity.y * p.velocity.y + p.velocity.z * p.velocity.z).sqrt();
        if sliding > normal {
            return sliding;
        }
    }
    normal
}

/// The normal part of [`velocity_key`] (m/s): the desired normal change when it is a push; past
/// the target (Δv < 0), the part of the overshoot the contact can take back by giving up the
/// impulse it pushed this step (at most impulse × normal inertia), so a contact that was
/// pushed past its target by its own earlier pick and its neighbours' is picked again
/// (Gauss-Seidel with accumulated clamping) instead of keeping a bounce higher than its target.
#[inline]
pub fn normal_key(p: &PreparedContact) -> f32 {
    let desired = p.desired_delta_velocity;
    if desired >= 0.0 || desired.is_nan() {
        desired
    } else {
        (-desired).min(p.impulse.x.max(0.0) * p.normal_inertia)
    }
}

/// The impulse the velocity pass applies at `p` (contact space, on A): frictionless when
/// μ ≤ 0 (no friction work at all: skip what a scene does not need), else
/// [`friction_impulse`] (against the impulse `p` accumulated so far this step).
pub fn contact_impulse(p: &PreparedContact, bodies: &[SolverBody]) -> Vec3 {
    if p.friction > 0.0 {
        friction_impulse(p, bodies)
    } else {
        frictionless_impulse(p)
    }
}

/// Applies the contact-space impulse `g` (on A; −g on B) to both bodies (lecture, "Applying the
/// Impulse"): Δv = g/m, Δω = I⁻¹(r × g), angular work skipped for bodies that do not rotate.
/// Returns what changed, for the neighbours' updates.
pub fn apply_impulse(p: &PreparedContact, g: Vec3, bodies: &mut [SolverBody]) -> BodyChange {
    let world = p.basis * g;
    let mut change = BodyChange {
        body: p.body,
        ..BodyChange::NONE
    };
    for side in 0..2 {
        let Some(b) = p.side_body_mut(bodies, side) else {
            change.body[side] = NO_BODY;
            continue;
        };
        let j = if side == 0 { world } else { -world };
        let dv = j * b.inv_mass_axes();
        b.linear_velocity += dv;
        change.linear[side] = dv;
        if b.rotates() {
            let dw = b.inv_inertia * p.r[side].cross(j);
            b.angular_velocity += dw;
            change.angular[side] = dw;
        }
    }
    change
}

/// Resolves the velocity of `p`: computes [`contact_impulse`] (with friction,
/// [`friction_pick`] against the impulse accumulated this step, recording whether the contact's
/// friction is saturated), adds it to `p.impulse` and applies it. `p`'s own closing velocity is
/// **not** updated here; the pass updates it like any other contact that shares a body
/// ([`update_velocity`]), as Cyclone does.
pub fn resolve_velocity(p: &mut PreparedContact, bodies: &mut [SolverBody]) -> BodyChange {
    let g = if p.friction > 0.0 {
        let pick = friction_pick(p, bodies);
        p.friction_saturated = pick.saturated;
        pick.applied
    } else {
        frictionless_impulse(p)
    };
    p.impulse += g;
    apply_impulse(p, g, bodies)
}

/// Updates the closing velocity and desired velocity change of `p` after `change` was applied
/// to bodies it may share: Δv_contact = ±Mᵀ(Δv + Δω × r), + for side A, − for side B. The
/// desired change is what is left to the contact's target ([`PreparedContact::target_velocity`]);
/// a change made by a contact between other bodies decides the target again, by the
/// micro-collision rule from the new velocity, where the rule wants a push or the contact was
/// bouncing (a target above 0); a resting contact driven apart keeps its target.
/// Returns whether `p` shared a body with the change.
pub fn update_velocity(p: &mut PreparedContact, change: &BodyChange, velocity_limit: f32) -> bool {
    update_velocity_for(p, change, change.body, velocity_limit)
}

/// [`update_velocity`] after a pick of the contact between the bodies `pair` (its sides as
/// the contact has them): a pick with one side held still
/// ([`PreparedContact::with_side_held`]) changes only the other body, but it is still a pick
/// of that pair for the pair's other points.
pub fn update_velocity_for(
    p: &mut PreparedContact,
    change: &BodyChange,
    pair: [u32; 2],
    velocity_limit: f32,
) -> bool {
    let mut touched = false;
    if let Some(d) = change.point_change(p.body[0], p.r[0]) {
        p.velocity += p.basis.transpose() * d;
        touched = true;
    }
    if let Some(d) = change.point_change(p.body[1], p.r[1]) {
        p.velocity -= p.basis.transpose() * d;
        touched = true;
    }
    if touched {
        let same_pair = pair == p.body || pair == [p.body[1], p.body[0]];
        if !same_pair && !p.held {
            // A new collision, or nothing to do: the micro-collision rule decides the target
            // again when it wants a push. Driven apart instead, a bouncing contact keeps what
            // the other pair's pick left (its impact was passed on: Newton's cradle), and a
            // resting one keeps its target, so that it may take back what it pushed: kept at
            // the separation instead, it could not, and a pick that had pushed a box up was
            // never undone (a pyramid with a heavy top stepped at `dt` 1.0 rose 0.2 m and
            // gained 329 kJ in its first step; benches/RESULTS.md, "Resting contacts driven
            // apart take back their push").
            let desired = desired_delta_velocity(
                p.velocity.x,
                p.acc_velocity,
                p.impact_speed_gain,
                p.restitution,
                velocity_limit,
                p.gap_velocity,
            );
            if desired > 0.0 || p.target_velocity > 0.0 {
                p.target_velocity = p.velocity.x + desired.max(0.0);
            }
        }
        p.desired_delta_velocity = p.target_velocity - p.velocity.x;
    }
    touched
}

/// Keeps [`PreparedContact::friction_saturated`] honest after the pass updated `p`
/// ([`update_velocity`]) for a pick that shared a body with it. For the contact just picked
/// (`picked`), records the sliding velocity its saturating pick left. For any other saturated
/// contact, clears the flag once the picks of its neighbours have changed its sliding velocity
/// by more than `velocity_epsilon` since it saturated: its friction (at the edge of its cone,
/// but pointing where the sliding was) can then act again, by turning, and the contact is worth
/// a pick for its sliding ([`velocity_key`]).
///
/// Why (part of the creep fix): corner-by-corner, a corner saturates early while its normal
/// impulse is small, and the picks of the other corners then turn the box's sliding into a spin
/// about the one corner that holds; without re-opening, a resting box on a 10° slope still
/// crept ≈ 0.05 m in 5 s. Re-opening needs a change larger than the epsilon, so as the pass
/// converges the changes stop re-opening contacts and the pass ends by itself.
pub fn reopen_friction(p: &mut PreparedContact, picked: bool, velocity_epsilon: f32) {
    if !p.friction_saturated {
        return;
    }
    let sliding = Vec3::new(0.0, p.velocity.y, p.velocity.z);
    if picked {
        p.saturated_sliding = sliding;
    } else if (sliding - p.saturated_sliding).length() > velocity_epsilon {
        p.friction_saturated = false;
    }
}

/// How far inside every point's cone (a fraction of μ·its normal impulse) the shared pattern of
/// [`share_manifold_friction`] must lie to be used: on the cone's edge it would hold nothing
/// that the corners' own friction does not.
const SHARED_FRICTION_MARGIN: f32 = 1e-3;

/// How many times a step a manifold's friction may be shared.
const SHARES_PER_STEP: u8 = 4;

/// The largest spread of a manifold's points along its normal, as a fraction of their spread
/// across it, for which [`share_manifold_friction`] treats them as lying in one plane (where
/// moving friction between them changes neither body's motion).
const SHARED_FRICTION_FLATNESS: f32 = 1e-2;

/// Shares the friction the points of one manifold (`contacts`: the same two bodies, the same
/// normal) accumulated this step between them in proportion to their normal impulses, and adds
/// the friction, shared the same way, that stops the manifold's centre of load from sliding.
///
/// The bodies' motion depends on the friction of points in one plane across the normal only
/// through its total T and its twist τ about the normal. Shared by load, with the same T and τ,
/// the points carry tᵢ = (Nᵢ/ΣN)·T + s·Nᵢ·(n × dᵢ), Nᵢ the point's normal impulse, dᵢ its
/// offset across the normal from the centre of load c = ΣNᵢ·rᵢ/ΣN, s = τ / ΣNᵢ|dᵢ|². Then the
/// tangential impulse P at c that stops c's relative sliding (its 2 × 2 effective mass on the
/// tangent plane) is added to T, as much of it as keeps every point inside its friction cone
/// (by [`SHARED_FRICTION_MARGIN`]): all of it where the manifold can hold; else the largest
/// part that fits, and the points are marked saturated. (Where it holds, each point's flag is
/// left as it was, to be reopened as any saturated point is when its neighbours' picks change
/// its sliding, [`reopen_friction`]: reopened at every share, the settled 20-row pyramid of
/// 10 m boxes kept its passes at their budget, 37 ms a step against 2.5.)
/// Nothing is done (`None`) where the centre of load slides slower than `velocity_epsilon`
/// (the pass's), where the points do not lie in one plane
/// ([`SHARED_FRICTION_FLATNESS`]), where they carry no normal impulse, or where even the shared
/// pattern alone leaves some point's cone; and at most [`SHARES_PER_STEP`] times a step per
/// manifold ([`PreparedContact::friction_shared`]). Returns the impulses' change on the bodies.
///
/// Why (issue 17 item 5, "one pushed below μs·m·g stays put"): a corner's stop-dead pick solves
/// its own 3 × 3 system, whose rotational coupling tilts its friction toward or away from the
/// face's centre; the corners' tilts cancel on the body but fill their cones. A unit box pushed
/// at 0.95·μs·m·g on flat ground ended its first step with every corner on its cone and only
/// 0.86 of μ·N acting along the push (the pairs of corners pushing ±14.8 N·s against each other
/// across it), and it slid (0.62 m in 2 s at μs 0.5, μd 0.45, any size). The static solution
/// exists (friction in proportion to the load, 0.95 of each corner's cone); the corners' picks
/// never reach it, because a pick moves only its own corner's impulse, and each pick tilts it
/// again (shared without stopping the centre, and reopened after every saturating pick, the
/// picks re-tilted what was shared: the 3D pyramid of 20 spent 1.3 million picks a step, its
/// whole budget, against 70 thousand).
pub fn share_manifold_friction(
    contacts: &mut [PreparedContact],
    bodies: &mut [SolverBody],
    velocity_epsilon: f32,
) -> Option<BodyChange> {
    let first = contacts.first()?;
    if contacts.len() < 2 {
        return None;
    }
    let pair = first.body;
    let n = first.basis.x_axis;
    let (t1, t2) = (first.basis.y_axis, first.basis.z_axis);
    let mut total_n = 0.0;
    let mut centre = [Vec3::ZERO; 2];
    let mut tangential = Vec3::ZERO;
    for p in contacts.iter() {
        if p.friction_shared >= SHARES_PER_STEP
            || p.body != pair
            || !(p.friction > 0.0)
            || p.basis.x_axis.dot(n) < 0.9999
        {
            return None;
        }
        let load = p.impulse.x.max(0.0);
        total_n += load;
        centre[0] += p.r[0] * load;
        centre[1] += p.r[1] * load;
        tangential += p.basis * Vec3::new(0.0, p.impulse.y, p.impulse.z);
    }
    if !(total_n > 0.0) {
        return None;
    }
    let centre = centre.map(|c| c / total_n);
    // The side whose lever arms locate the points (both give the same offsets).
    let side = if pair[0] != NO_BODY { 0 } else { 1 };
    let tangential = tangential - n * tangential.dot(n);
    let offset = |p: &PreparedContact| {
        let d = p.r[side] - centre[side];
        d - n * d.dot(n)
    };
    // The twist about the centre of load, and how flat the points lie.
    let (mut twist, mut spread, mut depth, mut across) = (0.0, 0.0, 0.0f32, 0.0f32);
    for p in contacts.iter() {
        depth = depth.max((p.r[side] - centre[side]).dot(n).abs());
        let d = offset(p);
        across = across.max(d.length());
        twist += d
            .cross(p.basis * Vec3::new(0.0, p.impulse.y, p.impulse.z))
            .dot(n);
        spread += p.impulse.x.max(0.0) * d.length_squared();
    }
    if !(depth <= SHARED_FRICTION_FLATNESS * across) || !(spread > 0.0) {
        return None;
    }
    let s = twist / spread;
    // What stops the centre of load sliding: K·P = −v on the tangent plane, K the centre's
    // response to an impulse on A (−P on B). (The arithmetic of `impulse_matrix` at the
    // centre, in world axes: calling it instead changes the results by rounding, which moved
    // the chaotic drift of the Millington resolver's 20-row pyramid from 2.2 to 8.1 mm.)
    let mut v = Vec3::ZERO;
    let mut k = Mat3::ZERO;
    for (side, (r, sign)) in centre.into_iter().zip([1.0f32, -1.0]).enumerate() {
        let Some(b) = first.side_body(bodies, side) else {
            continue;
        };
        v += sign * (b.linear_velocity + b.angular_velocity.cross(r));
        k += Mat3::from_diagonal(b.inv_mass_axes());
        if b.rotates() {
            k -= skew(r) * b.inv_inertia * skew(r);
        }
    }
    let (k11, k12, k22) = (t1.dot(k * t1), t1.dot(k * t2), t2.dot(k * t2));
    // K's entries are inverse masses: scaled to unit trace where their products would leave
    // f32's normal range (as in `friction_pick`), the solution scaled back.
    let unit = if k11 + k22 < SMALL_RESPONSE && k11 + k22 > 0.0 {
        1.0 / (k11 + k22)
    } else {
        1.0
    };
    let (k11, k12, k22) = (k11 * unit, k12 * unit, k22 * unit);
    let det = k11 * k22 - k12 * k12;
    let (v1, v2) = (t1.dot(v), t2.dot(v));
    if v1.hypot(v2) < velocity_epsilon {
        // Nothing to stop: the points' own picks are left what remains.
        return None;
    }
    let stop = if det > 1e-6 * (k11 * k22).max(f32::MIN_POSITIVE) {
        let p1 = -(k22 * v1 - k12 * v2) / det * unit;
        let p2 = -(k11 * v2 - k12 * v1) / det * unit;
        t1 * p1 + t2 * p2
    } else {
        Vec3::ZERO
    };
    // Each point's shared friction is aᵢ + α·bᵢ; the largest α ≤ 1 that keeps every point
    // inside its cone (α = 0 must: else nothing is done).
    // (In units of the total load where the fourth powers below would leave f32's range.)
    let per_load = if total_n > LARGE_IMPULSE.sqrt() {
        1.0 / total_n
    } else {
        1.0
    };
    let mut alpha = 1.0f32;
    for p in contacts.iter() {
        let load = p.impulse.x.max(0.0);
        let limit = (1.0 - SHARED_FRICTION_MARGIN) * p.friction * load * per_load;
        let a = (tangential * (load / total_n) + n.cross(offset(p)) * (s * load)) * per_load;
        let b = stop * (load / total_n) * per_load;
        let (aa, ab, bb) = (a.length_squared(), a.dot(b), b.length_squared());
        if !(aa < limit * limit) {
            return None;
        }
        if bb > 0.0 {
            // |a + α·b|² = limit² at the positive root.
            let root = (ab * ab - bb * (aa - limit * limit)).max(0.0).sqrt();
            alpha = alpha.min((root - ab) / bb);
        }
    }
    let alpha = alpha.clamp(0.0, 1.0);
    let holds = alpha >= 1.0;
    let total = tangential + stop * alpha;
    let shared = |p: &PreparedContact| {
        let load = p.impulse.x.max(0.0);
        p.basis.transpose() * (total * (load / total_n) + n.cross(offset(p)) * (s * load))
    };
    if !contacts.iter().all(|p| shared(p).is_finite()) {
        return None;
    }
    let mut change = BodyChange {
        body: pair,
        ..BodyChange::NONE
    };
    for p in contacts.iter_mut() {
        let local = shared(p);
        let delta = Vec3::new(0.0, local.y - p.impulse.y, local.z - p.impulse.z);
        p.impulse.y = local.y;
        p.impulse.z = local.z;
        p.friction_saturated |= !holds;
        p.friction_shared += 1;
        change.add(&apply_impulse(p, delta, bodies));
    }
    Some(change)
}

/// Most points of a manifold [`resolve_manifold_normals`] solves together.
pub const MANIFOLD_POINTS: usize = 4;

/// A pivot of [`resolve_manifold_normals`]'s elimination below this fraction of K's largest
/// diagonal entry marks its point's row as dependent on the rows before (a face's four
/// normal rows span three motions: one push, two tilts), and that point takes no impulse:
/// the others give the manifold's bodies the same motion. Regularising K instead (K + ε·diag
/// K) left ε/(1 + ε) of every change unresolved, and a pick that took back a loaded point's
/// push then threw a light box under a 1,000 times heavier one out at 4.5 m/s.
const DEPENDENT_PIVOT: f32 = 1e-3;

/// The change of contact `i`'s closing velocity along its normal per unit normal impulse at
/// contact `j` of the same two bodies (an entry of the manifold's K = J·M⁻¹·Jᵀ).
fn normal_response(pi: &PreparedContact, pj: &PreparedContact, bodies: &[SolverBody]) -> f32 {
    let nj = pj.basis.x_axis;
    let ni = pi.basis.x_axis;
    let mut k = 0.0;
    for side in 0..2 {
        let Some(b) = pj.side_body(bodies, side) else {
            continue;
        };
        // A unit push on A along n_j (−n_j on B) and its effect at i's lever arm on that
        // side, counted with the sign of that side in i's closing velocity: the two signs
        // cancel, so both sides add.
        let mut du = nj * b.inv_mass_axes();
        if b.rotates() {
            du += (b.inv_inertia * pj.r[side].cross(nj)).cross(pi.r[side]);
        }
        k += ni.dot(du);
    }
    k
}

/// Resolves the normal velocities of the points `contacts` of one manifold (the same two
/// bodies in the same order, at most [`MANIFOLD_POINTS`]) together, for a pick of the point
/// `picked`: the normal impulses x with K·x = Δv (K = J·M⁻¹·Jᵀ over the points that want a
/// push or hold one, Δv their desired changes), of those solutions the one that shares the
/// load most evenly (`solve_small`), each point's total of the step kept ≥ 0: a point whose
/// total would pull gives back what it pushed and the others are solved again without it.
/// Applies them and returns what changed on the two bodies. `None`, changing nothing, when
/// fewer than two points take part, when the picked point would pull or its change is one the
/// block cannot make (the points' targets are not those of one rigid motion): the caller then
/// picks the point alone.
#[allow(clippy::needless_range_loop)]
pub fn resolve_manifold_normals(
    contacts: &mut [PreparedContact],
    picked: usize,
    bodies: &mut [SolverBody],
) -> Option<BodyChange> {
    let n = contacts.len().min(MANIFOLD_POINTS);
    if picked >= n {
        return None;
    }
    let mut live = [false; MANIFOLD_POINTS];
    for (i, p) in contacts.iter().take(n).enumerate() {
        live[i] = p.normal_inertia > 0.0
            && p.desired_delta_velocity.is_finite()
            && (p.desired_delta_velocity > 0.0 || p.impulse.x > 0.0);
    }
    if live.iter().filter(|&&l| l).count() < 2 {
        return None;
    }
    let mut k = [[0.0f32; MANIFOLD_POINTS]; MANIFOLD_POINTS];
    for i in 0..n {
        for j in 0..n {
            if live[i] && live[j] {
                k[i][j] = normal_response(&contacts[i], &contacts[j], bodies);
            }
        }
    }
    // `fixed[i]`: point i's total is held at zero (x_i = −impulse_i).
    let mut fixed = [false; MANIFOLD_POINTS];
    let mut x = [0.0f32; MANIFOLD_POINTS];
    for _ in 0..=n {
        // Right-hand side of the free points, less what the fixed ones take back.
        let mut free = [0usize; MANIFOLD_POINTS];
        let mut m = 0;
        for i in (0..n).filter(|&i| live[i] && !fixed[i]) {
            free[m] = i;
            m += 1;
        }
        let free = &free[..m];
        for i in 0..n {
            x[i] = if live[i] && fixed[i] {
                -contacts[i].impulse.x
            } else {
                0.0
            };
        }
        let mut a = [[0.0f32; MANIFOLD_POINTS]; MANIFOLD_POINTS];
        let mut rhs = [0.0f32; MANIFOLD_POINTS];
        for (r, &i) in free.iter().enumerate() {
            rhs[r] = contacts[i].desired_delta_velocity;
            for j in 0..n {
                if live[j] && fixed[j] {
                    rhs[r] -= k[i][j] * x[j];
                }
            }
            for (c, &j) in free.iter().enumerate() {
                a[r][c] = k[i][j];
            }
        }
        let mut held = [0.0f32; MANIFOLD_POINTS];
        for (r, &i) in free.iter().enumerate() {
            held[r] = contacts[i].impulse.x;
        }
        let sol = solve_small(&mut a, &mut rhs, m, &held)?;
        for (r, &i) in free.iter().enumerate() {
            x[i] = sol[r];
        }
        let mut pulled = false;
        for &i in free {
            if contacts[i].impulse.x + x[i] < 0.0 {
                fixed[i] = true;
                pulled = true;
            }
        }
        if !pulled {
            break;
        }
    }
    if !x.iter().all(|v| v.is_finite()) || fixed[picked] || !live[picked] {
        return None;
    }
    for i in 0..n {
        if live[i] {
            x[i] = x[i].max(-contacts[i].impulse.x);
        }
    }
    // What the block leaves of the picked point's change: where its row depends on the
    // others and its target does not (the points' targets are not those of one rigid
    // motion), the block cannot resolve it, and picked again it would do the same: the
    // point is then picked alone.
    let desired = contacts[picked].desired_delta_velocity;
    let left = desired
        - (0..n)
            .filter(|&j| live[j])
            .map(|j| k[picked][j] * x[j])
            .sum::<f32>();
    if !(left.abs() <= 0.5 * desired.abs()) {
        return None;
    }
    let mut change: Option<BodyChange> = None;
    for i in 0..n {
        if !live[i] {
            continue;
        }
        let g = Vec3::new(x[i], 0.0, 0.0);
        contacts[i].impulse += g;
        let c = apply_impulse(&contacts[i], g, bodies);
        change = Some(match change {
            None => c,
            Some(mut sum) => {
                sum.add(&c);
                sum
            }
        });
    }
    change
}

/// Solves the leading `m` × `m` system of `a` (symmetric positive semidefinite) by Gaussian
/// elimination with partial pivoting, a variable whose pivot is below [`DEPENDENT_PIVOT`] of
/// the largest diagonal entry taken as free (its row dependent on the others); `None` when no
/// pivot is usable. Of the solutions, the one whose totals `held + x` are the most even: along
/// each direction the free variables leave open (a face's four points pushing opposite corners
/// in turn, which moves nothing), x is shifted so that the totals have no component, so a
/// resting face's load is shared by its points as evenly as the motion allows, and each point
/// keeps the normal impulse its friction is bounded by (with the free variable at zero, one
/// corner of a box on a 24° slope carried none, and the box crept 6 mm in 5 s).
// Index loops: the elimination reads the matrix by row and column, as the formulas do.
#[allow(clippy::needless_range_loop)]
fn solve_small(
    a: &mut [[f32; MANIFOLD_POINTS]; MANIFOLD_POINTS],
    b: &mut [f32; MANIFOLD_POINTS],
    m: usize,
    held: &[f32; MANIFOLD_POINTS],
) -> Option<[f32; MANIFOLD_POINTS]> {
    let scale = (0..m).map(|i| a[i][i].abs()).fold(0.0f32, f32::max);
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    // (pivot row, column) of each usable pivot, in elimination order.
    let mut pivots = [(0usize, 0usize); MANIFOLD_POINTS];
    let mut used = 0;
    let mut dependent = [false; MANIFOLD_POINTS];
    for col in 0..m {
        let row = used;
        let Some(pivot) = (row..m).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
        else {
            break;
        };
        if !(a[pivot][col].abs() > DEPENDENT_PIVOT * scale) {
            dependent[col] = true;
            continue;
        }
        a.swap(row, pivot);
        b.swap(row, pivot);
        for r in row + 1..m {
            let f = a[r][col] / a[row][col];
            for c in col..m {
                a[r][c] -= f * a[row][c];
            }
            b[r] -= f * b[row];
        }
        pivots[used] = (row, col);
        used += 1;
    }
    if used == 0 {
        return None;
    }
    // Back substitution: the particular solution (free variables 0), and for each free
    // variable the direction it leaves open (itself 1, the other free ones 0).
    let back = |rhs: &[f32; MANIFOLD_POINTS], x: &mut [f32; MANIFOLD_POINTS]| {
        for &(row, col) in pivots[..used].iter().rev() {
            let mut s = rhs[row];
            for c in col + 1..m {
                s -= a[row][c] * x[c];
            }
            x[col] = s / a[row][col];
        }
    };
    let mut x = [0.0f32; MANIFOLD_POINTS];
    back(b, &mut x);
    for free in (0..m).filter(|&c| dependent[c]) {
        let mut z = [0.0f32; MANIFOLD_POINTS];
        z[free] = 1.0;
        back(&[0.0; MANIFOLD_POINTS], &mut z);
        let zz: f32 = z[..m].iter().map(|v| v * v).sum();
        let along: f32 = (0..m).map(|i| (held[i] + x[i]) * z[i]).sum();
        if zz > 0.0 && zz.is_finite() {
            for i in 0..m {
                x[i] -= along / zz * z[i];
            }
        }
    }
    Some(x)
}
