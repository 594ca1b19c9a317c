//! Long calls that Ctrl-C stops and that may report progress: the work runs on a worker thread
//! with a [`Cancel`] token as its thread's token; the calling thread, GIL released, waits for it
//! and every [`POLL`] takes the GIL to run Python's signal handlers. A pending `KeyboardInterrupt`
//! (or any exception a handler raises) sets the token; the solvers stop at their next output time
//! (a study between cases) and the exception is raised.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use flexstar_model::cancel::with_cancel;
use flexstar_model::Cancel;
use pyo3::prelude::*;

/// How often the waiting thread looks for a signal (and may print progress).
const POLL: Duration = Duration::from_millis(50);

/// Seconds between two progress lines on stderr.
const PROGRESS_INTERVAL_S: f64 = 1.0;

/// Run `work` (given a progress callback taking the fraction done, 0..1) with the GIL released,
/// stoppable by Ctrl-C; with `progress`, a line `what: NN % after S s` on stderr every second (the
/// percentage where the work reports one, FEM runs).
pub fn interruptible<T: Send>(
    py: Python<'_>,
    what: &str,
    progress: bool,
    work: impl FnOnce(&(dyn Fn(f64) + Sync)) -> T + Send,
) -> PyResult<T> {
    let token = Cancel::new();
    let fraction = AtomicU64::new(f64::NAN.to_bits());
    let (out, interrupted) = py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = mpsc::channel();
            let (token, fraction) = (&token, &fraction);
            s.spawn(move || {
                let report = |x: f64| fraction.store(x.to_bits(), Ordering::Relaxed);
                let _ = tx.send(with_cancel(Some(token), || work(&report)));
            });
            wait(&rx, token, fraction, what, progress)
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    // the worker only drops its sender without a value when `work` panicked (re-raised by scope)
    out.ok_or_else(|| pyo3::exceptions::PyRuntimeError::new_err("flexstar: the worker thread stopped"))
}

/// Wait for the worker's value, polling Python's signal handlers (the first error sets `token`).
fn wait<T>(
    rx: &mpsc::Receiver<T>,
    token: &Cancel,
    fraction: &AtomicU64,
    what: &str,
    progress: bool,
) -> (Option<T>, Option<PyErr>) {
    let started = Instant::now();
    let mut last_line = 0.0;
    let mut interrupted = None;
    loop {
        match rx.recv_timeout(POLL) {
            Ok(v) => return (Some(v), interrupted),
            Err(mpsc::RecvTimeoutError::Disconnected) => return (None, interrupted),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        if interrupted.is_none() {
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                token.cancel();
                interrupted = Some(e);
            }
        }
        let elapsed = started.elapsed().as_secs_f64();
        if progress && elapsed - last_line >= PROGRESS_INTERVAL_S {
            last_line = elapsed;
            let done = 100.0 * f64::from_bits(fraction.load(Ordering::Relaxed));
            if done.is_nan() {
                eprintln!("{what}: running for {elapsed:.0} s");
            } else {
                eprintln!("{what}: {done:3.0} % after {elapsed:.0} s");
            }
        }
    }
}
