//! Continuous collision detection: the earliest time a moving collider touches resting or
//! slow geometry during a step.
//!
//! In: a collider, its body's pose at the start of the step (where contacts were detected) and
//! at its end (where the resolver integrated it), the colliders and bodies, and the broad phase
//! whose boxes locate resting (fixed or sleeping) colliders and slow awake ones (which the
//! caller names: a bullet is swept into a stack of awake boxes at their start poses). Out: the fraction of the step at
//! which the collider would first come within [`CcdSettings::slop`] of one of them.
//!
//! The seed lecture's velocity-based resolution ("move them back to the point of first
//! collision"): the facade moves the body back to that fraction of its motion and keeps its
//! velocity, so the next step's narrow phase finds a speculative contact and the resolver
//! resolves the impact. The rest of the step's motion of that one body is dropped (Box2D v3
//! does the same); nothing is lost that a contact would not have removed anyway. A body
//! stopped on the same collider two steps running (its resolver could not stop it: a needle
//! whose far end swings through a thin floor) has its velocity resolved against the hit at
//! the time of impact as well ([`CcdHit::contact`], [`stop_contact`]), so it is not rewound
//! again for the same approach.
//!
//! How: a linear shape cast ([`cast_shapes`]) of the start pose along the step's translation,
//! stopping `slop` short; a nonlinear cast ([`cast_shapes_nonlinear`]: the start pose turning
//! about the centre of mass at the step's rotation vector) when the rotation alone could carry a
//! point further than the linear test tolerates (for pairs parry cannot cast nonlinearly, such as
//! half-spaces, conservative advancement on parry's distance query). Every stop is within
//! `slop` of the surface, never a conservative bound short of it: a body stopped where the next
//! narrow phase finds no contact would keep its velocity, be stopped again, and hang in the air.
//! A body already within `slop` of a surface at
//! the start and still approaching (a cast hit at time 0) is not stopped outright, which would
//! freeze a fast body sliding along a floor: instead a small core sphere at its centre of mass
//! is cast, and only a core that would reach the surface (the body crossing it) stops the body.
//! The same core cast runs when the cast of the whole shape finds nothing: the centre of mass
//! crossing a surface is a crossing whatever parry's nonlinear cast concluded for a body
//! turning tens of radians within the step.
//! Two fast bodies are not swept against each other: their narrow phase and resolver handle
//! them.

use crate::broad_phase::BroadPhase;
use crate::collider::{Collider, ColliderHandle, ColliderSet};
use crate::material::Material;
use crate::settings::CcdSettings;
use jostle_body::BodySet;
use jostle_math::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::Ray;
use parry3d::query::{
    NonlinearRigidMotion, ShapeCastHit, ShapeCastOptions, ShapeCastStatus, Unsupported,
    cast_shapes, cast_shapes_nonlinear, contact, distance,
};
use parry3d::shape::Ball;

/// What CCD needs to know of a collider's shape, computed once when the collider is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CcdShape {
    /// Smallest dimension (m): twice the smallest half extent of the shape's local box. A body
    /// moving less than a fraction of this per step cannot cross a wall between detections.
    /// Infinite for unbounded shapes.
    pub thickness: f32,
    /// Largest distance (m) from the body's centre of mass to a point of the shape: how far a
    /// rotation of θ rad moves a point, at most, is θ·extent. Zero for a ball centred on the
    /// centre of mass, whose surface a rotation does not move.
    pub extent: f32,
}

impl CcdShape {
    /// The thickness and extent of `collider`'s shape, relative to its body's centre of mass.
    pub fn of(collider: &Collider) -> Self {
        if collider.is_unbounded() {
            return Self {
                thickness: f32::INFINITY,
                extent: f32::INFINITY,
            };
        }
        let half = collider.shape.compute_local_aabb().half_extents();
        let sphere = collider.shape.compute_local_bounding_sphere();
        let centre = collider.local_pose * sphere.center();
        // A ball turning about its own centre moves no point of its surface.
        let centred_ball =
            collider.shape.as_ball().is_some() && centre.length() <= 1e-6 * sphere.radius();
        Self {
            thickness: 2.0 * half.min_element(),
            extent: if centred_ball {
                0.0
            } else {
                centre.length() + sphere.radius()
            },
        }
    }

