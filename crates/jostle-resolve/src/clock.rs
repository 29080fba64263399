//! The wall clock behind the step profile, and behind the soft step's choice between one thread
//! and the team: a [`Stopwatch`] that reads `std::time::Instant` where the platform has a
//! clock and reads nothing where it has none (`wasm32-unknown-unknown`, whose `Instant::now`
//! panics), so that stepping a world never depends on a clock.
//!
//! Without a clock every elapsed time is zero: the profile's stage times read 0 and nothing
//! else changes, since no result depends on a time ([`HAS_CLOCK`]). The clockless build can be
//! checked on any platform with `RUSTFLAGS="--cfg jostle_no_clock"`.

use std::time::Duration;

/// Whether this build reads a wall clock. `false` on `wasm32-unknown-unknown` (and with
/// `--cfg jostle_no_clock`): then every [`Stopwatch::elapsed`] is zero.
pub const HAS_CLOCK: bool = cfg!(not(any(
    jostle_no_clock,
    all(target_family = "wasm", target_os = "unknown")
)));

/// A started wall clock; [`Stopwatch::elapsed`] is the time since [`Stopwatch::start`], or
/// zero without a clock ([`HAS_CLOCK`]).
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch {
    #[cfg(not(any(jostle_no_clock, all(target_family = "wasm", target_os = "unknown"))))]
    start: std::time::Instant,
}

impl Stopwatch {
    /// Starts a stopwatch now.
    #[inline]
    #[must_use]
    pub fn start() -> Self {
        Self {
            #[cfg(not(any(jostle_no_clock, all(target_family = "wasm", target_os = "unknown"))))]
            start: std::time::Instant::now(),
        }
    }

    /// The wall time since [`Stopwatch::start`]; zero without a clock.
    #[inline]
    #[must_use]
    pub fn elapsed(&self) -> Duration {
        #[cfg(not(any(jostle_no_clock, all(target_family = "wasm", target_os = "unknown"))))]
        {
            self.start.elapsed()
        }
        #[cfg(any(jostle_no_clock, all(target_family = "wasm", target_os = "unknown")))]
        {
            Duration::ZERO
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stopwatch_reads_the_clock_only_where_there_is_one() {
        let watch = Stopwatch::start();
        let mut x = 0u64;
        for i in 0..200_000u64 {
            x = std::hint::black_box(x.wrapping_add(i));
        }
        std::thread::sleep(Duration::from_millis(2));
        let elapsed = watch.elapsed();
        if HAS_CLOCK {
            assert!(elapsed >= Duration::from_millis(2), "{elapsed:?}");
        } else {
            assert_eq!(elapsed, Duration::ZERO);
        }
    }
}
