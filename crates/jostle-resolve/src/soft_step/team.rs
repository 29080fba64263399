//! Several threads through the substeps of one soft step (and through the preparation of its
//! batches before them), with results independent of how many take part.
//!
//! A step's substeps are a fixed sequence of *stages* (its preparation is one stage per
//! colour): integrate the velocities, warm start colour by colour, the biased pass colour by
//! colour, the direct solve, integrate the positions, relax colour by colour. A stage is a number of *items* (a few batches of one
//! colour, or a run of bodies) that write disjoint data, so they may run in any order and on
//! any thread with the same result, bit for bit; a stage starts only when the one before has
//! finished (in a flow, below, an item starts when the items it depends on have). Every thread
//! of the team runs the same sequence ([`Crew::stage`]):
//! - each stage's items are split into one contiguous part per thread, of equal counts
//!   ([`Plan`]); the soft step orders each colour's batches by the bodies they write, so a
//!   thread's part of every colour touches about the same bodies, and their states stay in
//!   its core's cache;
//! - items are claimed through an atomic counter per part; a thread runs its own part, then
//!   the parts of threads that have not reached the stage yet, and then waits only for items
//!   that a running thread has claimed (in a flow it does not wait at the stage's end at all).
//!   A thread that starts late, or never, holds nothing up: the others take its part. So the
//!   team cannot deadlock, however many helpers join.
//!
//! The substeps' team runs as a *flow* once a step's batches are laid out as the step before's
//! ([`Team::reset_flowing`]): a stage whose items list the bodies they touch
//! ([`Crew::stage_on_bodies`]) no longer waits for the whole stage before it; each item waits
//! only for the items of earlier stages that last touched its bodies (a flag per item), so a
//! thread whose part of a colour touches none of the other thread's bodies goes straight on
//! to its part of the next. The odd threads run their parts from the end, so the items
//! next to another thread's part, the ones that wait for it, come last. The results do not
//! change: every item still sees what every earlier item on its bodies wrote, and nothing
//! else. On the 20-row pyramid on two cores the step went from 0.379 to 0.366 ms
//! (benches/RESULTS.md, "Items that wait only for their bodies").
//!
//! The helpers are threads of the process, started on first use, that poll for [`POLL_MICROS`] after
//! each step before they park: on the two-core virtual machine of benches/RESULTS.md,
//! starting a rayon job that wakes a sleeping worker cost the caller 13–45 µs and the
//! worker joined 20–60 µs later, every step (rayon's workers sleep between steps as short as
//! the narrow phase); a polling helper joins within a microsecond. One world steps on them
//! at a time; a world whose step finds them busy runs alone.
//!
//! Box2D v3 runs its solver stages the same way (`solver.c`, "stages" and "blocks", with a
//! worker's own blocks first); this is written from that description.
//!
//! [`Solo`] is the same sequence on the calling thread alone, each stage's items in order; a
//! [`Plan`] records the stages without running them, which is how the team learns the
//! sequence before it starts.

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};

/// Most threads a team uses.
pub const MAX_THREADS: usize = 8;

/// Something that runs the stages of the substeps: [`Plan`], [`Solo`] or a [`Member`] of a
/// [`Team`].
pub trait Crew {
    /// Runs `f(i)` for every item `i` in `0..items`, each once, in any order and on any
    /// thread of the crew, and returns when all have finished (their writes visible to this
    /// thread). Every thread of a crew makes the same calls in the same order.
    fn stage(&self, items: u32, f: impl FnMut(u32));

    /// [`Crew::stage`] for a stage whose items share data with the items of other stages only
    /// through bodies: `touches(i, push)` pushes every body whose data item `i` reads or
    /// writes, and any two items of different stages that share any datum both push some
    /// body they share (the points of a batch are shared by its items of the biased and the
    /// relax pass, which push the batch's bodies); no two items of the stage push the same
    /// body. On a team prepared for it ([`Team::reset_flowing`]) an item then waits only for
    /// the items before it that touch its bodies, not for the whole stage before, and the call
    /// returns when this thread's items have finished, not all of them: code between two such
    /// stages must not read what their items write (a [`Crew::stage`] waits for everything
    /// before it, and [`Member::finish`] for everything). The results are the same, bit for
    /// bit.
    fn stage_on_bodies(
        &self,
        items: u32,
        touches: impl Fn(u32, &mut dyn FnMut(u32)),
        f: impl FnMut(u32),
    ) {
        let _ = touches;
        self.stage(items, f);
    }
}

/// Where each thread's part of a stage's items starts; entry `threads` is the item count.
pub type Parts = [u32; MAX_THREADS + 1];

/// Records each stage's parts and runs nothing: thread t of `threads` gets the items from
/// ⌈t·items/threads⌉ on (the first threads take the larger shares, so a stage of one item,
/// the direct solve, is the calling thread's). Split by count, every stage is shared evenly; split instead where the
/// bodies the items write cross fixed bounds (one range of bodies per thread, the same in
/// every stage), a colour's batches were shared unevenly and the stage waited for the
/// thread with more (the 3D pyramid of 10 layers on a team of two: the larger parts summed
/// over a step's stages were 1,887 items where even shares give 1,581, and its resolve stage
/// took 1.25 ms against 1.19 split by count; benches/RESULTS.md, "The batches prepared by the
/// threads that solve them").
#[derive(Debug, Default)]
pub struct Plan {
    /// Threads of the team (1 to [`MAX_THREADS`]).
    pub threads: usize,
    /// The parts of each stage, in order.
    pub stages: RefCell<Vec<Parts>>,
    /// When present, the bodies each item touches are recorded here
    /// ([`Crew::stage_on_bodies`]; [`Team::reset_flowing`]).
    pub touches: Option<RefCell<Touches>>,
}

