//! A small fork–join pool for the data-parallel loops of a step: `threads - 1` persistent
//! worker threads plus the calling thread, each running one share of a job.
//!
//! Running a job allocates nothing (atomics; workers spin briefly, then park), so a step stays
//! allocation-free with several threads. Work is split into contiguous particle ranges and every
//! sum is taken in a fixed order by its owner, so results are identical for any thread count.

use std::cell::UnsafeCell;
use std::ops::Range;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::{self, JoinHandle};

/// A job: called once with each share index `0..threads`.
type Job = dyn Fn(usize) + Sync;

/// The `share`-th of `threads` contiguous, near-equal parts of `0..n` ([`Pool::share`] on a
/// pool of `threads` threads).
pub fn share_of(threads: usize, share: usize, n: usize) -> Range<usize> {
    (share * n / threads)..((share + 1) * n / threads)
}

/// Spins (about a microsecond each) a waiting thread makes before it parks or yields.
const SPINS: u32 = 20_000;

struct Shared {
    /// Incremented by each published job; workers run a job when they see it change.
    generation: AtomicU64,
    /// Workers that have not finished the current job.
    remaining: AtomicUsize,
    /// The current job, valid while `remaining > 0` (set before `generation` is bumped).
    job: UnsafeCell<Option<&'static Job>>,
    panicked: AtomicBool,
    shutdown: AtomicBool,
}

// SAFETY: `job` is written only by the thread that owns the pool, while no worker reads it
// (before a generation bump, after every worker has reported back); workers read it only
// between those two points, ordered by the Release/Acquire pairs on `generation`/`remaining`.
unsafe impl Sync for Shared {}

/// The pool (see the module documentation).
pub struct Pool {
    shared: Arc<Shared>,
    workers: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Pool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Pool({} threads)", self.threads())
    }
}

impl Pool {
    /// A pool running jobs on `threads` threads (the caller's and `threads - 1` workers).
    pub fn new(threads: usize) -> Pool {
        let shared = Arc::new(Shared {
            generation: AtomicU64::new(0),
            remaining: AtomicUsize::new(0),
            job: UnsafeCell::new(None),
            panicked: AtomicBool::new(false),
            shutdown: AtomicBool::new(false),
        });
        let workers = (1..threads.max(1))
            .map(|k| {
                let shared = Arc::clone(&shared);
                thread::Builder::new()
                    .name(format!("tissuesim-{k}"))
                    .spawn(move || worker(k, &shared))
                    .expect("cannot spawn a tissuesim worker thread")
            })
            .collect();
        Pool { shared, workers }
    }

    /// Number of threads a job runs on.
    pub fn threads(&self) -> usize {
        self.workers.len() + 1
    }

    /// The `share`-th of `threads()` contiguous, near-equal parts of `0..n`.
    pub fn share(&self, share: usize, n: usize) -> Range<usize> {
        share_of(self.threads(), share, n)
    }

    /// Run `job(range)` for each share's contiguous range of `0..n` (see [`Pool::share`]), on
    /// every thread; with one thread, `job(0..n)` on the caller's.
    pub fn for_each_range(&self, n: usize, job: &(dyn Fn(Range<usize>) + Sync)) {
        self.run(&|share| job(self.share(share, n)));
    }

