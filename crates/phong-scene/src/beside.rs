//! Loading's work side by side on threads of its own (a model's halves, an OBJ's runs of
//! lines, a texture's maps). Where the system refuses a thread (a process's or container's
//! limit), the threads it did start, this one at least, do that thread's share: the same
//! values, never a panic. The only place in this crate that starts threads.

use phong_core::join::Join;
use std::sync::{Mutex, OnceLock, PoisonError};
use std::thread::{Scope, ScopedJoinHandle};

/// Side by side: `b` on a thread of its own where the machine has two cores or more.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Beside;

impl Join for Beside {
    fn join<A, B: Send>(&self, a: impl FnOnce() -> A, b: impl FnOnce() -> B + Send) -> (A, B) {
        if cores() < 2 {
            let a = a();
            return (a, b());
        }
        // `b` goes to whichever thread takes it first: the other, or this one after `a`
        // (where the other could not be started, or has not started yet).
        let b = Mutex::new(Some(b));
        let take_b = || {
            let b = b.lock().unwrap_or_else(PoisonError::into_inner).take();
            b.map(|b| b())
        };
        std::thread::scope(|scope| {
            let other = spawn(scope, take_b);
            let a = a();
            let b = take_b().or_else(|| joined(other.ok()?));
            (a, b.expect("b is done by one of the two threads"))
        })
    }
}

/// `f` of each item, in order, on up to `threads` threads (this one and others of its own),
/// each taking the next item as it comes free.
pub(crate) fn map<T: Send, R: Send>(items: Vec<T>, threads: usize, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    let n = items.len();
    let queue = Mutex::new(items.into_iter().enumerate());
    let work = || {
        let mut done = Vec::new();
        loop {
            let next = queue.lock().unwrap_or_else(PoisonError::into_inner).next();
            let Some((i, item)) = next else {
                break done;
            };
            done.push((i, f(item)));
        }
    };
    let mut done = std::thread::scope(|scope| {
        let others: Vec<_> = (1..threads.min(n)).filter_map(|_| spawn(scope, work).ok()).collect();
        let mut done = work();
        done.extend(others.into_iter().flat_map(joined));
        done
    });
    done.sort_unstable_by_key(|&(i, _)| i);
    done.into_iter().map(|(_, r)| r).collect()
}

/// The cores this process may use (asked once: on Linux it reads the cgroup's files).
pub(crate) fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// `f` on a thread of its own, or the system's refusal.
fn spawn<'scope, R: Send + 'scope>(
    scope: &'scope Scope<'scope, '_>,
    f: impl FnOnce() -> R + Send + 'scope,
) -> std::io::Result<ScopedJoinHandle<'scope, R>> {
    let builder = std::thread::Builder::new();
    // Tests ask for a stack no system grants, to be refused as under a thread limit.
    #[cfg(test)]
    let builder = if tests::REFUSED.get() {
        builder.stack_size(usize::MAX / 2)
    } else {
        builder
    };
    builder.spawn_scoped(scope, f)
}