impl Crew for Plan {
    fn stage(&self, items: u32, _f: impl FnMut(u32)) {
        let threads = self.threads.clamp(1, MAX_THREADS) as u64;
        let mut parts = [items; MAX_THREADS + 1];
        for (t, part) in parts.iter_mut().enumerate().take(threads as usize) {
            *part = (t as u64 * u64::from(items)).div_ceil(threads) as u32;
        }
        self.stages.borrow_mut().push(parts);
        if let Some(touches) = &self.touches {
            touches.borrow_mut().listed.push(false);
        }
    }

    fn stage_on_bodies(
        &self,
        items: u32,
        touches: impl Fn(u32, &mut dyn FnMut(u32)),
        f: impl FnMut(u32),
    ) {
        self.stage(items, f);
        if let Some(record) = &self.touches {
            let record = &mut *record.borrow_mut();
            if let Some(listed) = record.listed.last_mut() {
                *listed = true;
            }
            for i in 0..items {
                touches(i, &mut |body| record.bodies.push(body));
                record.ends.push(record.bodies.len() as u32);
            }
        }
    }
}

/// The bodies the items of a [`Plan`]'s stages touch ([`Crew::stage_on_bodies`]).
#[derive(Debug, Default)]
pub struct Touches {
    /// Per stage: whether its items listed their bodies.
    pub listed: Vec<bool>,
    /// Per item of a listed stage, in order: where its bodies end in `bodies`.
    pub ends: Vec<u32>,
    /// The bodies of those items, item after item.
    pub bodies: Vec<u32>,
}

impl Touches {
    /// Empties the record, keeping its storage.
    pub fn clear(&mut self) {
        self.listed.clear();
        self.ends.clear();
        self.bodies.clear();
    }
}

/// The calling thread alone, every item in order.
#[derive(Debug, Default)]
pub struct Solo;

impl Crew for Solo {
    #[inline]
    fn stage(&self, items: u32, mut f: impl FnMut(u32)) {
        for i in 0..items {
            f(i);
        }
    }
}

/// An atomic counter alone on its cache line, so that threads claiming from their own parts
/// do not contend.
#[derive(Debug, Default)]
#[repr(align(64))]
struct Counter(AtomicU32);

/// One stage's counters: the next unclaimed item of each thread's part, and how many items
/// have finished.
#[derive(Debug, Default)]
struct Slot {
    next: [Counter; MAX_THREADS],
    done: Counter,
}

/// The shared state of a team: counters per stage of the planned sequence.
#[derive(Debug, Default)]
pub struct Team {
    slots: Vec<Slot>,
    /// Per thread: the stages it has entered. A thread helps only with the parts of threads
    /// that have not entered the stage yet: taking items from a thread that is working on
    /// its part would move that part's batches, and their points, to another core's cache.
    entered: [Counter; MAX_THREADS],
    parts: Vec<Parts>,
    threads: usize,
    /// Set when a member panicked: the others leave their stages.
    poisoned: std::sync::atomic::AtomicBool,
    /// Which items wait for which ([`Team::reset_flowing`]).
    flow: Flow,
}

/// The items of the stages listed by body ([`Crew::stage_on_bodies`]) and, for each, the
/// items before it that it waits for: for each body it touches, the last item that touched
/// that body (since the last stage that is not listed, which every thread waits out whole).
/// An item marks itself done by writing the step's `epoch` into its flag.
#[derive(Debug, Default)]
struct Flow {
    /// Whether the team runs its listed stages this way.
    active: bool,
    /// Per stage: the index of its first item in `flag_of` and `waits`, or [`NOT_LISTED`].
    first: Vec<u32>,
    /// Per listed item: its flag.
    flag_of: Vec<u32>,
    /// Per listed item: where the flags it waits for end in `deps`.
    waits: Vec<u32>,
    /// Flags waited for.
    deps: Vec<u32>,
    /// Per listed item, its flag: the epoch of the step in which it last finished. Each
    /// part of a stage starts a cache line of its own, so that two threads finishing items
    /// do not write one line.
    flags: Vec<FlagLine>,
    /// This step's mark (never 0, the flags' first value).
    epoch: u32,
}

/// [`Flow::first`] of a stage whose items did not list their bodies.
const NOT_LISTED: u32 = u32::MAX;

/// Flags per cache line ([`Flow::flags`]).
const FLAGS_PER_LINE: u32 = 16;

/// A cache line of flags ([`Flow::flags`]).
#[derive(Debug, Default)]
#[repr(align(64))]
struct FlagLine([AtomicU32; FLAGS_PER_LINE as usize]);

