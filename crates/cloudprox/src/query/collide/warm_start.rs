//! The classifier's constraints carried from one query to the next, nearby one.
//!
//! Along a motion, consecutive states differ by at most the motion's resolution
//! (about a sensor sigma), so the samples whose constraints shaped one state's
//! separating surfaces are, mostly, those that shape the next state's. The
//! working set ([`crate::classify`]) starts from the samples nearest the other
//! cloud; given these (alone when they hold more samples of each cloud than
//! the surface has coefficients, else with the nearest), its first round is
//! more often already the optimum,
//! where it would otherwise need a second round or the whole problem. The hint
//! changes the work, not the optimum: the working set still adds every
//! violated constraint before it stops, so the surface is the cold query's to
//! the solver's tolerance. What is read off it moves by as much (`P` by up to
//! about 1e-5 in the tests), so a decision taken at a threshold (a state, a
//! misfit cut) can come out otherwise where a value lies that close to it.

/// The samples (indices into each cloud's query samples: its points, or its
/// surface elements' samples) whose constraints supported the last query's
/// surfaces.
#[derive(Debug, Clone, Default)]
pub(crate) struct WarmStart {
    /// The number of query samples of A and of B the hint was gathered on: a
    /// query on others (another cloud or model) starts without it.
    samples: (usize, usize),
    /// Sorted sample indices of cloud A and of cloud B.
    support: [Vec<u32>; 2],
    /// The current query's, gathered patch by patch.
    next: [Vec<u32>; 2],
    /// Whether the current query classified any patch.
    recorded: bool,
}

impl WarmStart {
    /// Starts a query of clouds with `na` and `nb` query samples: forgets what
    /// an unfinished one gathered, and the hint if it was gathered on clouds of
    /// other sizes.
    pub(crate) fn begin(&mut self, na: usize, nb: usize) {
        for v in &mut self.next {
            v.clear();
        }
        self.recorded = false;
        if self.samples != (na, nb) {
            self.samples = (na, nb);
            for v in &mut self.support {
                v.clear();
            }
        }
    }

    /// The working set's hint for a patch of A's samples `ia` and B's `ib`:
    /// one flag per sample, A's first, set where the last query's surfaces
    /// were supported by that sample.
    pub(crate) fn hint(&self, ia: &[u32], ib: &[u32]) -> Vec<bool> {
        let had = |side: &[u32], i: &u32| side.binary_search(i).is_ok();
        ia.iter()
            .map(|i| had(&self.support[0], i))
            .chain(ib.iter().map(|i| had(&self.support[1], i)))
            .collect()
    }

    /// Records a patch's supporting samples (`support` one flag per sample,
    /// A's first, as [`hint`](Self::hint); empty when the solver reported none).
    pub(crate) fn record(&mut self, ia: &[u32], ib: &[u32], support: &[bool]) {
        self.recorded = true;
        let ids = ia.iter().chain(ib).zip(support);
        for (k, (&i, &s)) in ids.enumerate() {
            if s {
                self.next[usize::from(k >= ia.len())].push(i);
            }
        }
    }

    /// Ends a query: what it gathered becomes the hint of the next, unless it
    /// classified nothing (a query decided by its bounds, or free), which
    /// keeps the last hint.
    pub(crate) fn finish(&mut self) {
        if !self.recorded {
            return;
        }
        for (support, next) in self.support.iter_mut().zip(&mut self.next) {
            next.sort_unstable();
            next.dedup();
            std::mem::swap(support, next);
            next.clear();
        }
        self.recorded = false;
    }

    /// The samples of A and of B currently hinted.
    #[cfg(test)]
    pub(crate) fn support(&self) -> (&[u32], &[u32]) {
        (&self.support[0], &self.support[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_patch_s_support_is_hinted_to_the_next_query_by_sample_index() {
        let mut w = WarmStart::default();
        w.begin(10, 10);
        // Two patches: A's 7 and 3 with B's 2 and 9; then A's 5 with B's 9.
        w.record(&[7, 3], &[2, 9], &[true, false, false, true]);
        w.record(&[5], &[9], &[true, true]);
        // Nothing is hinted before the query ends.
        assert!(w.hint(&[7, 5], &[9]).iter().all(|&h| !h));
        w.finish();
        assert_eq!(w.support(), (&[5, 7][..], &[9][..]));
        // A patch of the next query, other samples among them, in another order.
        assert_eq!(
            w.hint(&[1, 5, 7, 3], &[9, 2]),
            [false, true, true, false, true, false]
        );
    }

    #[test]
    fn a_query_that_classifies_nothing_keeps_the_hint_and_an_unfinished_one_leaves_nothing() {
        let mut w = WarmStart::default();
        w.begin(10, 10);
        w.record(&[4], &[6], &[true, true]);
        w.finish();
        // Decided by bounds: nothing recorded.
        w.begin(10, 10);
        w.finish();
        assert_eq!(w.support(), (&[4][..], &[6][..]));
        // A query that failed midway (recorded, never finished) is forgotten
        // by the next one's begin.
        w.begin(10, 10);
        w.record(&[8], &[1], &[true, true]);
        w.begin(10, 10);
        w.record(&[2], &[3], &[false, true]);
        w.finish();
        assert_eq!(w.support(), (&[][..], &[3][..]));
        // The solver reported no support (Clarabel's fallback): the next
        // query starts without a hint.
        w.begin(10, 10);
        w.record(&[2], &[3], &[]);
        w.finish();
        assert_eq!(w.support(), (&[][..], &[][..]));
        // A query of clouds of other sizes starts without the hint.
        w.begin(10, 10);
        w.record(&[4], &[6], &[true, true]);
        w.finish();
        w.begin(10, 11);
        assert!(w.hint(&[4], &[6]).iter().all(|&h| !h));
    }
}
