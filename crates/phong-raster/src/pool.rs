//! The threads CPU frames are drawn on, and the one rule for a thread count.

use crate::Error;
use phong_core::limits::MAX_THREADS;

/// A pool of rendering threads chosen once and kept (`phong batch`, `phong bench`, the
/// explorer, a Python renderer), or rayon's global pool (all cores).
pub struct Pool(Option<rayon::ThreadPool>);

impl Pool {
    /// Checks a thread count: from 1 to [`MAX_THREADS`]; `None` (all cores) passes.
    pub fn check(threads: Option<usize>) -> Result<(), Error> {
        match threads {
            Some(n) if !(1..=MAX_THREADS).contains(&n) => Err(Error::ThreadCount(n)),
            _ => Ok(()),
        }
    }

    /// A pool of `threads`, or the global pool for `None`.
    pub fn new(threads: Option<usize>) -> Result<Pool, Error> {
        match threads {
            None => Ok(Pool(None)),
            Some(_) => Pool::own(threads, "phong-render"),
        }
    }

    /// A pool of its own of `threads` (one a core for `None`), its threads named `name-i`: for
    /// a program whose frames must not wait behind other work on the global pool.
    pub fn own(threads: Option<usize>, name: &'static str) -> Result<Pool, Error> {
        Pool::check(threads)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .thread_name(move |i| format!("{name}-{i}"))
            .build()
            .map_err(|source| Error::Threads {
                threads: threads.unwrap_or(0),
                source,
            })?;
        Ok(Pool(Some(pool)))
    }

    /// Runs `f` on the pool's threads.
    pub fn install<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        match &self.0 {
            Some(p) => p.install(f),
            None => f(),
        }
    }

    /// The number of threads frames are drawn on.
    pub fn threads(&self) -> usize {
        match &self.0 {
            Some(p) => p.current_num_threads(),
            None => rayon::current_num_threads(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