impl Flow {
    /// Flag `f`.
    fn flag(&self, f: u32) -> &AtomicU32 {
        &self.flags[(f / FLAGS_PER_LINE) as usize].0[(f % FLAGS_PER_LINE) as usize]
    }

    /// Rebuilds the waits for the stages of `plan`, whose bodies `touches` lists, on a team
    /// of `threads`.
    fn build(&mut self, plan: &[Parts], touches: &Touches, threads: usize) {
        self.first.clear();
        self.flag_of.clear();
        self.waits.clear();
        self.deps.clear();
        let bodies = touches.bodies.iter().max().map_or(0, |&b| b as usize + 1);
        // Per body: the flag of the last listed item that touched it.
        let mut last = vec![u32::MAX; bodies];
        let mut flags = 0u32;
        let mut item_end = 0usize;
        let mut body_start = 0usize;
        let mut found: Vec<u32> = Vec::new();
        for (k, parts) in plan.iter().enumerate() {
            if !touches.listed.get(k).copied().unwrap_or(false) {
                self.first.push(NOT_LISTED);
                // Every thread waits for the whole of such a stage (and all before it).
                last.fill(u32::MAX);
                continue;
            }
            self.first.push(self.flag_of.len() as u32);
            let items = parts[MAX_THREADS];
            let stage_start = self.flag_of.len();
            for t in 0..threads.clamp(1, MAX_THREADS) {
                let (from, to) = (parts[t], parts[t + 1].min(items));
                flags = flags.next_multiple_of(FLAGS_PER_LINE);
                for _ in from..to {
                    self.flag_of.push(flags);
                    flags += 1;
                }
            }
            debug_assert_eq!(self.flag_of.len() - stage_start, items as usize);
            let stage_bodies = body_start;
            for i in 0..items as usize {
                let end = touches.ends[item_end + i] as usize;
                found.clear();
                found.extend(
                    touches.bodies[body_start..end]
                        .iter()
                        .map(|&b| last[b as usize])
                        .filter(|&f| f != u32::MAX),
                );
                found.sort_unstable();
                found.dedup();
                self.deps.extend_from_slice(&found);
                self.waits.push(self.deps.len() as u32);
                body_start = end;
            }
            // Then the stage's items become the last to touch their bodies (items of one
            // stage never wait for each other, so none may touch a body another touches: a
            // later item would wait for only one of them).
            #[cfg(debug_assertions)]
            {
                let mut seen: Vec<u32> = touches.bodies[stage_bodies..body_start].to_vec();
                seen.sort_unstable();
                let before = seen.len();
                seen.dedup();
                debug_assert_eq!(seen.len(), before, "stage {k}: two items touch one body");
            }
            let mut start = stage_bodies;
            for i in 0..items as usize {
                let end = touches.ends[item_end + i] as usize;
                for &b in &touches.bodies[start..end] {
                    last[b as usize] = self.flag_of[stage_start + i];
                }
                start = end;
            }
            item_end += items as usize;
        }
        let lines = flags.div_ceil(FLAGS_PER_LINE) as usize;
        if self.flags.len() < lines {
            self.flags.resize_with(lines, FlagLine::default);
        }
        self.active = true;
    }
}

impl Team {
    /// Prepares the team of `threads` (1 to [`MAX_THREADS`]) for the stages of `plan`
    /// (each stage's parts, in order, as [`Plan`] records them for `threads`); every stage
    /// waits for the whole stage before it.
    pub fn reset(&mut self, threads: usize, plan: &[Parts]) {
        self.flow.active = false;
        self.reset_counters(threads, plan);
    }

    /// [`Team::reset`], with the stages listed by body ([`Crew::stage_on_bodies`]) run so
    /// that an item waits only for the items before it that touch its bodies: with
    /// `touches` (recorded by a [`Plan`] for the same stages and threads), the waits are
    /// worked out afresh; without, the last ones are kept, which the caller may ask for only
    /// when `plan` and the bodies every item touches are those of the last call that had
    /// `touches`.
    pub fn reset_flowing(&mut self, threads: usize, plan: &[Parts], touches: Option<&Touches>) {
        match touches {
            Some(touches) => self
                .flow
                .build(plan, touches, threads.clamp(1, MAX_THREADS)),
            None => {
                debug_assert!(self.flow.active && self.flow.first.len() == plan.len());
            }
        }
        if self.flow.epoch == u32::MAX {
            // Every flag back to 0, below every epoch to come: no flag left from an earlier
            // round of epochs can read as finished.
            for line in &mut self.flow.flags {
                for flag in &mut line.0 {
                    *flag.get_mut() = 0;
                }
            }
            self.flow.epoch = 0;
        }
        self.flow.epoch += 1;
        self.reset_counters(threads, plan);
    }

    fn reset_counters(&mut self, threads: usize, plan: &[Parts]) {
        debug_assert!((1..=MAX_THREADS).contains(&threads));
        self.threads = threads.clamp(1, MAX_THREADS);
        self.parts.clear();
        self.parts.extend_from_slice(plan);
        for parts in &mut self.parts {
            // Parts past the team's threads are empty.
            let items = parts[MAX_THREADS];
            for p in &mut parts[self.threads..] {
                *p = items;
            }
        }
        if self.slots.len() < plan.len() {
            self.slots.resize_with(plan.len(), Slot::default);
        }
        for (slot, parts) in self.slots.iter_mut().zip(&self.parts) {
            for (t, next) in slot.next.iter_mut().enumerate().take(self.threads) {
                *next.0.get_mut() = parts[t];
            }
            *slot.done.0.get_mut() = 0;
        }
        for entered in &mut self.entered {
            *entered.0.get_mut() = 0;
        }
        *self.poisoned.get_mut() = false;
    }

