//! The soft-step resolver's tunables, in one place.
//!
//! The defaults start from Box2D v3's (`b2DefaultWorldDef`: damping ratio 10, push-out 3 m/s,
//! restitution threshold 1 m/s; speculative distance 4 × linear slop = 0.02 m) with its 4
//! substeps at 30 Hz (60 Hz against static bodies) doubled to 8 substeps at 60 Hz (120 Hz): the
//! same stiffness relative to the substep rate, a quarter of the load-proportional sink, and the
//! stability family of the `jostle` crate's tests standing where 4 substeps let columns fall
//! (its benches/RESULTS.md, "Eight substeps by default"); load compensation (`preload_rate`)
//! then removes most of the remaining sink (RESULTS.md, "Load compensation"); the damping
//! ratio is 7 instead of 10, which the whole family meets (RESULTS.md, "The contact damping
//! ratio").

/// Settings of [`crate::soft_step::SoftStepResolver`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct SoftStepSettings {
    /// Substeps per step (count). Default 8. Each substep integrates gravity, solves every
    /// contact once with its soft bias and moves the bodies; more substeps make stacks and
    /// high mass ratios stiffer at a cost linear in the count. 0 is treated as 1. For the
    /// faster, softer configuration of Box2D v3 set 4 substeps with `contact_hertz` 30 and
    /// `static_hertz` 60 (at 4 substeps the defaults' 60 Hz between bodies would sit at the
    /// cap, which measured worse: a 40-row pyramid collapses).
    pub substeps: u32,
    /// Relax iterations per substep (count). Default 1. Each re-solves the contacts without
    /// the soft bias after the positions moved, removing the push-out velocity the bias added
    /// (Catto's "relax"), so resolved overlap does not turn into a bounce.
    pub relax_iterations: u32,
    /// Stiffness of contacts between two dynamic bodies (Hz). Default 60, an eighth of the
    /// default substep rate (480 Hz). Higher is stiffer (a loaded contact sinks in proportion
    /// to 1/hertz²) but is capped at a quarter of the substep rate, beyond which the spring
    /// cannot be resolved by the substep; at the cap itself planar pyramids creep (a 20-row
    /// one drifts 18 mm at 8 substeps and 120 Hz, 0.4 mm at 60 Hz). Must be > 0.
    pub contact_hertz: f32,
    /// Stiffness of contacts against a static or immovable body (Hz). Default 120 (twice
    /// `contact_hertz`, as Box2D: a static body cannot share the correction). Same cap.
    pub static_hertz: f32,
    /// Damping ratio ζ of the contact spring (dimensionless). Default 7: over-damped, so
    /// overlap is removed without oscillation. At most
    /// [`SoftStepSettings::MAX_DAMPING_RATIO`].
    ///
    /// Measured on the stability family at the defaults (the `jostle` crate's
    /// benches/RESULTS.md, "The contact damping ratio"): ζ = 6, 7 and 8 meet the criterion in
    /// all 42 cases, 10 (Box2D's value, the default before) in 41 (the 60-box column sways
    /// 11.3 mm). On the columns alone, 5 lets the 60-column sway 10.1 mm, and 3 sways less but
    /// lets the 40- and 60-columns sink more than 1 mm per layer (the preload's stiffening is
    /// bounded by the damping it leaves) and two perturbed 20-columns sway 11–13 mm.
    pub damping_ratio: f32,
    /// Largest speed at which the soft bias pushes overlapping bodies apart (m/s), under
    /// gravity up to [`super::PUSH_OUT_GRAVITY`] (9.81 m/s²); under stronger gravity it
    /// grows in proportion ([`super::push_out_speed`]), since the bias that carries a
    /// contact's load does (a unit box resting under 10⁵ m/s² needs 8.6 m/s of it at the
    /// default substeps). Default 3. Bounds the energy a deep overlap or a crushed body can
    /// gain.
    pub max_push_out: f32,
    /// Overlap (m) beyond its spring's static compression under its current load (and beyond
    /// the one substep of gravity by which the discrete spring's equilibrium sits deeper) that
    /// a resting contact (loaded, and approaching slower than `restitution_threshold` at the
    /// start of the step) still pushes out through real velocity, as a plain soft contact.
    /// Default 0.005 (Box2D's linear slop). Overlap deeper than that, and all overlap of a
    /// contact that carries no load or hit fast (bodies that start overlapping, an impact), is
    /// pushed out through pseudo velocities that move the bodies but are discarded after each
    /// substep (split impulses), so separating overlapping bodies adds no kinetic energy.
    /// Larger values let resting contacts push more overlap out through real velocity (a box
    /// spinning 0.3 m deep in the floor gains 0.1% of its energy at 0.02).
    pub push_out_slop: f32,
    /// Gap (m) up to which a separated contact takes part as a speculative constraint (it
    /// stops the bodies from closing more than the gap within a substep). Default 0.02, the
    /// narrow phase's prediction distance. A contact with a larger gap takes part only when
    /// its bodies close that gap beyond the margin within the step at their velocities at
    /// its start (the speculative contacts the facade's narrow phase finds ahead of fast
    /// bodies); the others are ignored.
    pub speculative_margin: f32,
    /// Approach speed (m/s) above which restitution applies. Default 1. Slower impacts are
    /// perfectly inelastic, so resting contacts do not jitter.
    pub restitution_threshold: f32,
    /// Most sweeps of the restitution pass (count). Default 64: an impact passed through a
    /// chain of touching bodies converges slowly under Gauss-Seidel (a 5-ball Newton's cradle
    /// keeps its energy to 1.5·10⁻³ with 16 sweeps, 6·10⁻⁶ with 64, at 240 Hz). The pass stops earlier once a
    /// sweep corrects no normal velocity by more than
    /// [`SoftStepSettings::RESTITUTION_TOLERANCE`]; it runs only in steps where some contact
    /// bounces, so scenes without restitution never pay for it.
    pub restitution_iterations: u32,
    /// The gyroscopic term: each substep's turn keeps the body's world angular momentum
    /// (`soft_step::gyroscopic::turn`). Default true. Without it a free body's angular momentum is not conserved when its inertia is
    /// not spherical (a spun box never flips about its intermediate axis).
    pub gyroscopic: bool,
    /// Solve friction in the biased pass too, not only in the relax pass. Default false: the
    /// biased pass's push-out velocities are not real motion, and friction reacting to them
    /// drags resting bodies sideways (a 20-row pyramid drifts 5.3 mm from 2 s to 10 s with
    /// friction in both passes, 1.1 mm without; rapier3d's `friction_in_bias_pass` default
    /// is the same). Friction is always solved in the biased pass when `relax_iterations` is
    /// 0, since there is no other. Without it, the first substep's biased pass still keeps each
    /// point's friction impulse, carried from the last step, within μ times the normal impulse
    /// the pass leaves: a warm start whose normal impulse the pass takes back (a box crushed
    /// between walls, one of which passed through it) must not keep its friction.
    pub friction_in_bias_pass: bool,
    /// Start each step from the contact impulses of the previous step (matched by feature
    /// id). Default true. Without it stacks need many more substeps to stand.
    pub warm_start: bool,
    /// Solve each manifold's normal rows together in the relax pass: one small linear system
    /// per manifold (at most 4 × 4, regularised by a tenth of its diagonal, factored once per
    /// step) instead of point after point, so that a face's points share its load as the
    /// system does and not in the order they are solved. Default true. Measured against
    /// point by point (the `jostle` crate's benches/RESULTS.md, "Each manifold's normal rows
    /// solved together, the default"): columns of 5 to 60 boxes of 0.1, 1 and 10 m at μ 0.3,
    /// 0.6 and 0.9, started at rest, all 504 keep every box within 7.3 mm of its start over
    /// 20 s (point by point 437, and columns of 21, 43 and 49 boxes of 10 m fall); 8% more
    /// time per step on the 20-row pyramid. Under gravity, manifolds whose normal lies within
    /// 60° of horizontal (boxes side by side) are packed into batches of their own and solved
    /// point by point: they carry little load, and their block solution pulled in 93% of
    /// them, sending the whole batch back point by point (benches/RESULTS.md, "Manifolds side
    /// by side solved point by point").
    pub block_relax: bool,
    /// Rigid contacts instead of springs. Default false.
    ///
    /// Soft contacts (`contact_hertz`, `static_hertz`) are springs: without load compensation
    /// (`preload_rate`) they sink in proportion to the load they carry (a column of 40 unit
    /// boxes sinks 0.11 m at 8 substeps, 0.43 m at 4 substeps and 30 Hz as in rapier3d; with
    /// it, as by default, 19 mm) and a tall column of them buckles like an elastic one. Rigid contacts have no spring: the biased
    /// pass is the relax pass's rigid row (friction included), and every overlap beyond
    /// `rigid_slop` is pushed out through pseudo velocities at `push_out_rate`, so the sink is
    /// bounded by the slop whatever the load. Measured on the stability family (the `jostle`
    /// crate's benches/RESULTS.md, "Held contact frames and rigid contacts", at 4 substeps):
    /// columns of 40 boxes and a light box under 100 times its mass stand with a sink under
    /// 1 mm per layer; planar pyramids and walls creep more than with soft contacts, and a
    /// step costs two to three times as much.
    pub rigid_contacts: bool,
    /// Overlap (m) that rigid contacts leave alone. Default 0.001. Smaller slops jitter on
    /// contacts that share a load (a box on two supports); larger ones sink further.
    pub rigid_slop: f32,
    /// Fraction of a rigid contact's overlap beyond `rigid_slop` pushed out per substep
    /// (dimensionless, in (0, 1]). Default 0.2.
    pub push_out_rate: f32,
    /// Gauss-Seidel sweeps over a manifold's normal rows per pass with rigid contacts, and in
    /// the biased pass of soft contacts at an impact (a point of the batch approaching faster
    /// than gravity can make it within the step, |g|·dt, at the start of the step, or its
    /// bodies approaching that fast in the substep, or parting that fast under load) (count).
    /// Default 8. The points of a face share their load through the bodies' rotation, and one
    /// sweep leaves most of that coupling unsolved: a column of 40 boxes falls with 4 sweeps
    /// and stands with 8 (rigid contacts), and a unit box landing flat at 50 m/s on soft
    /// contacts left the step at 0.83 m/s sideways with one sweep (0.009 m/s with 8).
    pub normal_sweeps: u32,
    /// Load compensation of soft contacts (fraction per step, in [0, 1]). Default 0.02; 0
    /// turns it off.
    ///
    /// A soft contact settles at its spring's compression under its load, so without it a
    /// column's sink grows with the weight it carries (1.3 mm per layer for 20 unit boxes,
    /// 4.1 mm for 60, 43 mm under a box 1,000 times heavier). With a rate r > 0 every loaded
    /// manifold learns a preload ([`crate::Contact::preload`]), one value for all its points:
    /// at the end of each step in which it is at rest, r times its mean overlap beyond
    /// `preload_target` is added to it (a shortfall of more than half the target takes it
    /// down; within that it is held, so a manifold at rest stops integrating the noise of its
    /// overlap; never below 0, never above its springs' static compression under their
    /// load), and each of its points' springs
    /// acts as if compressed by that much more, growing in over the first `preload_target` of
    /// overlap. A loaded manifold then rests near `preload_target` whatever its load, after a
    /// few seconds. How much the preload may stiffen a spring is bounded by the load it
    /// carries, so that the load riding on it keeps a damping ratio of at least
    /// [`super::PRELOAD_MIN_DAMPING`]: under very heavy loads (1,000 times the supporting
    /// body's mass) it removes only part of the sink. It needs gravity (its bound is stated in
    /// |g|) and does nothing with `rigid_contacts`.
    ///
    /// Measured on the stability family (the `jostle` crate's benches/RESULTS.md, "Load
    /// compensation"): columns of 10 to 60 boxes, pyramids of 20 to 60 rows, walls and a light
    /// box under 100 times its mass sink 0.3–0.8 mm per layer in 20 s (without: up to 4.4 mm).
    /// Rates of 0.01 and 0.05 measured about the same; in 60 s runs the 60-row pyramid creeps
    /// 11 mm with the preload (2.8 mm without).
    pub preload_rate: f32,
    /// Overlap (m) at which load compensation (`preload_rate`) holds a loaded contact.
    /// Default 0.0005.
    pub preload_target: f32,
    /// Largest island (count of contact points) whose rows are solved directly when its
    /// bodies' masses differ widely ([`super::direct`]); a chain of bodies (each touching at
    /// most two others, a column) whose load path (its bodies resting on nothing immovable,
    /// plus one) is at least the step's sweeps (`substeps` × (1 + `relax_iterations`), 16 at
    /// the defaults), or half of them for a chain whose bodies' sizes add up to
    /// [`super::direct::TALL_CHAIN`] (12.5 m) or more, is solved directly, the longest chains
    /// first while together they hold at most [`super::direct::CHAIN_ROWS`] times as many points. Default 64 (chains: 1,024
    /// points, 256 unit boxes); 0 turns the direct solve off; at most
    /// [`SoftStepSettings::MAX_DIRECT_ROWS`]. The cost of a general island grows with the cube
    /// of the count, a chain's linearly with its length.
    pub direct_rows: u32,
    /// Mass ratio (dimensionless, ≥ 1) between two movable bodies in contact from which their
    /// island is solved directly ([`super::direct`]) and its springs are sized by their load.
    /// Default 10.
    pub direct_mass_ratio: f32,
}

