//! Neighbourhood queries over the points of one patch side: a hierarchy built
//! for the query (or, as the tests' reference, a scan over every point).

use crate::bvh::{Bvh, BvhSettings, BvhWorkspace};
use crate::math::Point3;
use crate::Real;

/// Nearest-neighbour and radius queries over a slice of points.
pub(crate) struct PointSearch<'a> {
    points: &'a [Point3],
    tree: Option<(Bvh, BvhWorkspace)>,
}

impl<'a> PointSearch<'a> {
    /// A search over `points` by a hierarchy (`indexed`), else by scanning
    /// every point (also where the hierarchy cannot be built: no points).
    pub(crate) fn new(points: &'a [Point3], indexed: bool) -> Self {
        let tree = indexed
            .then(|| Bvh::build(points, &vec![0.0; points.len()], &BvhSettings::default()).ok())
            .flatten()
            .map(|t| (t, BvhWorkspace::default()));
        Self { points, tree }
    }

    /// The points searched.
    pub(crate) fn points(&self) -> &'a [Point3] {
        self.points
    }

    /// The `k` nearest points of `x` (`1 <= k <=` their number) as `(squared
    /// distance, index)`, nearest first, into `out`. Which of several points
    /// at exactly the `k`-th distance is taken depends on the search.
    pub(crate) fn nearest(&mut self, x: &Point3, k: usize, out: &mut Vec<(Real, u32)>) {
        if let Some((tree, workspace)) = &mut self.tree {
            tree.nearest_k(self.points, x, k, workspace, out);
            return;
        }
        out.clear();
        out.extend(
            self.points
                .iter()
                .zip(0u32..)
                .map(|(y, j)| ((y - x).norm_squared(), j)),
        );
        out.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
        out.truncate(k);
        out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    }

    /// The points with `(p - x).norm() <= r`, into `out`, in index order.
    pub(crate) fn within(&mut self, x: &Point3, r: Real, out: &mut Vec<u32>) {
        if let Some((tree, workspace)) = &mut self.tree {
            tree.within_radius(self.points, x, r, workspace, out);
            out.sort_unstable();
            return;
        }
        out.clear();
        out.extend(
            self.points
                .iter()
                .zip(0u32..)
                .filter(|(p, _)| (*p - x).norm() <= r)
                .map(|(_, j)| j),
        );
    }

    /// Every point's neighbourhood among the searched points: the point and its
    /// `k - 1` nearest others (fewer in a smaller set).
    pub(crate) fn neighbourhoods(&mut self, k: usize) -> Neighbourhoods {
        let k = k.min(self.points.len());
        let mut entries = Vec::with_capacity(k * self.points.len());
        let mut one = Vec::with_capacity(k);
        for x in self.points {
            self.nearest(x, k, &mut one);
            one.sort_unstable_by_key(|&(_, j)| j);
            entries.extend_from_slice(&one);
        }
        Neighbourhoods { k, entries }
    }
}

/// The `k` nearest points of every point of a set (the point itself among
/// them), each point's in index order: sums over a neighbourhood add in the
/// same order whichever search found it.
pub(crate) struct Neighbourhoods {
    k: usize,
    entries: Vec<(Real, u32)>,
}

impl Neighbourhoods {
    /// Point `i`'s neighbourhood as `(squared distance, index)`, in index order.
    pub(crate) fn of(&self, i: usize) -> &[(Real, u32)] {
        &self.entries[i * self.k..(i + 1) * self.k]
    }

    /// The distance from point `i` to the farthest point of its neighbourhood.
    pub(crate) fn radius(&self, i: usize) -> Real {
        self.of(i).iter().map(|e| e.0).fold(0.0, Real::max).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hierarchy_finds_what_a_scan_finds() {
        let mut seed = 5u64;
        let mut uniform = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as Real) / ((1u64 << 53) as Real)
        };
        // A thin noisy sheet, denser at one end.
        let pts: Vec<Point3> = (0..600)
            .map(|_| {
                let u = uniform();
                Point3::new(u * u, uniform(), 0.01 * uniform())
            })
            .collect();
        let (mut tree, mut scan) = (PointSearch::new(&pts, true), PointSearch::new(&pts, false));
        assert!(tree.tree.is_some() && scan.tree.is_none());
        for k in [1, 7, 40] {
            let (a, b) = (tree.neighbourhoods(k), scan.neighbourhoods(k));
            for i in 0..pts.len() {
                assert_eq!(a.of(i), b.of(i));
                assert!(a.of(i).iter().any(|&(d, j)| j as usize == i && d == 0.0));
                assert!(a.of(i).windows(2).all(|w| w[0].1 < w[1].1));
                assert_eq!(a.radius(i), b.radius(i));
            }
        }
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (i, p) in pts.iter().enumerate().step_by(13) {
            let r = 0.02 * (1 + i % 5) as Real;
            tree.within(p, r, &mut x);
            scan.within(p, r, &mut y);
            assert_eq!(x, y);
            assert!(x.contains(&(i as u32)));
        }
        // A set smaller than k: every point is in every neighbourhood.
        let few = &pts[..3];
        let n = PointSearch::new(few, true).neighbourhoods(7);
        assert_eq!(
            n.of(2).iter().map(|e| e.1).collect::<Vec<_>>(),
            vec![0, 1, 2]
        );
        // No points: no hierarchy, nothing found.
        let mut none = PointSearch::new(&[], true);
        assert!(none.tree.is_none());
        none.within(&pts[0], 1.0, &mut x);
        assert!(x.is_empty());
    }
}