    /// Thread `id`'s view of the team (`id` below the threads it was reset for).
    pub fn member(&self, id: usize) -> Member<'_> {
        debug_assert!(id < self.threads);
        Member {
            team: self,
            id,
            stage: Cell::new(0),
            settled: Cell::new(0),
        }
    }
}

/// A clone is a new team, to be reset before use (a team holds no results).
impl Clone for Team {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// Spins before a waiting thread starts yielding its core (about a microsecond of spinning:
/// a stage usually ends sooner, and on a busy machine the thread being waited for may need
/// the core).
const SPINS_BEFORE_YIELD: u32 = 256;

/// One thread of a [`Team`].
#[derive(Debug)]
pub struct Member<'t> {
    team: &'t Team,
    id: usize,
    stage: Cell<usize>,
    /// Stages this thread has seen finished, every one of them.
    settled: Cell<usize>,
}

impl Member<'_> {
    /// This thread's index in the team (0 for the thread that called [`run`]).
    pub fn id(&self) -> usize {
        self.id
    }

    /// Waits until every stage before stage `k` has finished.
    fn settle(&self, k: usize) {
        let team = self.team;
        for j in self.settled.get()..k {
            let items = team.parts[j][MAX_THREADS];
            let done = &team.slots[j].done.0;
            let mut spins = 0u32;
            // Acquire: every item's writes are visible once all are counted.
            while done.load(Ordering::Acquire) < items {
                if team.poisoned.load(Ordering::Relaxed) {
                    return;
                }
                pause(&mut spins);
            }
        }
        self.settled.set(self.settled.get().max(k));
    }

    /// Waits until every stage has finished: the calling thread then sees every item's
    /// writes.
    pub fn finish(&self) {
        self.settle(self.team.parts.len());
    }

    /// Claims and runs items of `part` of the stage until none is left; returns how many
    /// this thread ran.
    fn run_part(&self, slot: &Slot, parts: &Parts, part: usize, f: &mut impl FnMut(u32)) -> u32 {
        let end = parts[part + 1];
        let mut ran = 0;
        loop {
            // Relaxed: the claim only has to be unique; the data an item reads was published
            // by the wait that ended the stage before (in a flow, by the flags it waits for).
            let i = slot.next[part].0.fetch_add(1, Ordering::Relaxed);
            if i >= end {
                return ran;
            }
            // The odd parts run from their end: next to a part before, a part's first items
            // touch the bodies whose last items that part touches, and in a flow
            // ([`Team::reset_flowing`]) they would wait for that part's last items.
            let i = if part % 2 == 1 {
                end - 1 - (i - parts[part])
            } else {
                i
            };
            f(i);
            ran += 1;
        }
    }
}

impl Crew for Member<'_> {
    fn stage(&self, items: u32, mut f: impl FnMut(u32)) {
        let k = self.stage.get();
        self.stage.set(k + 1);
        let team = self.team;
        if team.poisoned.load(Ordering::Relaxed) {
            return;
        }
        // The stages before may have run as a flow, each item waiting only for its own.
        self.settle(k);
        let parts = &team.parts[k];
        debug_assert_eq!(parts[MAX_THREADS], items, "stage {k} differs from the plan");
        let slot = &team.slots[k];
        team.entered[self.id]
            .0
            .store(k as u32 + 1, Ordering::SeqCst);
        let mut ran = 0;
        ran += self.run_part(slot, parts, self.id, &mut f);
        for j in 1..team.threads {
            let other = (self.id + j) % team.threads;
            // Sequentially consistent with the owner's entry above: either the owner sees
            // its counter advanced by this claim, or this thread sees it has entered, and
            // then the owner runs every item it has not claimed.
            if team.entered[other].0.load(Ordering::SeqCst) <= k as u32 {
                ran += self.run_part(slot, parts, other, &mut f);
            }
        }
        if ran > 0 {
            // Release: publishes this thread's writes to whoever sees the count complete.
            slot.done.0.fetch_add(ran, Ordering::Release);
        }
        let mut spins = 0u32;
        // Acquire: every item's writes are visible once all are counted.
        while slot.done.0.load(Ordering::Acquire) < items {
            if team.poisoned.load(Ordering::Relaxed) {
                return;
            }
            pause(&mut spins);
        }
        self.settled.set(k + 1);
    }

    fn stage_on_bodies(
        &self,
        items: u32,
        touches: impl Fn(u32, &mut dyn FnMut(u32)),
        mut f: impl FnMut(u32),
    ) {
        let team = self.team;
        let flow = &team.flow;
        let k = self.stage.get();
        let first = if flow.active {
            flow.first.get(k).copied().unwrap_or(NOT_LISTED)
        } else {
            NOT_LISTED
        };
        if first == NOT_LISTED {
            return self.stage(items, f);
        }
        let _ = touches;
        self.stage.set(k + 1);
        if team.poisoned.load(Ordering::Relaxed) {
            return;
        }
        let parts = &team.parts[k];
        debug_assert_eq!(parts[MAX_THREADS], items, "stage {k} differs from the plan");
        let slot = &team.slots[k];
        let epoch = flow.epoch;
        let mut item = |i: u32| {
            let n = (first + i) as usize;
            let from = if n == 0 {
                0
            } else {
                flow.waits[n - 1] as usize
            };
            for &d in &flow.deps[from..flow.waits[n] as usize] {
                let flag = flow.flag(d);
                let mut spins = 0u32;
                // Acquire: the writes of the item waited for (and of those it waited for).
                while flag.load(Ordering::Acquire) != epoch {
                    if team.poisoned.load(Ordering::Relaxed) {
                        return;
                    }
                    pause(&mut spins);
                }
            }
            f(i);
            // Release: publishes the item's writes to whoever sees the flag.
            flow.flag(flow.flag_of[n]).store(epoch, Ordering::Release);
        };
        // Entry, own part, help and count as in `stage`, written out again: folded into one
        // function for both, the build placed the AVX-512 kernels elsewhere and the 20-row
        // pyramid on one thread took 6% longer at the same instruction count (callgrind).
        team.entered[self.id]
            .0
            .store(k as u32 + 1, Ordering::SeqCst);
        let mut ran = self.run_part(slot, parts, self.id, &mut item);
        for j in 1..team.threads {
            let other = (self.id + j) % team.threads;
            // As in `stage`.
            if team.entered[other].0.load(Ordering::SeqCst) <= k as u32 {
                ran += self.run_part(slot, parts, other, &mut item);
            }
        }
        if ran > 0 {
            // Release: for the threads that wait for the whole stage (`settle`).
            slot.done.0.fetch_add(ran, Ordering::Release);
        }
    }
}