    /// How far a point of the shape moves at most (m) for a translation of `distance` metres
    /// and a rotation of `angle` rad about the centre of mass.
    pub fn motion(&self, distance: f32, angle: f32) -> f32 {
        distance + angle * self.extent
    }
}

/// The first resting collider a sweep touches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CcdHit {
    /// Fraction of the motion (0 = start pose, 1 = end pose) at which to stop the body: the
    /// time of impact, `slop` short.
    pub fraction: f32,
    /// The resting collider hit.
    pub collider: ColliderHandle,
    /// The body's centre-of-mass pose at `fraction` of the swept motion (the translation
    /// interpolated, the turn at a constant rate, whole turns included: see `spin` of
    /// [`sweep`]).
    pub stop: Pose,
    /// The body's pose at the time of impact itself (the same as `stop` unless the stop was
    /// backed off from a turning cast's touching pose): where [`stop_contact`] finds the
    /// point that hits.
    pub impact: Pose,
    /// Where the cast touched at `impact`, when the cast says (not for a body that started
    /// within `slop` of the surface): the point that hits, which need not be the point
    /// nearest the surface at the stop.
    pub contact: Option<CcdContact>,
    /// Whether the stop is the centre of mass reaching the surface (the cast of a core at
    /// the centre), not the shape touching it: the body is then half into what it hit, and
    /// `contact` is at its centre.
    pub core: bool,
}

/// The contact between a collider stopped by CCD and the collider it hit, at the stop pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CcdContact {
    /// Point on the stopped collider's surface, world frame (m).
    pub point: Vec3,
    /// Unit normal from the hit collider toward the stopped one, world frame.
    pub normal: Vec3,
    /// The pair's material ([`Material::mix`]).
    pub material: Material,
}

/// The contact of `collider`, its body at the centre-of-mass pose `body_pose`, with `target`
/// (a resting collider, at its body's pose in `bodies`), if they are within `reach` (m) of each
/// other; `None` when farther apart or when parry has no contact query for the pair. CCD uses
/// it to resolve the velocity of a body it stopped against what it hit.
pub fn stop_contact(
    collider: &Collider,
    body_pose: Pose,
    target: &Collider,
    bodies: &BodySet,
    reach: f32,
) -> Option<CcdContact> {
    let target_body = bodies.get(target.body)?;
    let from = body_pose * collider.local_pose;
    let to = target.world_pose(target_body);
    let c = contact(
        &from,
        collider.shape.as_ref(),
        &to,
        target.shape.as_ref(),
        reach,
    )
    .ok()
    .flatten()?;
    let normal = -c.normal1;
    (normal.is_finite() && c.point1.is_finite()).then_some(CcdContact {
        point: c.point1,
        normal,
        material: Material::mix(collider.material, target.material),
    })
}

