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

/// Stage by stage.
impl std::ops::Add for LoadTimes {
    type Output = LoadTimes;
    fn add(mut self, t: LoadTimes) -> LoadTimes {
        let LoadTimes {
            read,
            parse,
            normals,
            framing,
        } = t;
        self.read += read;
        self.parse += parse;
        self.normals += normals;
        self.framing += framing;
        self
    }
}

/// Adds `t` (another thread's stage times, taken where it ends) to this thread's.
pub(crate) fn add_times(t: LoadTimes) {
    TIMES.with(|c| c.set(c.get() + t));
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