impl Default for SoftStepSettings {
    fn default() -> Self {
        Self {
            substeps: 8,
            relax_iterations: 1,
            contact_hertz: 60.0,
            static_hertz: 120.0,
            damping_ratio: 7.0,
            max_push_out: 3.0,
            push_out_slop: 0.005,
            speculative_margin: 0.02,
            restitution_threshold: 1.0,
            restitution_iterations: 64,
            gyroscopic: true,
            friction_in_bias_pass: false,
            warm_start: true,
            block_relax: true,
            rigid_contacts: false,
            rigid_slop: 0.001,
            push_out_rate: 0.2,
            normal_sweeps: 8,
            preload_rate: 0.02,
            preload_target: 0.0005,
            direct_rows: 64,
            direct_mass_ratio: 10.0,
        }
    }
}

impl SoftStepSettings {
    /// The largest accepted `damping_ratio`. The spring's bias rate is ω/(2ζ + hω): at
    /// ζ = 1,000 about a hundredth of Box2D's ζ = 10 (overlap is pushed out about 100 times
    /// slower); larger values only approach a contact that never removes overlap.
    pub const MAX_DAMPING_RATIO: f32 = 1000.0;

    /// The largest accepted `direct_rows`: a dense system of 256 rows costs about 3 million
    /// operations per solve, two solves per substep.
    pub const MAX_DIRECT_ROWS: u32 = 256;