/// Sweeps `collider` from its body's pose `start` to `end` (centre-of-mass poses) against the
/// resting colliders near the motion (through `broad`'s boxes), and the awake ones for which
/// `slow` holds (bodies that move too little in the step to matter: they are taken at their
/// pose at the start of the step), and returns the earliest hit, ties broken by the lower
/// collider handle. `candidates` is scratch space, cleared here.
///
/// `None` when nothing is touched, or when the body only grazes what it already touched at the
/// start (see the module docs). Shape pairs parry cannot cast are skipped.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    collider: &Collider,
    shape: &CcdShape,
    start: Pose,
    end: Pose,
    spin: Vec3,
    slow: impl Fn(ColliderHandle) -> bool,
    colliders: &ColliderSet,
    bodies: &BodySet,
    broad: &BroadPhase,
    settings: &CcdSettings,
    candidates: &mut Vec<ColliderHandle>,
) -> Option<CcdHit> {
    let delta = end.translation - start.translation;
    let rotation = unwrapped_turn(end.rotation * start.rotation.inverse(), spin);
    let angle = rotation.length();
    let from = start * collider.local_pose;
    // The linear cast ignores the rotation, so its time of impact is off by as much as the
    // rotation moves a point: enough only while that is within half the slop. Judged against
    // the motion a body may make without CCD instead (a quarter of its thickness), a spinning
    // box was stopped where its translation alone would touch, short of where the turning
    // body gets, stopped again every step, and hung in the air while gravity filled its
    // velocity (benches/RESULTS.md, "Restitution 1 never raises a bounce").
    let turning = angle * shape.extent > 0.5 * settings.slop;
    let swept = if turning {
        let reach = Vec3::splat(shape.extent);
        let a = Aabb::new(start.translation - reach, start.translation + reach);
        a.merged(&a.translated(delta))
    } else {
        let a = collider.shape.compute_aabb(&from);
        a.merged(&a.translated(delta))
    }
    .loosened(settings.slop);

    candidates.clear();
    broad.resting_near(&swept, candidates);
    let resting = candidates.len();
    broad.awake_near(&swept, candidates);
    let mut k = resting;
    for i in resting..candidates.len() {
        if slow(candidates[i]) {
            candidates[k] = candidates[i];
            k += 1;
        }
    }
    candidates.truncate(k);
    let mut best: Option<CcdHit> = None;
    for &handle in candidates.iter() {
        let Some(target) = colliders.get(handle) else {
            continue;
        };
        let Some(target_body) = bodies.get(target.body) else {
            continue;
        };
        if target.body == collider.body || !collider.touches(target) {
            continue;
        }
        let to = target.world_pose(target_body);
        let mut impact_time = None;
        let mut touch = None;
        let mut core_normal = None;
        let motion = shape.motion(delta.length(), angle);
        // Already touching: parry's nonlinear cast, which then steps forward looking for an
        // approach, returned 10⁻⁶ for a plate pivoting about a corner that was separating, and
        // the plate was put back at the start of the step, step after step (benches/RESULTS.md,
        // "CCD: no freeze, no tunnel"). Sampled instead; so is a turning body whose cast hits
        // within one slop of its motion, which the back-off would put back at the start too (a
        // wedge 5.5 mm above a floor, frozen for 236 steps).
        let sampled = |touch: &mut Option<Witness>, impact_time: &mut Option<f32>| {
            let depth = (SAMPLED_DEPTH * shape.thickness).max(settings.slop);
            let step = (settings.motion_fraction * shape.thickness).max(settings.slop);
            let (hit, at) = sample_turning(
                collider,
                &from,
                delta,
                rotation,
                motion / step,
                target,
                &to,
                depth,
            );
            if let Some(Impact::At(_)) = hit {
                *impact_time = at.map(|a| a.0);
                *touch = at.map(|a| (a.1, a.2));
            }
            hit
        };
        let touching = turning
            && distance(&from, collider.shape.as_ref(), &to, target.shape.as_ref())
                .is_ok_and(|d| d.distance <= settings.slop);
        let hit = if touching {
            sampled(&mut touch, &mut impact_time)
        } else if turning {
            match cast_turning(collider, &from, delta, rotation, target, &to) {
                Ok((Some(Impact::At(t)), _)) if t * motion <= settings.slop => {
                    sampled(&mut touch, &mut impact_time)
                }
                Ok((hit, at)) => {
                    if let Some(Impact::At(t)) = hit {
                        impact_time = Some(t);
                        touch = at;
                    }
                    hit.map(|t| back_off(t, motion, settings.slop))
                }
                // parry has no nonlinear cast for this pair (half-spaces, composite against
                // composite): conservative advancement on parry's distance query.
                Err(Unsupported) => advance(
                    collider,
                    &from,
                    delta,
                    rotation,
                    motion,
                    target,
                    &to,
                    settings.slop,
                ),
            }
        } else {
            let (hit, at) = cast_linear(collider, &from, delta, target, &to, settings.slop);
            if let Some(Impact::At(_)) = hit {
                touch = at;
            }
            hit
        };
        let fraction = match hit {
            Some(Impact::At(t)) => t,
            // The centre of mass, which no rotation moves, crossing the surface: whatever
            // the cast of the whole shape says, the body went through (a needle spun at
            // 1,450 rad/s by its impact, 24 rad within the step, fell through a 20 cm floor
            // past parry's nonlinear cast, which found nothing).
            Some(Impact::AtStart) | None => match cast_core(shape, start, delta, target, &to) {
                Some((t, normal)) => {
                    core_normal = Some(normal);
                    t
                }
                None => continue,
            },
        };
        let closer = best.is_none_or(|b| (fraction, handle) < (b.fraction, b.collider));
        if closer {
            let at = |t: f32| {
                Pose::from_parts(
                    start.translation + delta * t,
                    (Quat::from_scaled_axis(rotation * t) * start.rotation).normalize(),
                )
            };
            let stop = at(fraction);
            let (impact, contact) = match core_normal {
                // The centre reached the surface: the impact is the body's as a whole, at its
                // centre along the surface normal, without friction.
                Some(normal) => (
                    stop,
                    Some(CcdContact {
                        point: stop.translation,
                        normal,
                        material: Material {
                            friction: 0.0,
                            ..Material::mix(collider.material, target.material)
                        },
                    }),
                ),
                None => {
                    let impact = at(impact_time.unwrap_or(fraction));
                    let contact = touch.map(|(point, normal)| {
                        let pose = impact * collider.local_pose;
                        CcdContact {
                            point: pose * point,
                            normal: -(pose.rotation * normal),
                            material: Material::mix(collider.material, target.material),
                        }
                    });
                    (impact, contact)
                }
            };
            best = Some(CcdHit {
                fraction,
                collider: handle,
                stop,
                impact,
                contact,
                core: core_normal.is_some(),
            });
        }
    }
    best
}