    /// Run `job(k)` for every share `k` in `0..threads()` (share 0 on the calling thread) and
    /// return when all have finished. A panic in any share is re-raised here.
    pub fn run<'a>(&self, job: &'a (dyn Fn(usize) + Sync + 'a)) {
        if self.workers.is_empty() {
            job(0);
            return;
        }
        // SAFETY: the reference is erased to 'static only for the duration of this call: the
        // workers drop it before `remaining` reaches 0, which is awaited below.
        let job_static: &'static Job =
            unsafe { std::mem::transmute::<&'a (dyn Fn(usize) + Sync + 'a), &'static Job>(job) };
        // SAFETY: no worker reads `job` now (the previous run waited for all of them).
        unsafe { *self.shared.job.get() = Some(job_static) };
        self.shared
            .remaining
            .store(self.workers.len(), Ordering::Release);
        self.shared.generation.fetch_add(1, Ordering::Release);
        for w in &self.workers {
            w.thread().unpark();
        }
        let mine = catch_unwind(AssertUnwindSafe(|| job(0)));
        let mut spins = 0;
        while self.shared.remaining.load(Ordering::Acquire) != 0 {
            if spins < SPINS {
                std::hint::spin_loop();
                spins += 1;
            } else {
                thread::yield_now();
            }
        }
        // SAFETY: every worker has finished with the job.
        unsafe { *self.shared.job.get() = None };
        if let Err(payload) = mine {
            resume_unwind(payload);
        }
        if self.shared.panicked.swap(false, Ordering::AcqRel) {
            panic!("a tissuesim worker thread panicked");
        }
    }
}

impl Drop for Pool {
    fn drop(&mut self) {
        self.shared.shutdown.store(true, Ordering::Release);
        for w in &self.workers {
            w.thread().unpark();
        }
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

fn worker(share: usize, shared: &Shared) {
    let mut seen = 0;
    loop {
        let mut spins = 0;
        loop {
            if shared.shutdown.load(Ordering::Acquire) {
                return;
            }
            let g = shared.generation.load(Ordering::Acquire);
            if g != seen {
                seen = g;
                break;
            }
            if spins < SPINS {
                std::hint::spin_loop();
                spins += 1;
            } else {
                // Woken by the next job's unpark (or spuriously: the loop checks again).
                thread::park();
            }
        }
        // SAFETY: published before the generation bump we just observed (Acquire).
        let job = unsafe { *shared.job.get() };
        if let Some(job) = job {
            if catch_unwind(AssertUnwindSafe(|| job(share))).is_err() {
                shared.panicked.store(true, Ordering::Release);
            }
        }
        shared.remaining.fetch_sub(1, Ordering::AcqRel);
    }
}

/// A raw pointer to a slice's data, shared by the shares of one job, each writing only the
/// elements of its own range.
#[derive(Clone, Copy)]
pub struct SharedSlice<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: used only inside `Pool::run` jobs whose shares write disjoint index ranges.
unsafe impl<T: Send> Sync for SharedSlice<T> {}
unsafe impl<T: Send> Send for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    /// Wrap a mutable slice for one job.
    pub fn new(slice: &mut [T]) -> Self {
        SharedSlice {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
        }
    }
    /// The elements `range` as a mutable slice.
    ///
    /// # Safety
    /// No other share may access any element of `range` during the job.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn range(&self, range: Range<usize>) -> &mut [T] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds (checked) and exclusive by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }
    /// The elements `range`, shared.
    ///
    /// # Safety
    /// No share may write any element of `range` while the result is in use.
    pub unsafe fn read(&self, range: Range<usize>) -> &[T] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds (checked) and not written by the caller's contract.
        unsafe { std::slice::from_raw_parts(self.ptr.add(range.start), range.len()) }
    }
    /// Element `i`, mutable.
    ///
    /// # Safety
    /// No other share may access element `i` during the job.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn element(&self, i: usize) -> &mut T {
        assert!(i < self.len);
        // SAFETY: in bounds (checked) and exclusive by the caller's contract.
        unsafe { &mut *self.ptr.add(i) }
    }
    /// Element `i`, mutable, its index not checked (for loops whose indices are validated
    /// once, outside the loop).
    ///
    /// # Safety
    /// `i` is below the slice's length, and no other share may access element `i` during the
    /// job.
    #[allow(clippy::mut_from_ref)]
    #[inline(always)]
    pub unsafe fn element_unchecked(&self, i: usize) -> &mut T {
        debug_assert!(i < self.len);
        // SAFETY: in bounds and exclusive by the caller's contract.
        unsafe { &mut *self.ptr.add(i) }
    }
    /// The slice's length.
    pub fn len(&self) -> usize {
        self.len
    }
}