/// One round of waiting: a spin, or once [`SPINS_BEFORE_YIELD`] have passed, a yield of the
/// core.
#[inline]
fn pause(spins: &mut u32) {
    if *spins < SPINS_BEFORE_YIELD {
        *spins += 1;
        std::hint::spin_loop();
    } else {
        std::thread::yield_now();
    }
}

/// Runs `work(member)` on the calling thread (member 0) and up to the team's threads − 1
/// helper threads, each with its [`Member`] of `team`, which must have been reset for
/// the plan of `work`. Helpers that are busy or asleep join late or not at all; the calling
/// thread then does their items ([`Crew::stage`]). Returns when every member that started
/// has finished.
///
/// # Panics
/// When `work` panics on any thread, the team is poisoned: every member leaves its stages
/// at once (the others would wait forever for the items the panicking one claimed), and
/// this function panics on the calling thread once no helper is inside `work` any more.
pub fn run<W>(team: &Team, work: W)
where
    W: Fn(&Member<'_>) + Sync,
{
    if team.threads > 1
        && let Some(helpers) = Helpers::get()
        // One job at a time: a team that finds the helpers busy with another world's step
        // (another thread's) runs alone, which its stages allow.
        && let Ok(_busy) = helpers.busy.try_lock()
    {
        let job = |id: usize| {
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let member = team.member(id);
                work(&member);
                if id == 0 {
                    // The caller reads the results: every item, whoever ran it, has finished.
                    member.finish();
                }
            }));
            if let Err(panic) = result {
                team.poisoned.store(true, Ordering::SeqCst);
                if id == 0 {
                    std::panic::resume_unwind(panic);
                }
            }
        };
        helpers.run(team.threads, &job);
        assert!(
            !team.poisoned.load(Ordering::SeqCst),
            "a soft-step stage panicked on a helper thread"
        );
        return;
    }
    let member = team.member(0);
    work(&member);
    member.finish();
}

/// Threads a step's team uses: [`set_threads`]' number if one was set, else the environment
/// variable `JOSTLE_THREADS` if it holds a positive number, else the CPU's available
/// parallelism; 1 without the `parallel` feature or on `wasm32-unknown-unknown` (which
/// cannot start threads); at most [`MAX_THREADS`].
pub fn available_threads() -> usize {
    if cfg!(any(
        not(feature = "parallel"),
        all(target_family = "wasm", target_os = "unknown")
    )) {
        return 1;
    }
    static DEFAULT: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    match THREADS.load(Ordering::Relaxed) {
        0 => *DEFAULT.get_or_init(|| {
            std::env::var("JOSTLE_THREADS")
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .filter(|&n| n > 0)
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        }),
        n => n,
    }
    .clamp(1, MAX_THREADS)
}

/// The number of threads every following step's team uses, for the whole process (0: the
/// CPU's available parallelism, the default). Results do not depend on it, bit for bit; it
/// only changes speed. With the `parallel` feature off, always 1.
pub fn set_threads(threads: usize) {
    THREADS.store(threads, Ordering::Relaxed);
}

static THREADS: AtomicUsize = AtomicUsize::new(0);