/// Most whole turns [`unwrapped_turn`] considers.
const MAX_TURNS: u32 = 64;

/// The rotation vector of the turn `turn` (start to end) that the body made, told apart from
/// the others with the same end (θ + 2πk about its axis, 2π − θ + 2πk about the opposite one)
/// as the one nearest to `spin`, the rotation vector ω·dt of its angular velocity. The
/// shortest one alone (θ ≤ π) is a body spinning at 5.5 rad per step cast as turning 0.8 rad
/// the other way: a needle spun up by a bounce was cast back into the floor it had just left,
/// stopped there step after step.
fn unwrapped_turn(turn: Quat, spin: Vec3) -> Vec3 {
    use std::f32::consts::TAU;
    let turn = if turn.w < 0.0 { -turn } else { turn };
    let shortest = turn.to_scaled_axis();
    let angle = shortest.length();
    let axis = if angle > 0.0 {
        shortest / angle
    } else if spin.length_squared() > 0.0 {
        spin.normalize()
    } else {
        return shortest;
    };
    let mut best = shortest;
    let turns = ((spin.length() / TAU) as u32 + 1).min(MAX_TURNS);
    for k in 0..=turns {
        let whole = TAU * k as f32;
        for candidate in [axis * (angle + whole), -axis * (TAU - angle + whole)] {
            if candidate.distance_squared(spin) < best.distance_squared(spin) {
                best = candidate;
            }
        }
    }
    best
}

/// A cast's outcome: a time of impact in (0, 1], or contact (within the target distance and
/// approaching) already at the start.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Impact {
    At(f32),
    AtStart,
}

fn impact(hit: Option<ShapeCastHit>) -> Option<Impact> {
    let hit = hit?;
    if hit.status == ShapeCastStatus::PenetratingOrWithinTargetDist || hit.time_of_impact <= 0.0 {
        Some(Impact::AtStart)
    } else {
        Some(Impact::At(hit.time_of_impact.min(1.0)))
    }
}

/// Linear cast of the collider at `from` along `delta` (one step = time 1), stopping `slop`
/// short of `target`.
fn cast_linear(
    collider: &Collider,
    from: &Pose,
    delta: Vec3,
    target: &Collider,
    to: &Pose,
    slop: f32,
) -> (Option<Impact>, Option<Witness>) {
    let options = ShapeCastOptions {
        max_time_of_impact: 1.0,
        target_distance: slop,
        stop_at_penetration: false,
        compute_impact_geometry_on_penetration: false,
    };
    let hit = cast_shapes(
        from,
        delta,
        collider.shape.as_ref(),
        to,
        Vec3::ZERO,
        target.shape.as_ref(),
        options,
    )
    .ok()
    .flatten();
    (impact(hit), witness(hit))
}

/// Where a cast touches: the point and the collider's outward normal there, both in the
/// collider's frame.
type Witness = (Vec3, Vec3);