/// A thread's result; its panic goes on in this thread.
fn joined<R>(h: ScopedJoinHandle<'_, R>) -> R {
    h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::cell::Cell;
    use std::thread::ThreadId;

    thread_local! {
        /// Whether this thread's requests for threads are refused.
        pub(crate) static REFUSED: Cell<bool> = const { Cell::new(false) };
    }

    /// `f()` with every thread it asks for refused.
    pub(crate) fn refused<R>(f: impl FnOnce() -> R) -> R {
        REFUSED.set(true);
        let r = f();
        REFUSED.set(false);
        r
    }

    fn here() -> ThreadId {
        std::thread::current().id()
    }

    #[test]
    fn a_refused_thread_is_refused() {
        let r = refused(|| std::thread::scope(|s| spawn(s, || 1).is_err()));
        assert!(r);
        assert!(std::thread::scope(|s| spawn(s, || 1).map(joined).ok()) == Some(1));
    }

    /// Both results, in their places, with or without threads; refused, everything on this
    /// thread.
    #[test]
    fn join_runs_both() {
        let me = here();
        let (a, b) = Beside.join(|| (1, here()), || ("two", here()));
        assert_eq!((a.0, b.0), (1, "two"));
        assert_eq!(a.1, me);
        let (a, b) = refused(|| Beside.join(|| (1, here()), || ("two", here())));
        assert_eq!((a, b), ((1, me), ("two", me)));
    }

    /// Every item once, results in the items' order, on more than one thread where there are
    /// cores; refused, on this thread alone.
    #[test]
    fn map_keeps_order() {
        let items: Vec<u64> = (0..200).collect();
        let slow_square = |x: u64| {
            std::thread::sleep(std::time::Duration::from_micros(200));
            (x * x, here())
        };
        let expected: Vec<u64> = items.iter().map(|x| x * x).collect();
        let out = map(items.clone(), 4, slow_square);
        assert_eq!(out.iter().map(|o| o.0).collect::<Vec<_>>(), expected);
        let threads: std::collections::HashSet<_> = out.iter().map(|o| o.1).collect();
        assert!(threads.len() > 1);
        let out = refused(|| map(items, 4, slow_square));
        assert_eq!(out.iter().map(|o| o.0).collect::<Vec<_>>(), expected);
        assert!(out.iter().all(|o| o.1 == here()));
        assert!(map(Vec::<u8>::new(), 4, |x| x).is_empty());
    }

    /// A panic on another thread reaches the caller.
    #[test]
    fn a_thread_s_panic_goes_on() {
        let r = std::panic::catch_unwind(|| map(vec![0, 1, 2, 3], 4, |x| assert!(x != 2, "item two")));
        assert!(r.is_err());
    }

    /// A large model in each format whose loading splits its work (an OBJ's runs of lines, a
    /// PLY's normals beside its framing, a glTF's flat normals in halves) gives the same scene
    /// with every thread refused.
    #[test]
    fn models_load_alike_without_threads() {
        let mesh = phong_core::primitives::sphere(160);
        let (p, t) = (mesh.positions(), mesh.triangles());
        let dir = std::env::temp_dir().join(format!("phong-beside-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut obj = String::new();
        p.iter().for_each(|v| obj += &format!("v {} {} {}\n", v.x, v.y, v.z));
        t.iter()
            .for_each(|f| obj += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1));
        let mut ply = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
             property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
            p.len(),
            t.len()
        )
        .into_bytes();
        p.iter().for_each(|v| ply.extend(bytemuck::bytes_of(v)));
        t.iter().for_each(|f| {
            ply.push(3);
            ply.extend(bytemuck::bytes_of(f));
        });
        let mut bin: Vec<u8> = bytemuck::cast_slice(p).to_vec();
        bin.extend(bytemuck::cast_slice::<[u32; 3], u8>(t));
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{{"byteLength":{len}}}],
            "bufferViews":[{{"buffer":0,"byteLength":{pl}}},{{"buffer":0,"byteOffset":{pl},"byteLength":{tl}}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{pc},"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]}},
            {{"bufferView":1,"componentType":5125,"count":{tc},"type":"SCALAR"}}]}}"#,
            len = bin.len(),
            pl = 12 * p.len(),
            tl = 12 * t.len(),
            pc = p.len(),
            tc = 3 * t.len()
        );
        let mut json = json.into_bytes();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut glb = b"glTF".to_vec();
        let total = 12 + 8 + json.len() + 8 + bin.len();
        for w in [2, total as u32, json.len() as u32, 0x4E4F_534A] {
            glb.extend(w.to_le_bytes());
        }
        glb.extend(&json);
        glb.extend([bin.len() as u32, 0x004E_4942].map(u32::to_le_bytes).concat());
        glb.extend(&bin);
        let files = [
            ("sphere.obj", obj.into_bytes()),
            ("sphere.ply", ply),
            ("sphere.glb", glb),
        ];
        for (name, bytes) in files {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            let load = || crate::load(&path).unwrap();
            let (threads, alone) = (load(), refused(load));
            assert_eq!(threads.scene.objects.len(), 1, "{name}");
            assert_eq!(format!("{:?}", threads.scene), format!("{:?}", alone.scene), "{name}");
            assert_eq!(threads.notes, alone.notes, "{name}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