/// How long a helper keeps polling for the next step's work before it parks (µs). A step's
/// other stages (broad and narrow phase, islands) take a fraction of a millisecond in the
/// scenes this pays for, so a helper polling that long is still there when the next
/// substeps start; waking a parked thread costs the caller 13–45 µs on a two-core virtual
/// machine (benches/RESULTS.md, "Two threads through the substeps").
pub const POLL_MICROS: u64 = 500;

/// The process's helper threads: [`MAX_THREADS`] − 1 at most, started on first use and kept
/// for the whole process. Between jobs a helper polls for [`POLL_MICROS`], then parks until
/// the next job wakes it.
pub(crate) struct Helpers {
    board: std::sync::Arc<Board>,
    /// The helpers started so far (helper i is member i + 1 of a team).
    threads: [std::sync::OnceLock<std::thread::Thread>; MAX_THREADS - 1],
    /// Helpers started (or that failed to start: the count stops there).
    started: std::sync::Mutex<usize>,
    /// Held while a job runs.
    busy: std::sync::Mutex<()>,
}

/// What the caller and the helpers share.
#[derive(Default)]
struct Board {
    /// Odd while a job is open; each job adds 2.
    epoch: std::sync::atomic::AtomicU64,
    /// The open job, valid while `epoch` is odd and the helper counted in `active`.
    job: std::sync::Mutex<Option<JobRef>>,
    /// The next member id to hand out.
    seats: AtomicUsize,
    /// Members in the job's thread count.
    wanted: AtomicUsize,
    /// Helpers inside the current job.
    active: AtomicUsize,
    /// Per helper: whether it is parked (or about to park).
    parked: Vec<std::sync::atomic::AtomicBool>,
}

/// The job's function with its lifetime erased: [`Helpers::run`] keeps it alive until no
/// helper uses it.
#[derive(Clone, Copy)]
struct JobRef(*const (dyn Fn(usize) + Sync));

// SAFETY: the pointee is `Sync`, and `Helpers::run` keeps it alive while helpers use it.
unsafe impl Send for JobRef {}

impl Helpers {
    /// The process's helpers, started on first use; `None` without the `parallel` feature or
    /// when no thread could be started.
    fn get() -> Option<&'static Helpers> {
        if cfg!(not(feature = "parallel")) {
            return None;
        }
        static HELPERS: std::sync::OnceLock<Option<Helpers>> = std::sync::OnceLock::new();
        HELPERS.get_or_init(Helpers::start).as_ref()
    }

    fn start() -> Option<Helpers> {
        let board = std::sync::Arc::new(Board {
            parked: (0..MAX_THREADS - 1)
                .map(|_| std::sync::atomic::AtomicBool::new(false))
                .collect(),
            ..Board::default()
        });
        Some(Helpers {
            board,
            threads: Default::default(),
            started: std::sync::Mutex::new(0),
            busy: std::sync::Mutex::new(()),
        })
    }

    /// Starts helpers until `count` have been (at most [`MAX_THREADS`] − 1). A helper that
    /// cannot be started is not: the team runs with fewer.
    fn ensure(&self, count: usize) {
        let count = count.min(MAX_THREADS - 1);
        if self
            .threads
            .get(count.wrapping_sub(1))
            .is_none_or(|t| t.get().is_some())
        {
            return;
        }
        let Ok(mut started) = self.started.lock() else {
            return;
        };
        while *started < count {
            let index = *started;
            let board = self.board.clone();
            let spawned = std::thread::Builder::new()
                .name(format!("jostle-helper-{index}"))
                .spawn(move || helper(&board, index));
            let Ok(handle) = spawned else {
                // Never retried: the count stays short of `count`.
                *started = MAX_THREADS;
                return;
            };
            let _ = self.threads[index].set(handle.thread().clone());
            *started += 1;
        }
    }

    /// Opens `job` for `threads` − 1 helpers, runs `job(0)`, closes it and waits for the
    /// helpers that joined.
    fn run(&self, threads: usize, job: &(dyn Fn(usize) + Sync)) {
        self.ensure(threads - 1);
        let board = &*self.board;
        // SAFETY (lifetime): the job is closed below, and this function returns only when no
        // helper is inside it (`active` is 0 after the close), even when `job(0)` panics
        // (the guard aborts then).
        let erased: *const (dyn Fn(usize) + Sync + '_) = job;
        let erased = JobRef(unsafe {
            std::mem::transmute::<
                *const (dyn Fn(usize) + Sync + '_),
                *const (dyn Fn(usize) + Sync + 'static),
            >(erased)
        });
        if let Ok(mut slot) = board.job.lock() {
            *slot = Some(erased);
        }
        board.seats.store(1, Ordering::SeqCst);
        board.wanted.store(threads, Ordering::SeqCst);
        board.epoch.fetch_add(1, Ordering::SeqCst); // odd: open
        for (thread, parked) in self.threads.iter().zip(&board.parked).take(threads - 1) {
            if parked.swap(false, Ordering::SeqCst)
                && let Some(thread) = thread.get()
            {
                thread.unpark();
            }
        }
        struct Close<'a>(&'a Board);
        impl Drop for Close<'_> {
            fn drop(&mut self) {
                // Also while unwinding from a panic of `job(0)`: the team is poisoned then,
                // so the helpers leave their stages.
                self.0.epoch.fetch_add(1, Ordering::SeqCst); // even: closed
                while self.0.active.load(Ordering::SeqCst) != 0 {
                    std::hint::spin_loop();
                }
            }
        }
        let close = Close(board);
        job(0);
        drop(close);
    }
}