/// The point (in the collider's frame) and the collider's outward normal (same frame) where
/// a cast touches, unless it touched at the start (then parry does not compute them).
fn witness(hit: Option<ShapeCastHit>) -> Option<Witness> {
    let hit = hit?;
    let ok = hit.status != ShapeCastStatus::PenetratingOrWithinTargetDist
        && hit.witness1.is_finite()
        && hit.normal1.is_finite()
        && hit.normal1.length_squared() > 0.5;
    ok.then_some((hit.witness1, hit.normal1))
}

/// Nonlinear cast: the collider at `from` translating by `delta` while turning by the rotation
/// vector `rotation` about its body's centre of mass, over one step (time 0 to 1).
fn cast_turning(
    collider: &Collider,
    from: &Pose,
    delta: Vec3,
    rotation: Vec3,
    target: &Collider,
    to: &Pose,
) -> Result<(Option<Impact>, Option<Witness>), Unsupported> {
    // The centre of mass in the collider's frame: the origin of the body frame.
    let centre = collider.local_pose.inverse().translation;
    let moving = NonlinearRigidMotion::new(*from, centre, delta, rotation);
    let resting = NonlinearRigidMotion::constant_position(*to);
    let hit = cast_shapes_nonlinear(
        &moving,
        collider.shape.as_ref(),
        &resting,
        target.shape.as_ref(),
        0.0,
        1.0,
        false,
    )?;
    Ok((impact(hit), witness(hit)))
}

/// Most distance queries of one conservative advancement.
const MAX_ADVANCE_ITERATIONS: usize = 64;

/// Overlap (in the moving body's thicknesses, at least the slop) that [`sample_turning`]
/// lets a body reach before it stops it: what the next step's contacts push out.
const SAMPLED_DEPTH: f32 = 0.25;

/// Most samples of [`sample_turning`].
const MAX_SAMPLES: f32 = 256.0;

/// Bisections of [`sample_turning`] between its last shallow sample and its first deep one.
const SAMPLE_BISECTIONS: usize = 8;

/// The motion of [`cast_turning`] for a body that touches `target` at its start: sampled at
/// `samples` times (rounded up; between 1 and [`MAX_SAMPLES`]) for the first at which the body
/// overlaps `target` by more than `depth`, then bisected between it and the sample before.
/// Returns the last time found within `depth` (the stop), and, at the deep time, that time,
/// the deepest point of the collider and its outward normal there (both in the collider's
/// frame): the point that hits. `None` when no sample is that deep.
#[allow(clippy::too_many_arguments)]
fn sample_turning(
    collider: &Collider,
    from: &Pose,
    delta: Vec3,
    rotation: Vec3,
    samples: f32,
    target: &Collider,
    to: &Pose,
    depth: f32,
) -> (Option<Impact>, Option<(f32, Vec3, Vec3)>) {
    let centre = collider.local_pose.inverse().translation;
    let moving = NonlinearRigidMotion::new(*from, centre, delta, rotation);
    let deep = |t: f32| {
        let pose = moving.position_at_time(t);
        contact(
            &pose,
            collider.shape.as_ref(),
            to,
            target.shape.as_ref(),
            0.0,
        )
        .ok()
        .flatten()
        .filter(|c| c.dist < -depth)
        .map(|c| (pose, c))
    };
    let n = samples.ceil().clamp(1.0, MAX_SAMPLES) as u32;
    let mut shallow = 0.0;
    for k in 1..=n {
        let t = k as f32 / n as f32;
        let Some(mut hit) = deep(t).map(|h| (t, h)) else {
            shallow = t;
            continue;
        };
        for _ in 0..SAMPLE_BISECTIONS {
            let mid = 0.5 * (shallow + hit.0);
            match deep(mid) {
                Some(h) => hit = (mid, h),
                None => shallow = mid,
            }
        }
        let (t, (pose, c)) = hit;
        let point = pose.inverse() * c.point1;
        let normal = pose.rotation.inverse() * c.normal1;
        let ok = point.is_finite() && normal.is_finite();
        let stop = if shallow > 0.0 {
            Impact::At(shallow)
        } else {
            Impact::AtStart
        };
        return (Some(stop), ok.then_some((t, point, normal)));
    }
    (None, None)
}