    /// The most `substeps`, `relax_iterations`, `restitution_iterations` and `normal_sweeps`
    /// accepted, and of `substeps` times a substep's sweeps (`normal_sweeps +
    /// relax_iterations`; with rigid contacts `(1 + relax_iterations) × normal_sweeps`):
    /// 1,024 sweeps over a manifold's rows per step, 14 times the defaults' 8 × 9.
    pub const MAX_PASSES: u32 = 1024;

    /// Normal velocity correction (m/s) below which a restitution sweep counts as converged.
    pub const RESTITUTION_TOLERANCE: f32 = 1e-5;

    /// Checks every field: the error is (field, message). The resolver never panics on
    /// invalid settings, but a value that fails here makes its results meaningless, so scene
    /// loading and other front ends should refuse it.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let non_negative = |field: &'static str, x: f32| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err((field, format!("must be finite and >= 0, got {x}")))
            }
        };
        if self.substeps == 0 {
            return Err(("substeps", "must be >= 1, got 0".into()));
        }
        // Each of these runs that many passes over every contact each step: a snapshot's
        // `substeps: 4294967295` never finished its first step.
        for (field, count) in [
            ("substeps", self.substeps),
            ("relax_iterations", self.relax_iterations),
            ("restitution_iterations", self.restitution_iterations),
            ("normal_sweeps", self.normal_sweeps),
        ] {
            if count > Self::MAX_PASSES {
                return Err((
                    field,
                    format!("must be <= {}, got {count}", Self::MAX_PASSES),
                ));
            }
        }
        // And together: each substep runs the biased pass (up to `normal_sweeps` sweeps of a
        // manifold's normal rows at an impact) and the relax passes, each of which sweeps them
        // `normal_sweeps` times with rigid contacts; `substeps: 1024` with
        // `relax_iterations: 1024` took 47 s for one step of a 210-box pyramid.
        let per_substep = if self.rigid_contacts {
            (1 + self.relax_iterations).saturating_mul(self.normal_sweeps)
        } else {
            self.normal_sweeps.saturating_add(self.relax_iterations)
        };
        let passes = u64::from(self.substeps) * u64::from(per_substep);
        if passes > u64::from(Self::MAX_PASSES) {
            return Err((
                "substeps",
                format!(
                    "substeps × the sweeps of a substep (normal_sweeps + relax_iterations; with \
                     rigid contacts (1 + relax_iterations) × normal_sweeps) must be <= {}, got \
                     {} × {per_substep} = {passes}",
                    Self::MAX_PASSES,
                    self.substeps
                ),
            ));
        }
        // A 0 Hz contact has no stiffness at all: bodies sink into each other for good.
        let positive = |field: &'static str, x: f32| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err((field, format!("must be finite and > 0, got {x}")))
            }
        };
        positive("contact_hertz", self.contact_hertz)?;
        positive("static_hertz", self.static_hertz)?;
        non_negative("damping_ratio", self.damping_ratio)?;
        if self.damping_ratio > Self::MAX_DAMPING_RATIO {
            return Err((
                "damping_ratio",
                format!(
                    "must be <= {}, got {}",
                    Self::MAX_DAMPING_RATIO,
                    self.damping_ratio
                ),
            ));
        }
        non_negative("max_push_out", self.max_push_out)?;
        non_negative("push_out_slop", self.push_out_slop)?;
        non_negative("speculative_margin", self.speculative_margin)?;
        non_negative("rigid_slop", self.rigid_slop)?;
        if !(self.push_out_rate > 0.0 && self.push_out_rate <= 1.0) {
            return Err((
                "push_out_rate",
                format!("must be in (0, 1], got {}", self.push_out_rate),
            ));
        }
        if !(self.preload_rate >= 0.0 && self.preload_rate <= 1.0) {
            return Err((
                "preload_rate",
                format!("must be in [0, 1], got {}", self.preload_rate),
            ));
        }
        non_negative("preload_target", self.preload_target)?;
        if self.direct_rows > Self::MAX_DIRECT_ROWS {
            return Err((
                "direct_rows",
                format!(
                    "must be <= {}, got {}",
                    Self::MAX_DIRECT_ROWS,
                    self.direct_rows
                ),
            ));
        }
        if !(self.direct_mass_ratio >= 1.0 && self.direct_mass_ratio.is_finite()) {
            return Err((
                "direct_mass_ratio",
                format!("must be finite and >= 1, got {}", self.direct_mass_ratio),
            ));
        }
        if self.normal_sweeps == 0 {
            return Err(("normal_sweeps", "must be >= 1, got 0".into()));
        }
        non_negative("restitution_threshold", self.restitution_threshold)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_field() {
        assert_eq!(SoftStepSettings::default().validate(), Ok(()));
        let d = SoftStepSettings::default;
        let cases = [
            (
                SoftStepSettings {
                    contact_hertz: f32::NAN,
                    ..d()
                },
                "contact_hertz",
            ),
            (
                SoftStepSettings {
                    static_hertz: 0.0,
                    ..d()
                },
                "static_hertz",
            ),
            (SoftStepSettings { substeps: 0, ..d() }, "substeps"),
            (
                SoftStepSettings {
                    push_out_rate: 0.0,
                    ..d()
                },
                "push_out_rate",
            ),
            (
                SoftStepSettings {
                    normal_sweeps: 0,
                    ..d()
                },
                "normal_sweeps",
            ),
            (
                SoftStepSettings {
                    preload_rate: 1.5,
                    ..d()
                },
                "preload_rate",
            ),
            (
                SoftStepSettings {
                    preload_target: f32::NAN,
                    ..d()
                },
                "preload_target",
            ),
            (
                SoftStepSettings {
                    damping_ratio: 1e30,
                    ..d()
                },
                "damping_ratio",
            ),
            (
                SoftStepSettings {
                    direct_rows: SoftStepSettings::MAX_DIRECT_ROWS + 1,
                    ..d()
                },
                "direct_rows",
            ),
            (
                SoftStepSettings {
                    direct_mass_ratio: 0.5,
                    ..d()
                },
                "direct_mass_ratio",
            ),
            (
                SoftStepSettings {
                    direct_mass_ratio: f32::INFINITY,
                    ..d()
                },
                "direct_mass_ratio",
            ),
            // Each count within its bound, their product not.
            (
                SoftStepSettings {
                    substeps: 1024,
                    relax_iterations: 1024,
                    ..d()
                },
                "substeps",
            ),
            (
                SoftStepSettings {
                    substeps: 256,
                    normal_sweeps: 8,
                    ..d()
                },
                "substeps",
            ),
            (
                SoftStepSettings {
                    substeps: 1,
                    relax_iterations: 1023,
                    normal_sweeps: 1024,
                    rigid_contacts: true,
                    ..d()
                },
                "substeps",
            ),
        ];
        for (bad, field) in cases {
            assert_eq!(bad.validate().unwrap_err().0, field);
        }
    }
}
