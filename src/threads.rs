//! The narrow phase's pairs on the soft step's threads ([`jostle_resolve::soft_step::team`]):
//! a [`Runner`] that splits a large update into one part per thread and runs the parts as
//! one stage of a team. The parts write their own lists, joined in order afterwards
//! ([`jostle_collide::NarrowPhase::update_with`]), so a step's results are bit for bit the
//! same for any number of threads.
//!
//! It splits only while the resolver's substeps run on the team (the last step's
//! [`jostle_resolve::ResolveStats::threads`]): the helper threads then poll between the
//! steps' jobs anyway. Started for the narrow phase alone, a helper polling after its part
//! slowed the calling thread's own stages: `assets/piles_1000.ron` (1,000 pairs, its resolver
//! on one thread) took 1.16–1.29 ms a step with the split against 0.86–0.88 without, on a
//! two-core virtual machine (benches/RESULTS.md, "The narrow phase on both cores").

use jostle_collide::{MAX_PARTS, Runner};
use jostle_resolve::soft_step::team::{self, Crew, MAX_THREADS, Parts, Team};
use std::sync::Mutex;

/// Fewest candidate pairs for which an update is split between threads: below, a part is
/// over before a helper thread would join.
pub(crate) const PARALLEL_MIN_PAIRS: usize = 256;

/// Runs the narrow phase's parts on a team of the process's helper threads.
#[derive(Debug, Default)]
pub(crate) struct TeamRunner {
    team: Mutex<Team>,
    /// Whether to split at all: the resolver's last substeps ran on the team.
    active: bool,
}

impl TeamRunner {
    /// Splits the following updates only if `resolver_threads`, the threads the resolver's
    /// last step ran on, is more than one.
    pub(crate) fn follow(&mut self, resolver_threads: u32) {
        self.active = resolver_threads > 1;
    }
}

impl Runner for TeamRunner {
    fn parts(&self, pairs: usize) -> usize {
        if !self.active || pairs < PARALLEL_MIN_PAIRS {
            1
        } else {
            team::available_threads().min(MAX_PARTS)
        }
    }

    fn run(&self, n: usize, f: &(dyn Fn(usize) + Sync)) {
        let threads = team::available_threads().min(n).max(1);
        if threads == 1 {
            (0..n).for_each(f);
            return;
        }
        let items = n as u32;
        // One stage: thread t's part starts at item t·n/threads.
        let mut parts: Parts = [items; MAX_THREADS + 1];
        for (t, start) in parts.iter_mut().enumerate().take(threads) {
            *start = (t * n / threads) as u32;
        }
        let mut team = self.team.lock().unwrap_or_else(|e| e.into_inner());
        team.reset(threads, &[parts]);
        team::run(&team, |member| {
            member.stage(items, |i| f(i as usize));
        });
    }
}