/// Conservative advancement (Mirtich 1996): the same motion as [`cast_turning`], for pairs
/// parry cannot cast nonlinearly. No point of the shape moves faster than `speed` (m per step),
/// so advancing by (distance − slop/2)/speed can never close the gap below slop/2; it stops
/// when the gap is within `slop`. `None` when the step ends first, the iterations run out
/// (a grazing motion that never closes in), or parry has no distance query for the pair.
#[allow(clippy::too_many_arguments)]
fn advance(
    collider: &Collider,
    from: &Pose,
    delta: Vec3,
    rotation: Vec3,
    speed: f32,
    target: &Collider,
    to: &Pose,
    slop: f32,
) -> Option<Impact> {
    let centre = collider.local_pose.inverse().translation;
    let moving = NonlinearRigidMotion::new(*from, centre, delta, rotation);
    let mut t = 0.0;
    for _ in 0..MAX_ADVANCE_ITERATIONS {
        let pose = moving.position_at_time(t);
        let gap = distance(&pose, collider.shape.as_ref(), to, target.shape.as_ref())
            .ok()?
            .distance;
        if gap <= slop {
            return Some(if t == 0.0 {
                Impact::AtStart
            } else {
                Impact::At(t)
            });
        }
        t += (gap - 0.5 * slop) / speed;
        if t > 1.0 {
            return None;
        }
    }
    None
}

/// Stops a nonlinear impact `slop` short, measured along the fastest point's path (`motion`
/// metres per step); the nonlinear cast has no target distance of its own.
fn back_off(impact: Impact, motion: f32, slop: f32) -> Impact {
    match impact {
        Impact::At(t) if motion > 0.0 => Impact::At((t - slop / motion).max(0.0)),
        other => other,
    }
}

