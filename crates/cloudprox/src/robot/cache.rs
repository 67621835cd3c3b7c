//! A few values per sampling spacing, built on first use and shared by the
//! robot's copies: the links' sampled clouds, the shadow's surface samples.

use std::sync::{Arc, Mutex, MutexGuard};

use crate::error::{Error, Result};
use crate::Real;

/// How many spacings a cache keeps: a planner queries one scene at a time.
const KEPT: usize = 4;

/// The entries of a [`SpacingCache`]: a spacing's bit pattern and its value.
type Entries<T> = Vec<(u64, Arc<T>)>;

/// Values keyed by a sampling spacing (its bit pattern), the oldest dropped
/// beyond [`KEPT`].
#[derive(Debug)]
pub(crate) struct SpacingCache<T>(Mutex<Entries<T>>);

impl<T> Default for SpacingCache<T> {
    fn default() -> Self {
        Self(Mutex::new(Vec::new()))
    }
}

impl<T> Clone for SpacingCache<T> {
    /// A cache holding the same values (empty if a thread panicked while
    /// holding it: it is only a cache).
    fn clone(&self) -> Self {
        Self(Mutex::new(
            self.0.lock().map_or_else(|_| Vec::new(), |s| s.clone()),
        ))
    }
}

impl<T> SpacingCache<T> {
    /// The value at `spacing`, built by `build` if the cache has none.
    ///
    /// # Errors
    /// `build`'s error; a cache poisoned by a panic on another thread.
    pub(crate) fn get_or_build(
        &self,
        spacing: Real,
        build: impl FnOnce() -> Result<T>,
    ) -> Result<Arc<T>> {
        let key = spacing.to_bits();
        if let Some(v) = self.find(key)? {
            return Ok(v);
        }
        // Built outside the lock: other spacings stay readable meanwhile.
        let built = Arc::new(build()?);
        let mut cache = self.lock()?;
        if let Some((_, existing)) = cache.iter().find(|(k, _)| *k == key) {
            return Ok(Arc::clone(existing));
        }
        if cache.len() >= KEPT {
            cache.remove(0);
        }
        cache.push((key, Arc::clone(&built)));
        Ok(built)
    }

    /// Drops every value.
    pub(crate) fn clear(&mut self) {
        match self.0.get_mut() {
            Ok(s) => s.clear(),
            Err(poisoned) => poisoned.into_inner().clear(),
        }
    }

    fn find(&self, key: u64) -> Result<Option<Arc<T>>> {
        let cache = self.lock()?;
        Ok(cache
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| Arc::clone(v)))
    }

    fn lock(&self) -> Result<MutexGuard<'_, Entries<T>>> {
        self.0
            .lock()
            .map_err(|_| Error::invalid("robot sample cache poisoned by an earlier panic"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn builds_once_per_spacing_and_keeps_the_newest() {
        let cache = SpacingCache::<usize>::default();
        let calls = Cell::new(0);
        let build = |v: usize| {
            calls.set(calls.get() + 1);
            Ok(v)
        };
        assert_eq!(*cache.get_or_build(0.01, || build(1)).unwrap(), 1);
        assert_eq!(*cache.get_or_build(0.01, || build(2)).unwrap(), 1);
        assert_eq!(calls.get(), 1);
        for (i, s) in [0.02, 0.03, 0.04, 0.05].into_iter().enumerate() {
            cache.get_or_build(s, || build(10 + i)).unwrap();
        }
        // 0.01 was the oldest of five: rebuilt.
        assert_eq!(*cache.get_or_build(0.01, || build(99)).unwrap(), 99);
        assert_eq!(*cache.get_or_build(0.05, || build(0)).unwrap(), 13);
    }

    #[test]
    fn a_failed_build_is_not_cached_and_clones_share_values() {
        let mut cache = SpacingCache::<usize>::default();
        assert!(cache
            .get_or_build(0.01, || Err(Error::invalid("no")))
            .is_err());
        assert_eq!(*cache.get_or_build(0.01, || Ok(3)).unwrap(), 3);
        let copy = cache.clone();
        assert_eq!(*copy.get_or_build(0.01, || Ok(4)).unwrap(), 3);
        cache.clear();
        assert_eq!(*cache.get_or_build(0.01, || Ok(5)).unwrap(), 5);
        assert_eq!(*copy.get_or_build(0.01, || Ok(6)).unwrap(), 3);
    }
}
