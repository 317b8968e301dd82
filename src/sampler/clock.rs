//! Wall time and CPU time of a phase, measured together.
//!
//! Chains share cores: with more chains than threads a chain's wall time includes the time it
//! waited for a core, so costs are counted in the calling thread's CPU time (a chain runs on one
//! rayon worker from start to end), with its wall time beside it.

use std::time::Instant;

/// CPU seconds the calling thread has used since it started (NaN where the platform has no
/// per-thread clock).
pub fn thread_cpu_seconds() -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid, writable timespec; the call only writes into it.
        let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        if rc == 0 {
            return ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9;
        }
        f64::NAN
    }
    #[cfg(not(unix))]
    {
        f64::NAN
    }
}

/// Started at a point of the calling thread; reads the wall and CPU seconds since.
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch {
    wall: Instant,
    cpu: f64,
}

/// A phase's wall time and the CPU time of the thread that ran it, in seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Elapsed {
    pub wall_seconds: f64,
    pub cpu_seconds: f64,
}

impl Stopwatch {
    pub fn start() -> Self {
        Self {
            wall: Instant::now(),
            cpu: thread_cpu_seconds(),
        }
    }

    /// Must be read on the thread that started it: CPU time is per thread.
    pub fn elapsed(&self) -> Elapsed {
        Elapsed {
            wall_seconds: self.wall.elapsed().as_secs_f64(),
            cpu_seconds: thread_cpu_seconds() - self.cpu,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_time_counts_work_and_not_sleep() {
        let watch = Stopwatch::start();
        std::thread::sleep(std::time::Duration::from_millis(150));
        let slept = watch.elapsed();
        assert!(slept.wall_seconds >= 0.15, "{slept:?}");
        assert!(slept.cpu_seconds < 0.05, "{slept:?}");
        // Busy on one thread until it has used 50 ms of CPU: on a loaded machine that takes
        // longer in wall time (a fixed wall-time loop got 13 ms of CPU in 100 ms here with
        // four builds beside it), so the loop is bounded by CPU time and, if the clock did
        // not count, by 10 s of wall time, where the first assertion fails.
        let watch = Stopwatch::start();
        let mut x = 0u64;
        let busy = loop {
            for _ in 0..10_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
            let e = watch.elapsed();
            if e.cpu_seconds >= 0.05 || e.wall_seconds > 10.0 {
                break e;
            }
        };
        assert!(busy.cpu_seconds >= 0.05, "{busy:?}");
        // CPU time of one thread never exceeds its wall time (other load can only lower it).
        assert!(busy.cpu_seconds <= busy.wall_seconds + 0.01, "{busy:?}");
    }
}
