//! Where a load's time went (`-v`): reading files, parsing models, computing normals. Kept per
//! thread, as the texture statistics are: loading a scene is one call on one thread.

use std::cell::Cell;
use std::time::{Duration, Instant};

/// The time a load spent in each of its stages (the rest is building the scene).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoadTimes {
    /// Reading model, MTL and scene files from disk.
    pub read: Duration,
    /// Parsing model files into meshes (their reads excluded).
    pub parse: Duration,
    /// Computing vertex normals (smooth, flat or by crease angle).
    pub normals: Duration,
    /// Framing a model alone: its closedness, up axis, front and camera.
    pub framing: Duration,
}

thread_local! {
    static TIMES: Cell<LoadTimes> = Cell::new(LoadTimes::default());
}

/// This thread's stage times since the last call, and a fresh count.
pub fn take_times() -> LoadTimes {
    TIMES.with(|t| t.replace(LoadTimes::default()))
}

/// Runs `f`, adding its time to the stage `add` picks; time spent reading files inside it is
/// counted as reading only.
pub(crate) fn timed<T>(add: fn(&mut LoadTimes) -> &mut Duration, f: impl FnOnce() -> T) -> T {
    let read_before = TIMES.with(|t| t.get().read);
    let start = Instant::now();
    let out = f();
    let spent = start.elapsed();
    TIMES.with(|t| {
        let mut times = t.get();
        let inner = times.read.saturating_sub(read_before);
        *add(&mut times) += spent.saturating_sub(inner);
        t.set(times);
    });
    out
}

/// `a` on this thread and `b` on a thread of its own where the machine has two cores or more
/// (else one after the other), each timed as [`timed`] times it into the stage `add_a` or
/// `add_b` picks: the two stages then overlap in time.
pub(crate) fn timed_side_by_side<A, B: Send>(
    (add_a, a): (fn(&mut LoadTimes) -> &mut Duration, impl FnOnce() -> A),
    (add_b, b): (fn(&mut LoadTimes) -> &mut Duration, impl FnOnce() -> B + Send),
) -> (A, B) {
    if std::thread::available_parallelism().map_or(1, |n| n.get()) < 2 {
        return (timed(add_a, a), timed(add_b, b));
    }
    let (out_a, (out_b, times_b)) = std::thread::scope(|scope| {
        let other = scope.spawn(|| {
            let out = timed(add_b, b);
            (out, take_times())
        });
        let out_a = timed(add_a, a);
        match other.join() {
            Ok(b) => (out_a, b),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    });
    TIMES.with(|t| {
        let mut times = t.get();
        times.read += times_b.read;
        times.parse += times_b.parse;
        times.normals += times_b.normals;
        times.framing += times_b.framing;
        t.set(times);
    });
    (out_a, out_b)
}
