//! How a stage runs two pieces of work that do not depend on each other. phong-core starts no
//! threads: a stage that can split its work takes a [`Join`], and its caller chooses one piece
//! after the other ([`InTurn`]) or side by side (phong-scene's loaders, on threads of their
//! own). Either gives the same values.

/// Runs `a` and `b`, one after the other or at the same time, and returns both results.
pub trait Join {
    /// `(a(), b())`.
    fn join<A, B: Send>(&self, a: impl FnOnce() -> A, b: impl FnOnce() -> B + Send) -> (A, B);
}

/// `a`, then `b`, on the calling thread.
#[derive(Clone, Copy, Debug, Default)]
pub struct InTurn;

impl Join for InTurn {
    fn join<A, B: Send>(&self, a: impl FnOnce() -> A, b: impl FnOnce() -> B + Send) -> (A, B) {
        let a = a();
        (a, b())
    }
}
