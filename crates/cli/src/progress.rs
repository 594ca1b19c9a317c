//! Progress of `verify` and `compare` on stderr: a bar on a terminal; in a batch job (stderr not
//! a terminal) one line every [`BATCH_INTERVAL_S`] seconds instead.

use std::io::IsTerminal;
use std::sync::Mutex;

use flexstar_compare::Progress;

/// Seconds between two progress lines when stderr is not a terminal.
pub const BATCH_INTERVAL_S: f64 = 5.0;

/// A progress reporter for one command.
pub enum Reporter {
    Bar(indicatif::ProgressBar),
    Lines { what: String, last: Mutex<f64> },
}

impl Reporter {
    /// A bar when stderr is a terminal, periodic lines otherwise.
    pub fn new(what: &str) -> Self {
        if std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(1000);
            bar.set_style(
                indicatif::ProgressStyle::with_template(&format!(
                    "{what} {{bar:40}} {{percent:>3}}% {{msg}} eta {{eta}}"
                ))
                .expect("valid template"),
            );
            Reporter::Bar(bar)
        } else {
            Reporter::Lines {
                what: what.to_string(),
                last: Mutex::new(0.0),
            }
        }
    }

    /// Report one progress update (called from worker threads).
    pub fn update(&self, p: Progress) {
        match self {
            Reporter::Bar(bar) => {
                bar.set_position((p.fraction * 1000.0) as u64);
                bar.set_message(format!("{}/{} runs", p.done, p.total));
            }
            Reporter::Lines { what, last } => {
                let mut last = last.lock().unwrap_or_else(|e| e.into_inner());
                if p.elapsed - *last >= BATCH_INTERVAL_S {
                    *last = p.elapsed;
                    eprintln!(
                        "{what}: {:3.0} % after {:.0} s, {}/{} runs done",
                        100.0 * p.fraction,
                        p.elapsed,
                        p.done,
                        p.total
                    );
                }
            }
        }
    }

    /// Remove the bar (lines need no cleanup).
    pub fn finish(&self) {
        if let Reporter::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}
