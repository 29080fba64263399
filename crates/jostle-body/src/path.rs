//! Scripted motion for position-based kinematic bodies: where the body is at each time.

use jostle_math::{Quat, Vec3};
use std::f64::consts::TAU;

/// A scripted motion of a position-based kinematic body ([`crate::BodyType::KinematicPosition`]):
/// its pose at each time since the world started. The world sends the body to the path's pose
/// at the end of every step, so that the body moves, and pushes what it meets, at the path's
/// velocity.
///
/// ```
/// use jostle_body::KinematicPath;
/// use jostle_math::{Quat, Vec3};
///
/// // A paddle swinging 4 m along x and back every 2 s.
/// let path = KinematicPath::Line {
///     start: Vec3::ZERO,
///     rotation: Quat::IDENTITY,
///     offset: Vec3::new(4.0, 0.0, 0.0),
///     period: 2.0,
/// };
/// let (at_half, _) = path.pose_at(1.0);
/// assert!((at_half - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum KinematicPath {
    /// Back and forth along a segment, smoothly: at time t the body is at
    /// start + offset·(1 − cos(2πt/period))/2, with its orientation kept.
    Line {
        /// Position at time 0 (m): one end of the segment.
        start: Vec3,
        /// Orientation, kept throughout.
        rotation: Quat,
        /// From the start to the other end of the segment (m).
        offset: Vec3,
        /// Time for the way there and back (s, > 0).
        period: f32,
    },
    /// A rigid turn about the line through `center` along `axis`, once per `period` (a
    /// negative period turns the other way): the body keeps its place on the turning frame,
    /// like a turntable's load or a windmill's blade; with the centre at the body's own
    /// position it spins in place.
    Turn {
        /// Position at time 0 (m).
        start: Vec3,
        /// Orientation at time 0.
        rotation: Quat,
        /// A point on the axis of the turn (m).
        center: Vec3,
        /// Direction of the axis (any length but zero); positive turns are right-handed.
        axis: Vec3,
        /// Time for one turn (s, non-zero; negative turns the other way).
        period: f32,
    },
}

impl KinematicPath {
    /// The pose (position, orientation) at time `t` (s).
    pub fn pose_at(&self, t: f64) -> (Vec3, Quat) {
        match *self {
            Self::Line {
                start,
                rotation,
                offset,
                period,
            } => {
                let phase = (t / period as f64).fract() * TAU;
                let along = 0.5 * (1.0 - phase.cos());
                (start + offset * along as f32, rotation)
            }
            Self::Turn {
                start,
                rotation,
                center,
                axis,
                period,
            } => {
                let angle = ((t / period as f64).fract() * TAU) as f32;
                let turn = Quat::from_axis_angle(axis.normalize_or_zero(), angle);
                (
                    center + turn * (start - center),
                    (turn * rotation).normalize(),
                )
            }
        }
    }

    /// The acceleration (m/s²) of the body's position at time `t` (s): what turns a step's
    /// mean velocity into the velocity at each instant of the step.
    pub fn acceleration_at(&self, t: f64) -> Vec3 {
        match *self {
            Self::Line { offset, period, .. } => {
                let rate = TAU / period as f64;
                let phase = (t / period as f64).fract() * TAU;
                offset * (0.5 * rate * rate * phase.cos()) as f32
            }
            Self::Turn {
                center,
                axis,
                period,
                ..
            } => {
                let (position, _) = self.pose_at(t);
                let spin = axis.normalize_or_zero() * (TAU / period as f64) as f32;
                spin.cross(spin.cross(position - center))
            }
        }
    }

    /// Checks the path's numbers: the field at fault and why.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let vector = |field: &'static str, v: Vec3| {
            if v.is_finite() {
                Ok(())
            } else {
                Err((field, format!("must be finite, got {v}")))
            }
        };
        let period = |p: f32, zero_ok: bool| {
            if p.is_finite() && (p > 0.0 || (!zero_ok && p < 0.0)) {
                Ok(())
            } else {
                Err((
                    "period",
                    format!("must be finite and non-zero (> 0 for a line), got {p}"),
                ))
            }
        };
        match *self {
            Self::Line {
                start,
                rotation,
                offset,
                period: p,
            } => {
                vector("start", start)?;
                vector("offset", offset)?;
                rotation_ok(rotation)?;
                period(p, true)
            }
            Self::Turn {
                start,
                rotation,
                center,
                axis,
                period: p,
            } => {
                vector("start", start)?;
                vector("center", center)?;
                vector("axis", axis)?;
                if axis.normalize_or_zero() == Vec3::ZERO {
                    return Err(("axis", format!("must have a direction, got {axis}")));
                }
                rotation_ok(rotation)?;
                period(p, false)
            }
        }
    }
}

