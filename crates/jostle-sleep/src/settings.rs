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
        }
    }
}