/// A helper's life: poll for an open job, join it if a seat is left, run its member; park
/// when nothing came for [`POLL_MICROS`].
fn helper(board: &Board, index: usize) {
    let mut seen = 0u64;
    let mut poll = true;
    loop {
        let epoch = next_job(board, index, seen, poll);
        poll = index + 1 < board.wanted.load(Ordering::SeqCst);
        seen = epoch;
        board.active.fetch_add(1, Ordering::SeqCst);
        // Joined only if the job is still the open one: the caller closes before it waits for
        // `active`, so either it sees this helper counted or this helper sees the close.
        if board.epoch.load(Ordering::SeqCst) == epoch {
            let id = board.seats.fetch_add(1, Ordering::SeqCst);
            if id < board.wanted.load(Ordering::SeqCst) {
                let job = board.job.lock().ok().and_then(|slot| *slot);
                if let Some(JobRef(job)) = job {
                    // SAFETY: the job stays alive while this helper is counted in `active`.
                    let job = unsafe { &*job };
                    // `run`'s job catches the panics of the work it runs.
                    job(id);
                }
            }
        }
        board.active.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Waits for a job newer than `seen` to open and returns its epoch: polls for
/// [`POLL_MICROS`], then parks until [`Helpers::run`] unparks it.
fn next_job(board: &Board, index: usize, seen: u64, poll: bool) -> u64 {
    let open = |epoch: u64| !epoch.is_multiple_of(2) && epoch != seen;
    let mut started = crate::clock::Stopwatch::start();
    let mut poll_micros = if poll { u128::from(POLL_MICROS) } else { 0 };
    let mut spins = 0u32;
    loop {
        let epoch = board.epoch.load(Ordering::SeqCst);
        if open(epoch) {
            return epoch;
        }
        spins = spins.wrapping_add(1);
        if !spins.is_multiple_of(64) || started.elapsed().as_micros() < poll_micros {
            std::hint::spin_loop();
            continue;
        }
        // Parking: either the caller opening a job sees the flag and unparks, or this
        // thread sees the job (both sides store, then load, sequentially consistent).
        board.parked[index].store(true, Ordering::SeqCst);
        let epoch = board.epoch.load(Ordering::SeqCst);
        if open(epoch) {
            board.parked[index].store(false, Ordering::SeqCst);
            return epoch;
        }
        while board.parked[index].load(Ordering::SeqCst) {
            std::thread::park();
        }
        started = crate::clock::Stopwatch::start();
        poll_micros = u128::from(POLL_MICROS);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, AtomicU64};

    /// The stages of the test for `threads`: item counts.
    fn plan(counts: &[u32], threads: usize) -> Vec<Parts> {
        let plan = Plan {
            threads,
            stages: RefCell::default(),
            touches: None,
        };
        for &items in counts {
            plan.stage(items, |_| {});
        }
        plan.stages.into_inner()
    }

    /// A team of `threads` for stages of `counts` items.
    fn team(threads: usize, counts: &[u32]) -> Team {
        let mut team = Team::default();
        team.reset(threads, &plan(counts, threads));
        team
    }

    /// Every item of every stage runs exactly once, and no item starts before the whole
    /// previous stage has finished, for any number of threads (helpers may join late or not
    /// at all).
    #[test]
    fn every_item_runs_once_after_the_stage_before() {
        let counts: Vec<u32> = (0..200).map(|k| (k * 7) % 23).collect();
        for threads in 1..=4 {
            let team = team(threads, &counts);
            let total: Vec<AtomicU64> = (0..counts.len()).map(|_| AtomicU64::new(0)).collect();
            let early = AtomicBool::new(false);
            let sum = |n: u32| u64::from(n) * u64::from(n + 1) / 2;
            run(&team, |m| {
                for (k, &items) in counts.iter().enumerate() {
                    m.stage(items, |i| {
                        if k > 0 && total[k - 1].load(Ordering::Relaxed) != sum(counts[k - 1]) {
                            early.store(true, Ordering::Relaxed);
                        }
                        total[k].fetch_add(u64::from(i) + 1, Ordering::Relaxed);
                    });
                }
            });
            assert!(
                !early.load(Ordering::Relaxed),
                "{threads} threads: a stage started early"
            );
            for (k, &items) in counts.iter().enumerate() {
                assert_eq!(
                    total[k].load(Ordering::Relaxed),
                    sum(items),
                    "{threads} threads, stage {k}"
                );
            }
        }
    }

    /// On a team reset to flow, every item runs once, after every item of an earlier stage
    /// that touches one of its bodies and before every later one, for any number of threads
    /// (helpers may join late or not at all), with stages listed by body and stages not
    /// listed (which wait for everything before them) mixed; and again on the next steps,
    /// with the waits kept, across the wrap of the steps' epoch.
    #[test]
    fn flowing_items_run_after_the_items_before_them_on_their_bodies() {
        const BODIES: u32 = 40;
        let mut seed = 12345u64;
        let mut next = |n: u32| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % u64::from(n.max(1))) as u32
        };
        // Per stage: listed or not, and per item its bodies (disjoint within the stage).
        let mut stages: Vec<(bool, Vec<Vec<u32>>)> = Vec::new();
        for _ in 0..150 {
            let mut bodies: Vec<u32> = (0..BODIES).collect();
            for i in (1..bodies.len()).rev() {
                let j = next(i as u32 + 1) as usize;
                bodies.swap(i, j);
            }
            let items = next(12);
            let mut list = Vec::new();
            let mut at = 0;
            for _ in 0..items {
                let n = (next(5) as usize).min(bodies.len() - at);
                list.push(bodies[at..at + n].to_vec());
                at += n;
            }
            stages.push((next(8) != 0, list));
        }
        // Per body: how many items touch it.
        let mut touching = vec![0u32; BODIES as usize];
        for (_, items) in &stages {
            for b in items.iter().flatten() {
                touching[*b as usize] += 1;
            }
        }
        for threads in 1..=4 {
            let plan = Plan {
                threads,
                stages: RefCell::default(),
                touches: Some(RefCell::default()),
            };
            for (listed, items) in &stages {
                let touches = |i: u32, push: &mut dyn FnMut(u32)| {
                    items[i as usize].iter().for_each(|&b| push(b));
                };
                if *listed {
                    plan.stage_on_bodies(items.len() as u32, touches, |_| {});
                } else {
                    plan.stage(items.len() as u32, |_| {});
                }
            }
            let parts = plan.stages.into_inner();
            let touches = plan.touches.map(RefCell::into_inner).unwrap_or_default();
            let mut team = Team::default();
            for step in 0..4u32 {
                let keep = step > 0;
                if step == 1 {
                    // Steps 2 and 3 run across the epoch's wrap: the flags step 0 left (its
                    // epoch, 1) must not read as finished at the epoch 1 of step 3.
                    team.flow.epoch = u32::MAX - 1;
                }
                team.reset_flowing(threads, &parts, (!keep).then_some(&touches));
                // At a step's start no flag reads as finished, nor could at a later epoch.
                let epoch = team.flow.epoch;
                assert!(
                    team.flow
                        .flags
                        .iter()
                        .flat_map(|line| &line.0)
                        .all(|f| f.load(Ordering::Relaxed) < epoch),
                    "{threads} threads, step {step}: a flag at or past epoch {epoch}"
                );
                // Per body: the items that have touched it so far.
                let seen: Vec<AtomicU64> = (0..BODIES).map(|_| AtomicU64::new(0)).collect();
                let early = AtomicBool::new(false);
                run(&team, |m| {
                    for (k, (listed, items)) in stages.iter().enumerate() {
                        let item = |i: u32| {
                            for &b in &items[i as usize] {
                                // The items before this one on body b: those of earlier stages.
                                let before = stages[..k]
                                    .iter()
                                    .flat_map(|(_, items)| items.iter())
                                    .filter(|bodies| bodies.contains(&b))
                                    .count() as u64;
                                if seen[b as usize].fetch_add(1, Ordering::SeqCst) != before {
                                    early.store(true, Ordering::Relaxed);
                                }
                            }
                        };
                        let touches = |i: u32, push: &mut dyn FnMut(u32)| {
                            items[i as usize].iter().for_each(|&b| push(b));
                        };
                        if *listed {
                            m.stage_on_bodies(items.len() as u32, touches, item);
                        } else {
                            m.stage(items.len() as u32, item);
                        }
                    }
                });
                assert!(
                    !early.load(Ordering::Relaxed),
                    "{threads} threads, step {step}: an item ran out of order"
                );
                for (b, seen) in seen.iter().enumerate() {
                    assert_eq!(
                        seen.load(Ordering::SeqCst),
                        u64::from(touching[b]),
                        "{threads} threads, step {step}: body {b}"
                    );
                }
            }
        }
    }

    /// A panic in one member's item reaches the caller as a panic, whichever thread it
    /// happened on, and the team does not hang.
    #[test]
    fn a_panicking_item_poisons_the_team() {
        let counts = [64u32; 20];
        for threads in 1..=3 {
            let team = team(threads, &counts);
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                run(&team, |m| {
                    for (k, &items) in counts.iter().enumerate() {
                        m.stage(items, |i| {
                            assert!(!(k == 7 && i == 50), "item 50 of stage 7");
                        });
                    }
                });
            }));
            assert!(result.is_err(), "{threads} threads");
        }
    }

    /// Each thread's part is an equal share of the stage's items (to one item), in order.
    #[test]
    fn parts_share_each_stage_evenly() {
        let parts = plan(&[10, 0, 3, 1], 3);
        assert_eq!(&parts[0][..3], &[0, 4, 7]);
        assert!(parts[0][3..].iter().all(|&p| p == 10));
        assert!(parts[1].iter().all(|&p| p == 0));
        assert_eq!(&parts[2][..3], &[0, 1, 2]);
        assert!(parts[2][3..].iter().all(|&p| p == 3));
        // One item: the calling thread's (thread 0).
        assert_eq!(&parts[3][..2], &[0, 1]);
    }
}
