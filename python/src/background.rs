//! Long work off the interpreter: it runs on a thread of its own with the GIL released, while
//! the calling thread checks Python's signals every 50 ms. Ctrl-C (or any signal whose handler
//! raises) sets the run's stop flag, which the library's chains check between transitions;
//! the work is waited for and the handler's exception (`KeyboardInterrupt`) raised. Nothing
//! is written by an interrupted run: the bindings write files only after the work returns.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often the calling thread looks at Python's signals.
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// Runs `work(stop)` on another thread; a signal handler's exception sets `stop` and is raised
/// once the work has returned.
pub fn interruptible<T: Send>(
    py: Python<'_>,
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
        loop {
            let (state, back) = py.detach(move || (finished.recv_timeout(SIGNAL_CHECK), finished));
            finished = back;
            if !matches!(state, Err(RecvTimeoutError::Timeout)) {
                break;
            }
            if let Err(interrupt) = py.check_signals() {
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
