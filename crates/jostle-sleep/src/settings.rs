//! Sleep settings.

/// How bodies go to sleep. Plain settings; every field's unit and default is documented.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct SleepSettings {
    /// Whether islands may sleep at all. Default true. Disabling it is for benchmarks and
    /// debugging: every body is then simulated every step.
    pub enabled: bool,
    /// Sleep threshold ε on the motion average |v|² + |ω|² (m²/s², rad²/s² counted alike).
    /// Default 0.3, the value of Millington's Cyclone. A body qualifies for sleep when its
    /// motion is below ε; its motion is capped at 10·ε and set to 2·ε when it wakes.
    pub threshold: f32,
    /// Base of the recency bias: per step, bias = `bias_base`^dt, and
    /// motion ← bias·motion + (1 − bias)·(|v|² + |ω|²). Default 0.5 (motion halves its weight
    /// every second of simulated time), as in Cyclone.
    pub bias_base: f32,
    /// Threshold (m²/s²) on the mean motion |v̄|² + r²·|ω̄|², v̄ and ω̄ the velocities averaged
    /// with the same recency bias and r the body's radius of gyration (the mean turn as the
    /// speed it gives the body's mass), and on the present |v|²: a body qualifies for sleep
    /// only when both are below it as well. Default 0.0025 (0.05 m/s).
    /// The motion average alone let a body moving steadily below √ε (0.55 m/s) fall asleep
    /// and stop: a ball gliding at 0.3 m/s in zero gravity, a box sliding down a slope steeper
    /// than its friction angle, a box on a moving belt. A body at rest jitters about its
    /// place, slowly, and its velocities average away. A body speeding up from rest at less
    /// than about 0.05 m/s² still qualifies once its motion has decayed (1 s after it was
    /// added or woken) and is stopped. Each mean is capped at ten times this (as the motion is
    /// at 10·ε), so that a fall is forgotten within about 2 s of the landing.
    pub drift_threshold: f32,
}

impl SleepSettings {
    /// Checks the fields: the error is (field, message). A threshold of −1 put every body to
    /// sleep at its first step; a NaN one kept all awake.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if !(self.threshold.is_finite() && self.threshold > 0.0) {
            return Err((
                "threshold",
                format!("must be finite and > 0, got {}", self.threshold),
            ));
        }
        if !(self.drift_threshold.is_finite() && self.drift_threshold > 0.0) {
            return Err((
                "drift_threshold",
                format!("must be finite and > 0, got {}", self.drift_threshold),
            ));
        }
        if !(self.bias_base.is_finite() && self.bias_base > 0.0 && self.bias_base < 1.0) {
            return Err((
                "bias_base",
                format!("must be in (0, 1), got {}", self.bias_base),
            ));
        }
        Ok(())
    }
}

impl Default for SleepSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            threshold: 0.3,
            bias_base: 0.5,
            drift_threshold: 0.0025,
        }
    }
}
