//! Model files read once and used many times: `phong batch` renders many views of one model,
//! and a Python loop many frames of one scene.

use phong_scene::ModelFile;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Model files kept after their first read, each until its expected uses are done (so that a
/// batch over a whole library does not keep every model). A file not announced with
/// [`Models::expect`] is read every time it is asked for, unless the cache keeps everything
/// ([`Models::keep_all`]).
#[derive(Default)]
pub struct Models {
    inner: Mutex<Inner>,
}

#[derive(Default)]
struct Inner {
    keep_all: bool,
    uses: HashMap<PathBuf, usize>,
    /// A slot per model kept: locked while its file is read, so that two threads asking for
    /// one model read it once.
    slots: HashMap<PathBuf, Arc<Mutex<Option<Arc<ModelFile>>>>>,
}

/// The cache's key for `path`: the canonical path where it has one.
fn key(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

impl Models {
    /// A cache that keeps nothing until told what to expect.
    pub fn new() -> Models {
        Models::default()
    }

    /// A cache that keeps every model it reads (a scene used for many frames).
    pub fn keep_all() -> Models {
        let m = Models::default();
        m.inner.lock().expect("not poisoned").keep_all = true;
        m
    }

    /// Announces `n` more uses of the model at `path`: it is kept from its first read until
    /// that many reads were served.
    pub fn expect(&self, path: &Path, n: usize) {
        *self
            .inner
            .lock()
            .expect("not poisoned")
            .uses
            .entry(key(path))
            .or_default() += n;
    }

    /// The model at `path`, read now or kept from an earlier read; `fresh` is true where it
    /// was read now (so that its warnings are printed once).
    pub(crate) fn get(&self, path: &Path) -> Result<(Arc<ModelFile>, bool), phong_scene::Error> {
        let k = key(path);
        let slot = {
            let mut inner = self.inner.lock().expect("not poisoned");
            (inner.keep_all || inner.uses.contains_key(&k)).then(|| inner.slots.entry(k.clone()).or_default().clone())
        };
        let Some(slot) = slot else {
            return Ok((Arc::new(ModelFile::read(path)?), true));
        };
        let result = {
            let mut guard = slot.lock().expect("not poisoned");
            match &*guard {
                Some(r) => Ok((r.clone(), false)),
                None => ModelFile::read(path).map(|r| {
                    let r = Arc::new(r);
                    *guard = Some(r.clone());
                    (r, true)
                }),
            }
        };
        self.inner.lock().expect("not poisoned").used(&k);
        result
    }

    /// Whether this cache keeps any model (it keeps all, or expects some).
    pub fn caches(&self) -> bool {
        let inner = self.inner.lock().expect("not poisoned");
        inner.keep_all || !inner.uses.is_empty()
    }

    /// How many models are kept now.
    pub fn kept(&self) -> usize {
        let inner = self.inner.lock().expect("not poisoned");
        inner
            .slots
            .values()
            .filter(|s| s.lock().expect("not poisoned").is_some())
            .count()
    }
}

impl Inner {
    /// One use of `k` served: the model is dropped after its last expected use.
    fn used(&mut self, k: &Path) {
        if self.keep_all {
            return;
        }
        if let Some(n) = self.uses.get_mut(k) {
            *n = n.saturating_sub(1);
            if *n == 0 {
                self.uses.remove(k);
                self.slots.remove(k);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn a_model_is_read_once_for_its_expected_uses_then_dropped() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.obj");
        std::fs::write(&path, TRIANGLE).expect("write");
        let models = Models::new();
        models.expect(&path, 3);
        let fresh: Vec<bool> = (0..3).map(|_| models.get(&path).expect("read").1).collect();
        assert_eq!(fresh, [true, false, false]);
        assert_eq!(models.kept(), 0, "dropped after its last use");
        assert!(models.get(&path).expect("read").1, "read again once its uses are done");
    }

    #[test]
    fn an_unannounced_model_is_not_kept_unless_all_are() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.obj");
        std::fs::write(&path, TRIANGLE).expect("write");
        let models = Models::new();
        assert!(models.get(&path).expect("read").1);
        assert!(models.get(&path).expect("read").1);
        let all = Models::keep_all();
        assert!(all.get(&path).expect("read").1);
        assert!(!all.get(&path).expect("read").1);
        assert_eq!(all.kept(), 1);
    }
}
