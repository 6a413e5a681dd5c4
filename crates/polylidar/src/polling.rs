//! Keeping a second worker of the pool awake for the length of a run.
//!
//! A rayon worker that finds no work spins for some tens of microseconds and then
//! sleeps; the next parallel section wakes it through the kernel. On the 2-core virtual
//! machine of our benchmarks such a wake takes 40–90 µs, as long as many of the parallel
//! sections of a depth frame's 6–8 ms, which follow each other with short sequential
//! stretches in between. OpenMP, which the C++ original uses, spins much longer before
//! it sleeps. Here one other worker polls for work until the run ends.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long the polling worker goes on finding no work before it goes to sleep after
/// all: longer than the sequential stretches of a frame, short enough that a stall
/// (see [`run_polled`]) stays small.
const IDLE_LIMIT: Duration = Duration::from_micros(500);

/// Runs `f` in `pool` (rayon's global pool for `None`) while one other worker polls
/// for work instead of sleeping, until `f` returns. Called from one of the pool's own
/// workers (or, for `None`, from any worker), it runs `f` as rayon would, unpolled: the
/// run is then part of a larger parallel job, whose workers are busy anyway.
pub(crate) fn install_polled<T: Send>(
    pool: Option<&rayon::ThreadPool>,
    f: impl FnOnce() -> T + Send,
) -> T {
    match pool {
        Some(pool) if pool.current_thread_index().is_none() && pool.current_num_threads() > 1 => {
            pool.install(|| run_polled(f, IDLE_LIMIT).0)
        }
        Some(pool) => pool.install(f),
        None if rayon::current_thread_index().is_none() && rayon::current_num_threads() > 1 => {
            run_polled(f, IDLE_LIMIT).0
        }
        None => f(),
    }
}

/// Runs `f` on a worker while another worker polls (see [`poll`]), giving up after
/// `idle_limit` without work; returns `f`'s result and how many jobs the poller ran.
///
/// The poller is the oldest job of `f`'s worker's deque, so the first theft from that
/// worker takes it, before any of `f`'s jobs: the thief is idle, or busy with another
/// run, never waiting inside this one, and `f` never waits for it. A thief busy with
/// another run holds that run up until this one ends or finds no work for
/// `idle_limit`, which also ends the only cycle possible (two runs that took each
/// other's pollers). The result comes back once the poller has finished the job it is
/// running, if any.
fn run_polled<T: Send>(f: impl FnOnce() -> T + Send, idle_limit: Duration) -> (T, usize) {
    let done = AtomicBool::new(false);
    let home = AtomicUsize::new(usize::MAX);
    rayon::join(
        || {
            let _done = SetOnDrop(&done);
            home.store(
                rayon::current_thread_index().unwrap_or(usize::MAX),
                Ordering::Release,
            );
            f()
        },
        || poll(&done, &home, idle_limit),
    )
}

/// Sets the flag when dropped: when the run returns or unwinds.
struct SetOnDrop<'a>(&'a AtomicBool);

impl Drop for SetOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// Runs the pool's pending jobs as they come until `done` or `idle_limit` without
/// work; returns how many it ran. Does nothing on the `home` worker, which pops the
/// poller itself when no other worker took it.
fn poll(done: &AtomicBool, home: &AtomicUsize, idle_limit: Duration) -> usize {
    if rayon::current_thread_index() == Some(home.load(Ordering::Acquire)) {
        return 0;
    }
    let (mut ran, mut idle_since) = (0, None);
    while !done.load(Ordering::Acquire) {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            ran += 1;
            idle_since = None;
            continue;
        }
        let since = *idle_since.get_or_insert_with(Instant::now);
        if since.elapsed() > idle_limit {
            break;
        }
        std::hint::spin_loop();
    }
    ran
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
    }

    /// Sums `0..n` in parallel, each item after some busy work, so that both workers
    /// take part while the run lasts.
    fn busy_sum(n: u64) -> u64 {
        (0..n)
            .into_par_iter()
            .map(|i| {
                let start = Instant::now();
                while start.elapsed() < Duration::from_micros(500) {
                    std::hint::spin_loop();
                }
                i
            })
            .sum()
    }

    #[test]
    fn the_poller_runs_jobs_of_the_run_on_the_other_worker() {
        // The run lasts until a job of it ran on the other worker, which took the poller
        // first (the oldest job); an hour's limit keeps a stalled machine from ending
        // the polling before.
        let (runs, ran) = pool(2).install(|| {
            run_polled(
                || {
                    let home = rayon::current_thread_index();
                    let mut runs = 0;
                    loop {
                        runs += 1;
                        assert_eq!(busy_sum(4), 6);
                        let elsewhere = (0..2)
                            .into_par_iter()
                            .any(|_| rayon::current_thread_index() != home);
                        if elsewhere {
                            return runs;
                        }
                    }
                },
                Duration::from_secs(3600),
            )
        });
        assert!(runs > 0);
        assert!(ran > 0, "the poller ran none of the run's jobs");
    }

    #[test]
    fn a_pool_of_one_runs_alone() {
        let (sum, ran) = pool(1).install(|| run_polled(|| busy_sum(10), Duration::from_secs(30)));
        assert_eq!((sum, ran), (45, 0));
    }

    #[test]
    fn entered_from_a_worker_it_runs_unpolled() {
        let own = pool(2);
        let sums: Vec<u64> = own.install(|| {
            (0..4u64)
                .into_par_iter()
                .map(|n| install_polled(Some(&own), || (0..n).sum()))
                .collect()
        });
        assert_eq!(sums, [0, 0, 1, 3]);
    }

    #[test]
    fn a_panic_in_the_run_reaches_the_caller_and_ends_the_polling() {
        // With an hour's limit, only the end of the run ends the polling in time.
        let caught = std::panic::catch_unwind(|| {
            pool(2).install(|| run_polled(|| panic!("in the run"), Duration::from_secs(3600)))
        });
        assert!(caught.is_err());
    }

    #[test]
    fn off_any_pool_it_runs_on_a_worker_of_the_global_one() {
        assert!(rayon::current_thread_index().is_none());
        let on_worker = install_polled(None, || rayon::current_thread_index().is_some());
        assert_eq!(on_worker, rayon::current_num_threads() > 1);
        let own = pool(2);
        assert_eq!(
            install_polled(Some(&own), rayon::current_thread_index).map(|_| ()),
            Some(())
        );
    }
}
