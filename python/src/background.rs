//! Long work off the interpreter: it runs on a thread of its own with the GIL released, while
//! the calling thread checks Python's signals every 50 ms. Ctrl-C (or any signal whose handler
//! raises) sets the run's stop flag, which the library's chains check between transitions;
//! the work is waited for and the handler's exception (`KeyboardInterrupt`) raised. Nothing
//! is written by an interrupted run: the bindings write files only after the work returns.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often the calling thread looks at Python's signals.
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// How often a progress line is redrawn.
const PROGRESS_EVERY: Duration = Duration::from_millis(250);

/// A run's progress as the calling thread shows it: the transitions counted so far out of
/// `total`, drawn by `motorcal._progress(label, done, total, finished)` (one line, rewritten in
/// place, which a terminal and a notebook's output cell both show as one bar; ended once the
/// work has returned).
pub struct Progress {
    pub label: String,
    pub done: Arc<AtomicUsize>,
    pub total: usize,
}

impl Progress {
    fn show(&self, py: Python<'_>, finished: bool) -> PyResult<()> {
        let done = if finished {
            self.total
        } else {
            self.done.load(Ordering::Relaxed).min(self.total)
        };
        py.import("motorcal")?.getattr("_progress")?.call1((
            self.label.as_str(),
            done,
            self.total,
            finished,
        ))?;
        Ok(())
    }
}

/// Runs `work(stop)` on another thread; a signal handler's exception sets `stop` and is raised
/// once the work has returned.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    interruptible_with(py, None, work)
}

/// [`interruptible`], drawing `progress` (if any) while the work runs.
pub fn interruptible_with<T: Send>(
    py: Python<'_>,
    progress: Option<&Progress>,
    work: impl FnOnce(Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    std::thread::scope(|scope| {
        let (done, mut finished) = channel::<()>();
        let handle = scope.spawn(move || {
            let out = work(flag);
            let _ = done.send(());
            out
        });
        let mut drawn = Instant::now();
        loop {
            let (state, back) = py.detach(move || (finished.recv_timeout(SIGNAL_CHECK), finished));
            finished = back;
            if !matches!(state, Err(RecvTimeoutError::Timeout)) {
                if let Some(p) = progress {
                    p.show(py, true)?;
                }
                break;
            }
            // Drawing runs Python, where a pending signal's handler may raise: that error is
            // the interrupt too, and the run is stopped before it is raised.
            let drawing = match progress {
                Some(p) if drawn.elapsed() >= PROGRESS_EVERY => {
                    drawn = Instant::now();
                    p.show(py, false)
                }
                _ => Ok(()),
            };
            if let Err(interrupt) = drawing.and_then(|()| py.check_signals()) {
                stop.store(true, Ordering::SeqCst);
                // The chains stop at their next transition; their partial output is dropped.
                let _ = py.detach(move || handle.join());
                return Err(interrupt);
            }
        }
        py.detach(move || handle.join())
            .map_err(|_| PyRuntimeError::new_err("the run panicked"))
    })
}
