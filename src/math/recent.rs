//! The last few expensive tables a process built, kept by the description they were
//! built from: a scene loaded again (by a test, a Python session, `heron converge`'s
//! reference and its runs) finds its halo table or ice phase function instead of tracing
//! tens of millions of rays again.
use std::sync::{Arc, Mutex};

/// Up to `capacity` values by key, the oldest dropped first.
pub struct Recent<T> {
    capacity: usize,
    entries: Mutex<Vec<(String, Arc<T>)>>,
}

impl<T> Recent<T> {
    pub const fn new(capacity: usize) -> Self {
        Recent {
            capacity,
            entries: Mutex::new(Vec::new()),
        }
    }

    /// The value kept under `key`, or `build()`'s, then kept. The lock is not held while
    /// building, so two threads may build the same value; both are the same.
    pub fn get_or_build(&self, key: String, build: impl FnOnce() -> T) -> Arc<T> {
        let lock = || self.entries.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, v)) = lock().iter().find(|(k, _)| *k == key) {
            return v.clone();
        }
        let v = Arc::new(build());
        let mut entries = lock();
        if entries.len() == self.capacity {
            entries.remove(0);
        }
        entries.push((key, v.clone()));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_last_values_by_key() {
        let cache: Recent<u32> = Recent::new(2);
        let mut built = 0;
        let mut get = |k: &str, v: u32| {
            *cache.get_or_build(k.to_string(), || {
                built += 1;
                v
            })
        };
        assert_eq!(get("a", 1), 1);
        assert_eq!(get("a", 9), 1);
        assert_eq!(get("b", 2), 2);
        assert_eq!(get("c", 3), 3);
        // "a" was the oldest and is gone.
        assert_eq!(get("a", 4), 4);
        assert_eq!(built, 4);
    }
}
