//! Stopping a run on request (Ctrl-C in Python): a shared [`Cancel`] token that a front sets from
//! another thread, and that the solvers poll at their output times through [`cancelled`].
//!
//! The token reaches the solvers through the thread that runs them: [`with_cancel`] makes it the
//! current thread's token for the duration of a call (a study sets it again on each of its worker
//! threads), so the solvers' signatures do not change.

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A request to stop, shared between the thread that sets it and the threads that poll it.
#[derive(Debug, Clone, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A token not set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Ask every run polling this token to stop at its next output time.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Cancel::cancel`] has been called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

thread_local! {
    static CURRENT: RefCell<Option<Cancel>> = const { RefCell::new(None) };
}

/// Run `f` with `token` as the current thread's token (the previous one is restored after).
pub fn with_cancel<R>(token: Option<&Cancel>, f: impl FnOnce() -> R) -> R {
    let previous = CURRENT.with(|c| c.replace(token.cloned()));
    let out = f();
    CURRENT.with(|c| *c.borrow_mut() = previous);
    out
}

/// The current thread's token (to hand on to worker threads), if any.
pub fn current() -> Option<Cancel> {
    CURRENT.with(|c| c.borrow().clone())
}

/// Whether the current thread's token is set (false without a token): the solvers' poll.
pub fn cancelled() -> bool {
    CURRENT.with(|c| c.borrow().as_ref().is_some_and(Cancel::is_cancelled))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_token_is_seen_only_inside_its_scope() {
        let token = Cancel::new();
        assert!(!cancelled());
        with_cancel(Some(&token), || {
            assert!(!cancelled());
            token.cancel();
            assert!(cancelled());
            with_cancel(None, || assert!(!cancelled()));
            assert!(cancelled());
        });
        assert!(!cancelled());
    }
}