/// A barrier for the shares of one `Pool::run` job that run in phases (a phase's writes are
/// seen by every share after the barrier). If a share panics, [`Barrier::guard`] breaks the
/// barrier so that the other shares do not wait for it forever.
pub struct Barrier {
    threads: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    broken: AtomicBool,
}

impl Barrier {
    /// A barrier for `threads` shares.
    pub fn new(threads: usize) -> Barrier {
        Barrier {
            threads,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            broken: AtomicBool::new(false),
        }
    }
    /// Wait until every share has arrived (or the barrier is broken).
    pub fn wait(&self) {
        let generation = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.threads {
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::AcqRel);
            return;
        }
        let mut spins = 0;
        while self.generation.load(Ordering::Acquire) == generation
            && !self.broken.load(Ordering::Acquire)
        {
            if spins < SPINS {
                std::hint::spin_loop();
                spins += 1;
            } else {
                thread::yield_now();
            }
        }
    }
    /// Held by a share for the length of its work: breaks the barrier if the share panics.
    pub fn guard(&self) -> BarrierGuard<'_> {
        BarrierGuard(self)
    }
}

/// See [`Barrier::guard`].
pub struct BarrierGuard<'a>(&'a Barrier);

impl Drop for BarrierGuard<'_> {
    fn drop(&mut self) {
        if thread::panicking() {
            self.0.broken.store(true, Ordering::Release);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_share_runs_once_per_job_and_results_do_not_depend_on_threads() {
        for threads in [1, 2, 3] {
            let pool = Pool::new(threads);
            let mut data = vec![0u64; 1000];
            for round in 0..50 {
                let out = SharedSlice::new(&mut data);
                pool.run(&|k| {
                    let r = pool.share(k, 1000);
                    // SAFETY: shares are disjoint.
                    for (i, v) in unsafe { out.range(r.clone()) }.iter_mut().enumerate() {
                        *v += (r.start + i) as u64 * round;
                    }
                });
            }
            let expected: Vec<u64> = (0..1000).map(|i| i * (0..50).sum::<u64>()).collect();
            assert_eq!(data, expected, "{threads} threads");
        }
    }

    #[test]
    fn a_barrier_orders_the_phases_and_a_panic_breaks_it() {
        let pool = Pool::new(2);
        let mut data = vec![0u64; 100];
        let barrier = Barrier::new(pool.threads());
        let out = SharedSlice::new(&mut data);
        pool.run(&|k| {
            let _guard = barrier.guard();
            for phase in 0..20u64 {
                // Each phase reads what the other share wrote in the previous one.
                let i = (k + phase as usize) % 2;
                // SAFETY: in a phase, share k touches only the elements of parity i, the
                // other share those of the other parity.
                for e in (i..100).step_by(2) {
                    let v = unsafe { out.element(e) };
                    *v = *v * 2 + 1;
                }
                barrier.wait();
            }
        });
        assert!(data.iter().all(|&v| v == (1 << 20) - 1), "{data:?}");
        let barrier = Barrier::new(pool.threads());
        let r = catch_unwind(AssertUnwindSafe(|| {
            pool.run(&|k| {
                let _guard = barrier.guard();
                if k == 1 {
                    panic!("boom");
                }
                barrier.wait();
            })
        }));
        assert!(r.is_err(), "the panic reaches the caller, nobody hangs");
    }

    #[test]
    fn a_panicking_share_is_reported_to_the_caller() {
        let pool = Pool::new(2);
        let r = catch_unwind(AssertUnwindSafe(|| {
            pool.run(&|k| {
                if k == 1 {
                    panic!("boom");
                }
            })
        }));
        assert!(r.is_err());
        // The pool still works afterwards.
        let hits = AtomicUsize::new(0);
        pool.run(&|_| {
            hits.fetch_add(1, Ordering::SeqCst);
        });
        assert_eq!(hits.load(Ordering::SeqCst), 2);
    }
}
