//! When a progress line is due where stderr is not a terminal (a log file, a SLURM output):
//! at each tenth of the work and at least once a minute, so that a log has about ten lines per
//! task and still shows a long one is alive.

use std::time::{Duration, Instant};

/// The longest quiet spell in a log.
pub const MINUTE: Duration = Duration::from_secs(60);

/// The schedule of progress lines for work of some total size.
#[derive(Debug, Clone)]
pub struct Lines {
    next: f64,
    last: Option<Instant>,
}

impl Lines {
    /// The schedule from the start (the first call prints).
    pub fn new() -> Self {
        Self {
            next: 0.0,
            last: None,
        }
    }

    /// Whether a line is due with `done` of `total` done; if so, the next is scheduled.
    pub fn due(&mut self, done: f64, total: f64) -> bool {
        let late = self.last.is_some_and(|t| t.elapsed() >= MINUTE);
        if done >= self.next || done >= total || late {
            self.next = done + total / 10.0;
            self.last = Some(Instant::now());
            true
        } else {
            false
        }
    }
}

impl Default for Lines {
    fn default() -> Self {
        Self::new()
    }
}
