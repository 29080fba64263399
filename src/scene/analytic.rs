//! A scene's closed form ([`Analytic`]): what a scene file declares under `analytic:` so that a
//! benchmark can measure the run's **analytic error** against it (the `jostle bench` command
//! reports it). The declaration is part of the scene format; the measuring is the bench's.

/// A scene's closed form, for the **analytic error** of the module documentation. Declared in
/// a scene file as `analytic: FreeFall(body: "ball")` and so on; every body named must be a
/// dynamic body of the scene's `bodies` list, every number finite (validated with the scene,
/// naming the field). `g` is the magnitude of the scene's gravity; positions are of the
/// body's centre of mass; t is the simulated time since the start of the run.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Analytic {
    /// Flight under gravity alone: p(t) = p₀ + v₀t + ½·g⃗·t² (g⃗ the scene's gravity vector).
    /// Error: the largest |p − p(t)| (m). Semi-implicit Euler leaves ½|g|·t·dt of it, so this
    /// error shrinks linearly with the step.
    FreeFall {
        /// The falling body.
        body: String,
    },
    /// A body released at rest on a plane inclined `angle` degrees with combined friction
    /// `friction` (μ): it slides with a = g(sin θ − μ cos θ), or holds (a = 0) when
    /// tan θ ≤ μ, so the distance travelled is s(t) = ½at². Error: the largest
    /// | |p − p₀| − s(t) | (m).
    Incline {
        /// The sliding body.
        body: String,
        /// Inclination (degrees), in [0, 90).
        angle: f32,
        /// Combined friction coefficient μ (≥ 0) between the body and the plane.
        friction: f32,
    },
    /// A solid ball launched sliding without spin on level ground with combined friction μ:
    /// friction decelerates it at μg until t* = 2v₀/(7μg), after which it rolls at 5/7 v₀.
    /// Horizontal distance x(t) = v₀t − ½μgt² before t*, x(t*) + 5/7·v₀(t − t*) after.
    /// Error: the largest | |horizontal displacement| − x(t) | (m).
    SlidingToRolling {
        /// The ball.
        body: String,
        /// Combined friction coefficient μ (> 0) between ball and ground.
        friction: f32,
    },
    /// A body dropped from rest onto level ground with combined restitution e: the k-th apex
    /// is at `rest_height` + e²ᵏ(y₀ − `rest_height`). Error: the largest |apexₖ − closed
    /// form| (m) over the apexes the closed form has before the run's last frame; an apex the
    /// run misses counts its whole closed-form height above `rest_height`. An apex is a frame
    /// where the vertical velocity turns from up to down more than 1 cm above `rest_height`.
    Bounce {
        /// The bouncing body.
        body: String,
        /// Combined restitution e, in [0, 1].
        restitution: f32,
        /// Height of the centre of mass when the body rests on the ground (m).
        rest_height: f32,
    },
    /// A head-on collision of two bodies moving along the line of their centres, with
    /// combined restitution e: along that line, u′ₐ = (mₐuₐ + m_b u_b − m_b e(uₐ − u_b)) /
    /// (mₐ + m_b) and u′_b = (mₐuₐ + m_b u_b + mₐe(uₐ − u_b)) / (mₐ + m_b) if they approach,
    /// unchanged otherwise. Error: the largest |v − v′| of the two bodies at the end of the run
    /// (m/s).
    Collision {
        /// The first body.
        a: String,
        /// The second body.
        b: String,
        /// Combined restitution e, in [0, 1].
        restitution: f32,
    },
}

impl Analytic {
    /// The names of the bodies the declaration refers to.
    pub fn bodies(&self) -> Vec<&str> {
        match self {
            Self::FreeFall { body }
            | Self::Incline { body, .. }
            | Self::SlidingToRolling { body, .. }
            | Self::Bounce { body, .. } => vec![body.as_str()],
            Self::Collision { a, b, .. } => vec![a.as_str(), b.as_str()],
        }
    }

    /// Checks the numbers (finite, in range). The error is (field under `analytic.`, message).
    /// Whether the bodies exist is the scene's to check ([`Analytic::bodies`]).
    pub fn validate(&self) -> Result<(), (String, String)> {
        let check = |field: &str, x: f32, ok: bool, range: &str| {
            if x.is_finite() && ok {
                Ok(())
            } else {
                Err((
                    format!("analytic.{field}"),
                    format!("must be finite and {range}, got {x}"),
                ))
            }
        };
        match self {
            Self::FreeFall { .. } => Ok(()),
            Self::Incline {
                angle, friction, ..
            } => {
                check("angle", *angle, (0.0..90.0).contains(angle), "in [0, 90)")?;
                check("friction", *friction, *friction >= 0.0, ">= 0")
            }
            Self::SlidingToRolling { friction, .. } => {
                check("friction", *friction, *friction > 0.0, "> 0")
            }
            Self::Bounce {
                restitution,
                rest_height,
                ..
            } => {
                check(
                    "restitution",
                    *restitution,
                    (0.0..=1.0).contains(restitution),
                    "in [0, 1]",
                )?;
                check("rest_height", *rest_height, true, "a height (m)")
            }
            Self::Collision { a, b, restitution } => {
                if a == b {
                    return Err((
                        "analytic.b".into(),
                        format!("must differ from `a` (\"{a}\")"),
                    ));
                }
                check(
                    "restitution",
                    *restitution,
                    (0.0..=1.0).contains(restitution),
                    "in [0, 1]",
                )
            }
        }
    }
}
