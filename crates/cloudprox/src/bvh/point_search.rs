//! Neighbourhood queries over a set of points during a query (a patch side's
//! points, a region's element means): a hierarchy built for the query above
//! [`SEARCH_TREE_MIN`] points, a scan over every point below (the tests
//! compare the two, and both with a full sort of every point).
//!
//! Ties at the `k`-th distance go to the smaller index in both, as in the
//! hashed grid's k-NN: a grid-sampled surface (a depth image, a lattice)
//! gives many, and which of them is taken changes a neighbourhood. Both keep
//! their `k` nearest with the same insertion (`offer_nearest`).
//!
//! [`super::knn_of_every_point`] is the other k-NN of the crate: a whole
//! cloud's, in parallel, when the cloud is prepared; this one runs inside one
//! query, on one thread.

use std::borrow::Cow;
use std::cell::RefCell;

use crate::bvh::bvh_nearest::offer_nearest;
use crate::bvh::{Bvh, BvhSettings, BvhWorkspace};
use crate::math::Point3;
use crate::Real;

/// Above this many points a search builds a hierarchy.
pub(crate) const SEARCH_TREE_MIN: usize = 32;

/// Nearest-neighbour and radius queries over a set of points.
pub(crate) struct PointSearch<'a> {
    points: Cow<'a, [Point3]>,
    /// The hierarchy and its traversal's scratch space (queries take `&self`,
    /// so that the points can be read while searching).
    tree: Option<(Bvh, RefCell<BvhWorkspace>)>,
}

impl<'a> PointSearch<'a> {
    /// A search over `points`: by a hierarchy above [`SEARCH_TREE_MIN`]
    /// points, else by scanning them.
    pub(crate) fn new(points: impl Into<Cow<'a, [Point3]>>) -> Self {
        let points = points.into();
        let tree = if points.len() > SEARCH_TREE_MIN {
            Bvh::build(&points, &vec![0.0; points.len()], &BvhSettings::default())
                .ok()
                .map(|t| (t, RefCell::new(BvhWorkspace::default())))
        } else {
            None
        };
        Self { points, tree }
    }

    /// A search that scans every point (compared with the hierarchy in tests).
    #[cfg(test)]
    pub(crate) fn scan(points: impl Into<Cow<'a, [Point3]>>) -> Self {
        Self {
            points: points.into(),
            tree: None,
        }
    }

    /// The points searched.
    pub(crate) fn points(&self) -> &[Point3] {
        &self.points
    }

    /// The `k` nearest points of `x` (all of them if there are fewer) as
    /// `(squared distance, index)`, nearest first, ties by index, into `out`.
    pub(crate) fn nearest(&self, x: &Point3, k: usize, out: &mut Vec<(Real, u32)>) {
        let k = k.min(self.points.len());
        if let Some((tree, workspace)) = &self.tree {
            tree.nearest_k(&self.points, x, k, &mut workspace.borrow_mut(), out);
            return;
        }
        out.clear();
        if k == 0 {
            return;
        }
        for (y, j) in self.points.iter().zip(0u32..) {
            offer_nearest(out, k, (y - x).norm_squared(), j);
        }
    }

    /// The candidates that can be among the `k` nearest points of any `x`
    /// within `r` of `centre` (those within `d_k + 2 r` of `centre`, `d_k`
    /// the distance of its `k`-th nearest: every point nearer `x` than its
    /// `k`-th nearest lies there, by the triangle inequality), into `out` in
    /// index order; [`PointSearch::nearest_among`] then finds them as
    /// [`PointSearch::nearest`] would, with one search for many nearby `x`.
    pub(crate) fn candidates_near(
        &self,
        centre: &Point3,
        r: Real,
        k: usize,
        scratch: &mut Vec<(Real, u32)>,
        out: &mut Vec<u32>,
    ) {
        self.nearest(centre, k, scratch);
        let Some(&(d2, _)) = scratch.last() else {
            out.clear();
            return;
        };
        // A relative margin over the rounding of the distances.
        let reach = (d2.sqrt() + 2.0 * r) * (1.0 + 1e-9);
        self.within(centre, reach, out);
    }