/// Fraction of the step at which a core sphere at the centre of mass (radius a quarter of the
/// thickness) touches `target`; `None` when it does not, or already does at the start (the body
/// is deep in the target: a case for the resolver's projection, not for a stop).
fn cast_core(
    shape: &CcdShape,
    start: Pose,
    delta: Vec3,
    target: &Collider,
    to: &Pose,
) -> Option<(f32, Vec3)> {
    let core = Ball::new(0.25 * shape.thickness);
    let options = ShapeCastOptions {
        max_time_of_impact: 1.0,
        target_distance: 0.0,
        stop_at_penetration: false,
        compute_impact_geometry_on_penetration: false,
    };
    let from = Pose::from_translation(start.translation);
    let hit = cast_shapes(
        &from,
        delta,
        &core,
        to,
        Vec3::ZERO,
        target.shape.as_ref(),
        options,
    )
    .ok()
    .flatten();
    match impact(hit)? {
        Impact::At(t) => {
            let normal = to.rotation * hit?.normal2;
            normal.is_finite().then_some((t, normal))
        }
        // The core already overlaps (the body half into the surface, its centre still
        // outside): the centre itself, a ray. Without it a plate sunk to its middle in a floor
        // by an earlier impact crossed it in the next step (benches/RESULTS.md, "CCD: no
        // freeze, no tunnel").
        Impact::AtStart => {
            let ray = Ray::new(start.translation, delta);
            let hit = target.shape.cast_ray_and_get_normal(to, &ray, 1.0, true)?;
            (hit.time_of_impact > 0.0 && hit.normal.is_finite())
                .then_some((hit.time_of_impact, hit.normal))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_body::RigidBody;
    use jostle_math::Quat;
    use parry3d::shape::SharedShape;

    /// A 0.01 m wall at x ∈ [−0.01, 0] and a ball (r 0.05) at x = 1 whose step ends 1 m
    /// behind the wall: the sweep stops it `slop` short of the face.
    #[test]
    fn sweep_stops_a_ball_short_of_a_thin_wall() {
        let mut bodies = BodySet::new();
        let wall = bodies
            .insert(RigidBody::fixed().with_pose(Vec3::new(-0.005, 0.0, 0.0), Quat::IDENTITY));
        let ball = bodies.insert(
            RigidBody::dynamic(1.0, jostle_math::Mat3::IDENTITY)
                .expect("mass")
                .with_pose(Vec3::X, Quat::IDENTITY),
        );
        let mut colliders = ColliderSet::new();
        let wall_collider =
            colliders.insert(Collider::new(SharedShape::cuboid(0.005, 1.0, 1.0), wall));
        let ball_collider = colliders.insert(Collider::new(SharedShape::ball(0.05), ball));
        let mut broad = BroadPhase::new();
        broad.update(&colliders, &bodies, 0.01);
        let settings = CcdSettings::default();
        let collider = colliders.get(ball_collider).expect("ball");
        let shape = CcdShape::of(collider);
        assert_eq!(shape.thickness, 0.1);
        assert_eq!(shape.extent, 0.0, "a centred ball's rotation moves nothing");
        let start = Pose::from_translation(Vec3::X);
        let end = Pose::from_translation(-Vec3::X);
        let hit = sweep(
            collider,
            &shape,
            start,
            end,
            Vec3::ZERO,
            |_| false,
            &colliders,
            &bodies,
            &broad,
            &settings,
            &mut Vec::new(),
        )
        .expect("the ball hits the wall");
        assert_eq!(hit.collider, wall_collider);
        // Stop where the ball's surface is `slop` from the face: centre at 0.05 + 0.005.
        let x = 1.0 - 2.0 * hit.fraction;
        assert!((x - 0.055).abs() < 1e-4, "stopped at x = {x}");
        // Moving away, nothing is hit.
        let away = sweep(
            collider,
            &shape,
            start,
            Pose::from_translation(Vec3::new(3.0, 0.0, 0.0)),
            Vec3::ZERO,
            |_| false,
            &colliders,
            &bodies,
            &broad,
            &settings,
            &mut Vec::new(),
        );
        assert_eq!(away, None);
    }

    /// A unit box spinning at 16.5 rad/s and falling at 2.85 m/s, 10 mm above a half-space:
    /// its rotation lifts its lowest corner as fast as it falls, and it only reaches the
    /// plane late in the step. The linear cast (which ignores a rotation that moves a corner
    /// 0.24 m) stopped it early in the step, where the turning box is still 9 mm up; the
    /// next step did the same, and it hung in the air for as long as it spun. A stop must be
    /// within `slop` of the surface at the pose it stops at (the module's rule).
    #[test]
    fn a_spinning_box_is_stopped_where_its_turning_pose_touches() {
        let mut bodies = BodySet::new();
        let ground = bodies.insert(RigidBody::fixed());
        let body =
            bodies.insert(RigidBody::dynamic(1.0, jostle_math::Mat3::IDENTITY).expect("mass"));
        let mut colliders = ColliderSet::new();
        let floor = colliders.insert(Collider::new(SharedShape::halfspace(Vec3::Y), ground));
        let cube = colliders.insert(Collider::new(SharedShape::cuboid(0.5, 0.5, 0.5), body));
        let start = Pose::from_parts(
            Vec3::new(0.0, 0.707, 0.0),
            Quat::from_xyzw(-0.6967, -0.6150, -0.3445, -0.1334).normalize(),
        );
        let dt = 1.0 / 60.0;
        let spin = Vec3::new(-2.411, 0.645, 16.491) * dt;
        let end = Pose::from_parts(
            start.translation + Vec3::new(0.0, -2.854, 0.0) * dt,
            (Quat::from_scaled_axis(spin) * start.rotation).normalize(),
        );
        let mut broad = BroadPhase::new();
        broad.update(&colliders, &bodies, 0.01);
        let settings = CcdSettings::default();
        let collider = colliders.get(cube).expect("cube");
        let shape = CcdShape::of(collider);
        let gap = |pose: &Pose| {
            distance(
                pose,
                collider.shape.as_ref(),
                &Pose::IDENTITY,
                colliders.get(floor).expect("floor").shape.as_ref(),
            )
            .expect("distance")
            .distance
        };
        assert!(gap(&start) > 0.009, "starts {} above", gap(&start));
        let Some(hit) = sweep(
            collider,
            &shape,
            start,
            end,
            Vec3::ZERO,
            |_| false,
            &colliders,
            &bodies,
            &broad,
            &settings,
            &mut Vec::new(),
        ) else {
            return;
        };
        let motion =
            NonlinearRigidMotion::new(start, Vec3::ZERO, end.translation - start.translation, spin);
        let stopped = motion.position_at_time(hit.fraction);
        assert!(
            gap(&stopped) <= settings.slop + 1e-4,
            "stopped at {} of the step, {} m above the floor",
            hit.fraction,
            gap(&stopped)
        );
    }
}
