//! Where reading a stage has got to, for a progress display, and the way a caller stops it
//! ([`super::scene::Stage::load_with_progress`]).
//!
//! A big stage takes seconds to read (BENCHMARKS.md "Big stages": 100,000 lights in ~12 s on two
//! cores, most of it openusd composing), and a stage whose arcs reach many distinct layers far
//! longer: a caller should be able to say what is happening and to give up.

use std::ops::ControlFlow;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// One step of reading a stage, in the order they happen. The counts only grow within a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LoadProgress {
    /// Opening and parsing the root layer and its sublayers.
    Opening,
    /// The checks of every layer the root reaches (docs/INPUTS.md "Stages"): nesting depth,
    /// prim counts, arcs. Each reached layer is read here, so a stage of many files spends its
    /// reading time in this step.
    Checking,
    /// Composing the stage while traversing it: `prims` found so far (layers a reference or
    /// payload names are loaded as their prims are reached).
    Traversing { prims: u64 },
    /// Asking each prim found whether it is a light, and listing a light's schema and authored
    /// properties: `done` of `total` prims.
    Finding { done: u64, total: u64 },
    /// Reading each light's inputs, visibility and world transform at the query time: `done` of
    /// `total` lights.
    Reading { done: u64, total: u64 },
}

impl std::fmt::Display for LoadProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoadProgress::Opening => write!(f, "opening"),
            LoadProgress::Checking => write!(f, "checking its layers"),
            LoadProgress::Traversing { prims } => write!(f, "composing: {prims} prims"),
            LoadProgress::Finding { done, total } => {
                write!(f, "finding the lights: {done} of {total} prims")
            }
            LoadProgress::Reading { done, total } => {
                write!(f, "reading the lights: {done} of {total}")
            }
        }
    }
}

/// How many items a step goes through between two reports: a report costs a message to the
/// caller's thread, an item (a prim, a light) tens of microseconds.
const EVERY: u64 = 1024;

/// The reading thread's side: sends [`LoadProgress`] to the caller (at a step's start, every
/// [`EVERY`] items, at its end) and tells the reader when the caller has given up.
pub(crate) struct Reporter {
    send: Option<Box<dyn FnMut(LoadProgress) + Send>>,
    stop: Arc<AtomicBool>,
}

/// The caller gave up ([`Reporter::step`]); the reader returns it as
/// [`crate::error::LuxError::Cancelled`].
#[derive(Debug)]
pub(crate) struct Stopped;

impl Reporter {
    /// Reports nothing and never stops (`UsdStage::open`, `Stage::load`).
    pub fn silent() -> Self {
        Self {
            send: None,
            stop: Arc::new(AtomicBool::new(false)),
        }
    }

    pub fn new(send: impl FnMut(LoadProgress) + Send + 'static, stop: Arc<AtomicBool>) -> Self {
        Self {
            send: Some(Box::new(send)),
            stop,
        }
    }

    /// Reports `p` and says whether to go on.
    pub fn report(&mut self, p: LoadProgress) -> Result<(), Stopped> {
        if let Some(send) = &mut self.send {
            send(p);
        }
        self.check()
    }

    /// Whether the caller has given up.
    pub fn check(&self) -> Result<(), Stopped> {
        match self.stop.load(Ordering::Relaxed) {
            true => Err(Stopped),
            false => Ok(()),
        }
    }

    /// Reports `p(i)` when `i` items are done and `i` is a positive multiple of [`EVERY`] (a
    /// step reports its start and end itself), and says whether to go on (asked at every item:
    /// an atomic load).
    pub fn step(&mut self, i: u64, p: impl FnOnce(u64) -> LoadProgress) -> Result<(), Stopped> {
        if i > 0 && i.is_multiple_of(EVERY) {
            self.report(p(i))
        } else {
            self.check()
        }
    }
}

/// The caller's side of a load with progress: runs `progress` on each report; `Break` gives up.
pub(crate) fn relay(
    progress: &mut dyn FnMut(LoadProgress) -> ControlFlow<()>,
    p: LoadProgress,
    stop: &AtomicBool,
) -> ControlFlow<()> {
    let flow = progress(p);
    if flow.is_break() {
        stop.store(true, Ordering::Relaxed);
    }
    flow
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A caller's `Break` reaches the reading thread: its next report or check says stop.
    #[test]
    fn a_break_stops_the_reporter() {
        let stop = Arc::new(AtomicBool::new(false));
        let sent = Arc::new(std::sync::Mutex::new(Vec::new()));
        let log = sent.clone();
        let mut r = Reporter::new(move |p| log.lock().unwrap().push(p), stop.clone());
        assert!(r.report(LoadProgress::Opening).is_ok());
        // Only positive multiples of EVERY are reported between a step's ends.
        for i in 0..=2 * EVERY {
            assert!(
                r.step(i, |prims| LoadProgress::Traversing { prims })
                    .is_ok()
            );
        }
        let mut go_on = |_| ControlFlow::Continue(());
        assert!(relay(&mut go_on, LoadProgress::Checking, &stop).is_continue());
        assert!(r.check().is_ok());
        let mut give_up = |_| ControlFlow::Break(());
        assert!(relay(&mut give_up, LoadProgress::Checking, &stop).is_break());
        assert!(r.check().is_err());
        assert!(
            r.step(1, |prims| LoadProgress::Traversing { prims })
                .is_err()
        );
        assert_eq!(
            *sent.lock().unwrap(),
            [
                LoadProgress::Opening,
                LoadProgress::Traversing { prims: EVERY },
                LoadProgress::Traversing { prims: 2 * EVERY },
            ]
        );
        assert!(Reporter::silent().report(LoadProgress::Opening).is_ok());
    }
}