    /// The `k` nearest points of `x` among `candidates` (from
    /// [`PointSearch::candidates_near`] for a centre within its `r` of `x`):
    /// the same as [`PointSearch::nearest`], ties by index.
    pub(crate) fn nearest_among(
        &self,
        x: &Point3,
        k: usize,
        candidates: &[u32],
        out: &mut Vec<(Real, u32)>,
    ) {
        out.clear();
        let k = k.min(candidates.len());
        if k == 0 {
            return;
        }
        for &j in candidates {
            offer_nearest(out, k, (self.points[j as usize] - x).norm_squared(), j);
        }
    }

    /// The points with `(p - x).norm() <= r`, into `out`, in index order.
    pub(crate) fn within(&self, x: &Point3, r: Real, out: &mut Vec<u32>) {
        if let Some((tree, workspace)) = &self.tree {
            tree.within_radius(&self.points, x, r, &mut workspace.borrow_mut(), out);
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

    /// Every point's neighbourhood among the searched points: its `k` nearest
    /// (fewer in a smaller set; the point itself among them unless more than
    /// `k` points share its position), each in index order.
    pub(crate) fn neighbourhoods(&self, k: usize) -> Neighbourhoods {
        let k = k.min(self.points.len());
        let n = self.points.len();
        let mut entries = Vec::with_capacity(k * n);
        let mut one = Vec::with_capacity(k);
        for x in self.points.iter() {
            self.nearest(x, k, &mut one);
            one.sort_unstable_by_key(|&(_, j)| j);
            entries.extend_from_slice(&one);
        }
        Neighbourhoods { k, entries }
    }
}

/// The `k` nearest points of every point of a set, each point's in index
/// order: sums over a neighbourhood add in the same order whichever search
/// found it.
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
    use crate::math::Vector3;

    fn check(pts: &[Point3], radii: &[Real]) {
        let (tree, scan) = (PointSearch::new(pts), PointSearch::scan(pts));
        assert!(tree.tree.is_some() && scan.tree.is_none());
        for k in [1, 7, 40] {
            let (a, b) = (tree.neighbourhoods(k), scan.neighbourhoods(k));
            for i in 0..pts.len() {
                assert_eq!(a.of(i), b.of(i), "k {k}, point {i}");
                assert!(a.of(i).iter().any(|&(d, j)| j as usize == i && d == 0.0));
                assert!(a.of(i).windows(2).all(|w| w[0].1 < w[1].1));
                assert_eq!(a.radius(i), b.radius(i));
            }
        }
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (i, p) in pts.iter().enumerate().step_by(13) {
            for &r in radii {
                tree.within(p, r, &mut x);
                scan.within(p, r, &mut y);
                assert_eq!(x, y);
                assert!(x.contains(&(i as u32)));
            }
        }
    }

    #[test]
    fn the_hierarchy_finds_what_a_scan_finds() {
        let mut uniform = crate::sample::lcg_uniform(5);
        // A thin noisy sheet, denser at one end.
        let sheet: Vec<Point3> = (0..600)
            .map(|_| {
                let u = uniform();
                Point3::new(u * u, uniform(), 0.01 * uniform())
            })
            .collect();
        check(&sheet, &[0.02, 0.05, 0.1]);
        // A lattice: every point has four neighbours at one spacing and four
        // at the diagonal, so the 7 nearest are decided by the ties' indices;
        // the radii fall on lattice distances.
        let lattice: Vec<Point3> = (0..900)
            .map(|i| Point3::new((i % 30) as Real * 0.01, (i / 30) as Real * 0.01, 0.0))
            .collect();
        check(&lattice, &[0.01, 0.02 * std::f64::consts::SQRT_2, 0.03]);
    }

    #[test]
    fn the_nearest_among_an_elements_candidates_are_the_nearest_of_all() {
        // A lattice (ties at most k-th distances) and a noisy sheet; centres
        // on and off the points, probes scattered within `r` of each.
        let mut uniform = crate::sample::lcg_uniform(11);
        let lattice: Vec<Point3> = (0..400)
            .map(|i| Point3::new((i % 20) as Real, (i / 20) as Real, 0.0))
            .collect();
        let sheet: Vec<Point3> = (0..300)
            .map(|_| Point3::new(20.0 * uniform(), 20.0 * uniform(), 0.3 * uniform()))
            .collect();
        for pts in [lattice, sheet] {
            let search = PointSearch::new(&pts[..]);
            let (mut scratch, mut cand, mut got, mut want) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for c in 0..25 {
                let centre = Point3::new(0.8 * c as Real, 0.7 * c as Real, 0.0);
                for (k, r) in [(1, 0.0), (6, 1.5), (6, 4.0), (12, 2.5)] {
                    search.candidates_near(&centre, r, k, &mut scratch, &mut cand);
                    assert!(cand.len() < pts.len() || r >= 4.0, "centre {c}: no pruning");
                    for p in 0..20 {
                        let a = std::f64::consts::TAU * p as Real / 20.0;
                        let x = centre
                            + Vector3::new(a.cos(), a.sin(), 0.0) * r * (p % 3) as Real / 2.0;
                        search.nearest_among(&x, k, &cand, &mut got);
                        search.nearest(&x, k, &mut want);
                        assert_eq!(got, want, "centre {c}, k {k}, r {r}, probe {p}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_nearest_are_the_first_of_all_points_sorted_by_distance_then_index() {
        // The reference sorts every point, independently of the insertion
        // both searches share; a lattice makes most k-th distances ties.
        let lattice: Vec<Point3> = (0..400)
            .map(|i| Point3::new((i % 20) as Real, (i / 20) as Real, 0.0))
            .collect();
        let (tree, scan) = (
            PointSearch::new(&lattice[..]),
            PointSearch::scan(&lattice[..]),
        );
        let mut out = Vec::new();
        for q in [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(7.0, 9.0, 0.0),
            Point3::new(7.5, 9.5, 1.0),
            Point3::new(19.0, 3.5, 0.0),
        ] {
            let mut all: Vec<(Real, u32)> = lattice
                .iter()
                .zip(0u32..)
                .map(|(p, j)| ((p - q).norm_squared(), j))
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            // Beyond the number of points: all of them.
            for k in [1, 2, 5, 9, 40, 400, 450] {
                for search in [&tree, &scan] {
                    search.nearest(&q, k, &mut out);
                    assert_eq!(out, all[..k.min(all.len())], "query {q:?}, k {k}");
                }
            }
        }
    }

    #[test]
    fn small_and_empty_sets() {
        let pts: Vec<Point3> = (0..5).map(|i| Point3::new(i as Real, 0.0, 0.0)).collect();
        // Few points: a scan; fewer than k: every point in every neighbourhood.
        let few = PointSearch::new(&pts[..3]);
        assert!(few.tree.is_none());
        let n = few.neighbourhoods(7);
        assert_eq!(
            n.of(2).iter().map(|e| e.1).collect::<Vec<_>>(),
            vec![0, 1, 2]
        );
        let mut out = vec![(1.0, 1)];
        few.nearest(&pts[0], 0, &mut out);
        assert!(out.is_empty());
        // An owned set, as the element means are.
        let owned = PointSearch::new(pts.clone());
        owned.nearest(&Point3::new(2.6, 0.0, 0.0), 2, &mut out);
        assert_eq!(out.iter().map(|e| e.1).collect::<Vec<_>>(), vec![3, 2]);
        // No points: nothing found.
        let none = PointSearch::new(&[][..]);
        none.within(&pts[0], 1.0, &mut Vec::new());
        let mut w = vec![3];
        none.within(&pts[0], 1.0, &mut w);
        assert!(w.is_empty());
        none.nearest(&pts[0], 3, &mut out);
        assert!(out.is_empty());
    }
}