fn rotation_ok(q: Quat) -> Result<(), (&'static str, String)> {
    if q.is_finite() && (q.length() - 1.0).abs() < 1e-3 {
        Ok(())
    } else {
        Err(("rotation", format!("must be a unit quaternion, got {q}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_goes_there_and_back_each_period() {
        let path = KinematicPath::Line {
            start: Vec3::new(1.0, 2.0, 3.0),
            rotation: Quat::from_rotation_y(0.3),
            offset: Vec3::new(0.0, 0.0, -2.0),
            period: 4.0,
        };
        for (t, z) in [
            (0.0, 3.0),
            (1.0, 2.0),
            (2.0, 1.0),
            (3.0, 2.0),
            (4.0, 3.0),
            (6.0, 1.0),
        ] {
            let (p, q) = path.pose_at(t);
            assert!((p - Vec3::new(1.0, 2.0, z)).length() < 1e-5, "{t}: {p}");
            assert!(q.abs_diff_eq(Quat::from_rotation_y(0.3), 1e-6));
        }
        assert_eq!(path.check(), Ok(()));
    }

    #[test]
    fn a_turn_carries_the_body_round_its_axis() {
        let path = KinematicPath::Turn {
            start: Vec3::new(2.0, 1.0, 0.0),
            rotation: Quat::IDENTITY,
            center: Vec3::new(0.0, 1.0, 0.0),
            axis: Vec3::new(0.0, 3.0, 0.0),
            period: 8.0,
        };
        // A quarter turn about +y takes +x to −z.
        let (p, q) = path.pose_at(2.0);
        assert!((p - Vec3::new(0.0, 1.0, -2.0)).length() < 1e-5, "{p}");
        assert!(q.abs_diff_eq(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2), 1e-6));
        // A negative period turns the other way.
        let back = KinematicPath::Turn {
            start: Vec3::new(2.0, 1.0, 0.0),
            rotation: Quat::IDENTITY,
            center: Vec3::new(0.0, 1.0, 0.0),
            axis: Vec3::Y,
            period: -8.0,
        };
        let (p, _) = back.pose_at(2.0);
        assert!((p - Vec3::new(0.0, 1.0, 2.0)).length() < 1e-5, "{p}");
        // Far into a run the phase is still exact.
        let (p, _) = path.pose_at(8.0 * 1e6 + 2.0);
        assert!((p - Vec3::new(0.0, 1.0, -2.0)).length() < 1e-4, "{p}");
    }

    /// The acceleration is the second difference of the poses, for lines and turns (either
    /// way round, about axes through or off the start).
    #[test]
    fn the_acceleration_is_the_paths_second_difference() {
        let paths = [
            KinematicPath::Line {
                start: Vec3::new(1.0, 2.0, 3.0),
                rotation: Quat::IDENTITY,
                offset: Vec3::new(0.5, 0.0, -2.0),
                period: 3.0,
            },
            KinematicPath::Turn {
                start: Vec3::new(2.0, 1.0, 0.5),
                rotation: Quat::IDENTITY,
                center: Vec3::new(-1.0, 0.0, 0.0),
                axis: Vec3::new(0.0, 2.0, 0.5),
                period: 5.0,
            },
            KinematicPath::Turn {
                start: Vec3::new(0.0, 1.0, 0.0),
                rotation: Quat::IDENTITY,
                center: Vec3::ZERO,
                axis: Vec3::Y,
                period: -2.0,
            },
        ];
        let h = 1e-2;
        for path in &paths {
            for t in [0.0, 0.4, 1.3, 2.9] {
                let x = |t: f64| path.pose_at(t).0.as_dvec3();
                let numeric = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
                let a = path.acceleration_at(t).as_dvec3();
                assert!(
                    (a - numeric).length() < 1e-2 * numeric.length().max(1.0),
                    "{path:?} at {t}: {a} against {numeric}"
                );
            }
        }
    }

    #[test]
    fn bad_numbers_name_their_field() {
        let line = KinematicPath::Line {
            start: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            offset: Vec3::X,
            period: 0.0,
        };
        assert_eq!(line.check().unwrap_err().0, "period");
        let turn = KinematicPath::Turn {
            start: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            center: Vec3::ZERO,
            axis: Vec3::ZERO,
            period: 1.0,
        };
        assert_eq!(turn.check().unwrap_err().0, "axis");
        let turn = KinematicPath::Turn {
            start: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            center: Vec3::NAN,
            axis: Vec3::Y,
            period: 1.0,
        };
        assert_eq!(turn.check().unwrap_err().0, "center");
    }
}
