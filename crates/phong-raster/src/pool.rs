//! The threads CPU frames are drawn on, and the one rule for a thread count.

use crate::Error;
use phong_core::limits::MAX_THREADS;
use std::sync::OnceLock;

/// A pool of rendering threads chosen once and kept (`phong batch`, `phong bench`, the
/// explorer, a Python renderer), or rayon's global pool (all cores). Where the system refuses
/// threads (a process's or container's limit), a pool of one thread or of all cores draws on
/// the calling thread alone instead.
pub struct Pool(Threads);

enum Threads {
    /// rayon's global pool.
    Global,
    /// A pool of its own.
    Own(rayon::ThreadPool),
    /// The calling thread alone (no thread could be started).
    Here,
}

impl Pool {
    /// Checks a thread count: from 1 to [`MAX_THREADS`]; `None` (all cores) passes.
    pub fn check(threads: Option<usize>) -> Result<(), Error> {
        match threads {
            Some(n) if !(1..=MAX_THREADS).contains(&n) => Err(Error::ThreadCount(n)),
            _ => Ok(()),
        }
    }

    /// A pool of `threads`, or the global pool for `None` (the calling thread where the global
    /// pool cannot start its threads).
    pub fn new(threads: Option<usize>) -> Result<Pool, Error> {
        match threads {
            None if global_starts() => Ok(Pool(Threads::Global)),
            None => Ok(Pool(Threads::Here)),
            Some(_) => Pool::own(threads, "phong-render"),
        }
    }

    /// A pool of its own of `threads` (one a core for `None`), its threads named `name-i`: for
    /// a program whose frames must not wait behind other work on the global pool.
    pub fn own(threads: Option<usize>, name: &'static str) -> Result<Pool, Error> {
        Pool::check(threads)?;
        let builder = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .thread_name(move |i| format!("{name}-{i}"));
        // Tests ask for a stack no system grants, to be refused as under a thread limit.
        #[cfg(test)]
        let builder = if tests::REFUSED.get() {
            builder.stack_size(usize::MAX / 2)
        } else {
            builder
        };
        match builder.build() {
            Ok(pool) => Ok(Pool(Threads::Own(pool))),
            // One thread, or whatever the machine has: this one.
            Err(e) if refused(&e) && threads.is_none_or(|n| n == 1) => Ok(Pool(Threads::Here)),
            Err(e) => Err(Error::Threads {
                threads: threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                reason: match std::error::Error::source(&e) {
                    Some(io) => io.to_string(),
                    None => e.to_string(),
                },
            }),
        }
    }

    /// Runs `f` on the pool's threads.
    pub fn install<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        match &self.0 {
            Threads::Global => f(),
            Threads::Own(p) => p.install(f),
            Threads::Here => here(f),
        }
    }

    /// The number of threads frames are drawn on.
    pub fn threads(&self) -> usize {
        match &self.0 {
            Threads::Global => rayon::current_num_threads(),
            Threads::Own(p) => p.current_num_threads(),
            Threads::Here => 1,
        }
    }
}

/// Whether rayon's global pool could start its threads (asked once: where it could not, using
/// it would panic, so [`Pool::new`] draws on the calling thread instead). Already built (by an
/// earlier frame, or by its first use) counts as started.
fn global_starts() -> bool {
    static STARTS: OnceLock<bool> = OnceLock::new();
    *STARTS.get_or_init(|| match rayon::ThreadPoolBuilder::new().build_global() {
        Ok(()) => true,
        Err(e) => !refused(&e),
    })
}

/// Whether a pool could not be built because a thread was refused (rayon's error then has the
/// system's as its source).
fn refused(e: &rayon::ThreadPoolBuildError) -> bool {
    std::error::Error::source(e).is_some()
}

/// `f` on the calling thread as the one thread of a pool of its own, so that a frame's parallel
/// loops run here and not on rayon's global pool (which could not start). A thread that is
/// already one of a pool's runs `f` as it is, its loops on that pool.
fn here<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    thread_local! {
        static HERE: Option<rayon::ThreadPool> =
            rayon::ThreadPoolBuilder::new().num_threads(1).use_current_thread().build().ok();
    }
    HERE.with(|pool| match pool {
        Some(p) => p.install(f),
        None => f(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::cell::Cell;

    thread_local! {
        /// Whether this thread's pools are refused their threads.
        pub(super) static REFUSED: Cell<bool> = const { Cell::new(false) };
    }

    /// The count's bounds, and pools of the sizes asked for.
    #[test]
    fn counts_are_checked_and_kept() {
        assert!(matches!(Pool::check(Some(0)), Err(Error::ThreadCount(0))));
        assert!(matches!(
            Pool::new(Some(MAX_THREADS + 1)),
            Err(Error::ThreadCount(n)) if n == MAX_THREADS + 1
        ));
        assert!(Pool::check(None).is_ok() && Pool::check(Some(MAX_THREADS)).is_ok());
        assert_eq!(Pool::new(Some(3)).unwrap().threads(), 3);
        let own = Pool::own(Some(2), "test").unwrap();
        assert_eq!(own.threads(), 2);
        let name = own.install(|| std::thread::current().name().map(str::to_owned));
        assert!(name.is_some_and(|n| n.starts_with("test-")));
        assert_eq!(Pool::new(None).unwrap().threads(), rayon::current_num_threads());
    }

    /// Where threads are refused, a pool of one thread or of every core draws its parallel
    /// loops on the calling thread (the same sums); a pool of several threads asked for is an
    /// error that says why once.
    #[test]
    fn refused_threads_draw_here_or_say_why() {
        REFUSED.set(true);
        let me = std::thread::current().id();
        for threads in [Some(1), None] {
            let pool = Pool::own(threads, "test").unwrap();
            assert_eq!(pool.threads(), 1);
            let (sum, all_here) = pool.install(|| {
                let v: Vec<u64> = (0..10_000).collect();
                let sum: u64 = v.par_iter().map(|x| x * x).sum();
                let all_here = v.par_chunks(100).all(|_| std::thread::current().id() == me);
                (sum, all_here)
            });
            assert_eq!(sum, (0..10_000u64).map(|x| x * x).sum::<u64>());
            assert!(all_here, "{threads:?}");
        }
        let e = Pool::own(Some(2), "test").err().expect("two threads refused");
        let text = e.to_string();
        assert!(text.starts_with("could not start 2 rendering threads: "), "{text}");
        let reason = &text["could not start 2 rendering threads: ".len()..];
        assert!(!reason.is_empty() && !reason.contains(": "), "{text}");
        assert!(std::error::Error::source(&e).is_none(), "the reason is said once");
        REFUSED.set(false);
    }
}
