//! The thread a stage is read on: a large stack for deep stages, the composed stage freed there
//! after the lights are handed back, and the reports of [`Stage::load_with_progress`] relayed
//! to the caller's thread.

use std::ops::ControlFlow;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::RecvTimeoutError;

use super::progress::{LoadProgress, Reporter, relay};
#[cfg(doc)]
use super::scene::Stage;
use super::stage as usd;
use crate::error::{LuxError, Result};

/// The stack of the thread that reads a stage. openusd's text parser and composition engine
/// recurse once or more per namespace level: on the 8 MiB main stack a debug build overflowed
/// at 3 000 levels and not at 1 000 (so 3–8 KiB a level), and a 10 000-level stage read with
/// this stack (the depth limit raised) had not overflowed after 20 minutes of composing. The depth limit (docs/INPUTS.md,
/// default 1 000) is checked before anything recurses; 512 MiB leaves room to raise it far
/// beyond what openusd composes in reasonable time. Memory is only reserved, and committed as
/// the stack grows.
pub(super) const STACK_BYTES: usize = 512 << 20;

/// Runs `f` on a thread with a [`STACK_BYTES`] stack and returns the first of what it returns.
/// The second, what `f` built to get there (the composed stage), is dropped on that thread
/// after the first is handed back, while the caller goes on: freeing openusd's structures is
/// about a second of CPU for a 100,000-light stage, which would otherwise be spent before the
/// caller sees a light. The thread is not joined once it has answered.
///
/// A panic on that thread before it answers becomes an error naming the stage: openusd 0.8 has
/// debug assertions that malformed files reach (found by fuzz/: a `.usdc` whose path table
/// builds an invalid variant path asserts in `sdf::Path::from_str_unchecked`), and a stage must
/// never abort the process.
pub(super) fn on_large_stack<T: Send + 'static, L>(
    path: &Path,
    mut progress: Option<&mut dyn FnMut(LoadProgress) -> ControlFlow<()>>,
    f: impl FnOnce(&mut Reporter) -> Result<(T, L)> + Send + 'static,
) -> Result<T> {
    // Reports are a step's start and end and one every 1,024 items: a few hundred for the
    // largest stages; a caller slower than the reader holds it back at 64.
    let (tx, rx) = std::sync::mpsc::sync_channel(64);
    let stop = Arc::new(AtomicBool::new(false));
    let mut reporter = match progress {
        Some(_) => {
            let tx = tx.clone();
            Reporter::new(
                move |p| {
                    // The receiver is gone once the caller gave up: nothing is left to tell.
                    let _ = tx.send(Message::Progress(p));
                },
                stop.clone(),
            )
        }
        None => Reporter::silent(),
    };
    let handle = std::thread::Builder::new()
        .name("luxeval-stage".into())
        .stack_size(STACK_BYTES)
        .spawn(move || match f(&mut reporter) {
            Ok((value, rest)) => {
                // The receiver is gone only if the caller panicked or gave up; nothing is
                // left to tell.
                let _ = tx.send(Message::Done(Ok(value)));
                drop(reporter);
                drop(rest);
            }
            Err(e) => {
                let _ = tx.send(Message::Done(Err(e)));
            }
        });
    let handle = match handle {
        Ok(h) => h,
        // No thread (out of memory or address space).
        Err(_) => {
            return Err(LuxError::input(
                "stage",
                "cannot start the thread that reads the stage (out of memory?)",
            ));
        }
    };
    // The last report, repeated to `progress` while the reader is silent (openusd parsing or
    // composing), so that a display stays alive and a caller can give up meanwhile.
    let mut last = LoadProgress::Opening;
    loop {
        let message = match progress {
            Some(_) => match rx.recv_timeout(HEARTBEAT) {
                Err(RecvTimeoutError::Timeout) => Ok(Message::Progress(last)),
                Err(RecvTimeoutError::Disconnected) => Err(()),
                Ok(m) => Ok(m),
            },
            None => rx.recv().map_err(|_| ()),
        };
        match message {
            Ok(Message::Progress(p)) => {
                last = p;
                if let Some(progress) = progress.as_deref_mut()
                    && relay(progress, p, &stop).is_break()
                {
                    return Err(usd::cancelled(path));
                }
            }
            Ok(Message::Done(r)) => return r,
            // No answer: the thread panicked (its senders dropped while unwinding).
            Err(()) => {
                let panic = match handle.join() {
                    Err(panic) => panic,
                    Ok(()) => Box::new("the reading thread ended without an answer"),
                };
                let msg = panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("no message");
                return Err(LuxError::input(
                    path.display().to_string(),
                    format!("the USD reader failed on this file (it panicked: {msg})"),
                ));
            }
        }
    }
}

/// How long the caller of [`Stage::load_with_progress`] waits for a report before it tells
/// `progress` the last one again.
const HEARTBEAT: std::time::Duration = std::time::Duration::from_millis(250);

/// What the reading thread sends its caller.
enum Message<T> {
    Progress(LoadProgress),
    Done(Result<T>),
}
