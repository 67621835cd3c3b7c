//! Near regions: connected groups of kept leaf pairs, split into patches.

use std::collections::HashMap;

use crate::bvh::{Aabb, Bvh};
use crate::cloud::PointCloud;
use crate::math::{Matrix3, Point3, Pose, PrincipalAxes, Vector3};
use crate::probability::normal_quantile;
use crate::query::collide::contact::mean;
use crate::Real;

/// A set of points of both clouds classified together.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Patch {
    /// Connected near region the patch comes from.
    pub component: u32,
    /// Point indices of cloud A.
    pub a: Vec<u32>,
    /// Point indices of cloud B.
    pub b: Vec<u32>,
}

/// The margin, in sampling spacings, by which two samples may be farther apart
/// than the surfaces they sample.
pub const SAMPLING_MARGIN: Real = 0.5;

/// The near rule for points `x_i`, `x_j` at distance `d`, with `h` the larger
/// of their sampling spacings: near when the noise reaches across the distance
/// less half a spacing, `prune_bound(max(0, d - h/2), s_i, s_j, 2) >= epsilon`
/// (sampled surfaces can meet between samples), or, as context, when
/// `d <= context * h`: the classifier sees at least `context` spacings of
/// surface around the contact, which matters where the sampling is sparse
/// against the noise, and adds nothing where the noise's reach is wider.
///
/// `s_i = sqrt(u^T Sigma_i u)` is point `i`'s *sensor* standard deviation along
/// the line `u` joining the two points (the noise that can carry one towards the
/// other). The discretization part of the covariance is left out: it spreads
/// along the surface and stands for where between the samples the surface is,
/// which the half spacing already covers; counting it across the gap made every
/// region as wide as the sampling is sparse (measured: near regions of 400-1000
/// points and 31% false collisions beyond 3 sigma on the piano scene at 5 cm
/// spacing, 1.45 cm noise). The hierarchy prunes with the largest sensor
/// standard deviations (a superset).
///
/// The bound is evaluated through its inverse, `max(0, d - h/2) <= (s_i + s_j)
/// k` with `k = Phi^-1(1 - epsilon / 2)` ([`NearRule::new`]), so no
/// transcendental function runs per pair.
///
/// A sample marked to measure its context in its *own* spacing (the elements
/// model's single-point elements: points that fit no surface with their
/// neighbours) joins as context only when `d <= context * h_i`; its partner
/// keeps `context * h`. A noise-free robot link sampled from its mesh is such
/// points only (its covariance across the surface is the discretization's
/// alone, so every curvature is significant), while a scanned table top is
/// large elements whose grid samples lie six spacings apart: measured in the
/// larger spacing, the context took every point of the link within two grid
/// pitches of the table (regions of 1 000-2 000 samples where the points
/// model reads 200-400).
#[derive(Debug, Clone, Copy)]
struct NearRule {
    k: Real,
    context: Real,
}

/// One cloud's noise as the near rule reads it: spacings, smallest and largest
/// sensor standard deviations, sensor covariances, and the rotation from B's
/// frame into the cloud's own.
struct CloudNoise<'a> {
    spacing: &'a [Real],
    own_context: Option<&'a [bool]>,
    sigma_min: &'a [Real],
    sigma_max: &'a [Real],
    cov: &'a [Matrix3],
    to_own_frame: Matrix3,
}

impl<'a> CloudNoise<'a> {
    fn new(cloud: &'a PointCloud, to_own_frame: Matrix3, own_context: Option<&'a [bool]>) -> Self {
        Self {
            spacing: cloud.spacing(),
            own_context,
            sigma_min: cloud.sensor_sigma_min(),
            sigma_max: cloud.sensor_sigma_max(),
            cov: cloud.sensor_covariances(),
            to_own_frame,
        }
    }

    /// Point `i`, at `x` in B's frame.
    fn point(&self, i: usize, x: Point3) -> PointNoise<'_> {
        PointNoise {
            x,
            spacing: self.spacing[i],
            own_context: self.own_context.is_some_and(|o| o[i]),
            sigma_min: self.sigma_min[i],
            sigma_max: self.sigma_max[i],
            cov: &self.cov[i],
            to_own_frame: &self.to_own_frame,
        }
    }
}

/// One point's side of a pair test (see [`CloudNoise`]).
struct PointNoise<'a> {
    x: Point3,
    spacing: Real,
    own_context: bool,
    sigma_min: Real,
    sigma_max: Real,
    cov: &'a Matrix3,
    to_own_frame: &'a Matrix3,
}

impl PointNoise<'_> {
    fn std_along(&self, u: &Vector3) -> Real {
        let v = self.to_own_frame * u;
        v.dot(&(self.cov * v)).max(0.0).sqrt()
    }
}

impl NearRule {
    fn new(epsilon: Real, context: Real) -> Self {
        Self {
            k: -normal_quantile(0.5 * epsilon),
            context,
        }
    }

    // Called for every candidate pair of `near_points`: the compiler's own
    // choice to inline it or not came and went with unrelated changes of the
    // crate (the call cost the near-contact queries 5-11%; measured with
    // `benches/query.rs`).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn near_sides(&self, i: &PointNoise<'_>, j: &PointNoise<'_>) -> (bool, bool) {
        let diff = j.x - i.x;
        let d2 = diff.norm_squared();
        let h = i.spacing.max(j.spacing);
        if !(i.own_context || j.own_context) {
            let context = self.context * h;
            let near = d2 <= context * context || self.noise_reaches(i, j, diff, d2, h);
            return (near, near);
        }
        let within = |p: &PointNoise<'_>| {
            let r = self.context * if p.own_context { p.spacing } else { h };
            d2 <= r * r
        };
        let (ci, cj) = (within(i), within(j));
        if ci && cj {
            return (true, true);
        }
        let near = self.noise_reaches(i, j, diff, d2, h);
        (ci || near, cj || near)
    }

    /// The largest distance at which point `i` can be near, or context of,
    /// any point `j` whose spacing is at most `spacing_max` and whose largest
    /// sensor standard deviation is at most `sigma_max`: the larger of the
    /// context radius `context h` and the noise's reach `(s_i + s_j) k + h/2`,
    /// with `h` the larger spacing.
    fn block_reach(&self, i: &PointNoise<'_>, spacing_max: Real, sigma_max: Real) -> Real {
        let h = i.spacing.max(spacing_max);
        (self.context * h).max(self.reach_max(i.sigma_max + sigma_max, h))
    }

    /// The farthest the rule's noise part reaches between two points whose
    /// largest sensor deviations sum to `sigma_max_sum`, `h` the larger
    /// spacing: `sigma_max_sum k + h/2` (the pair test and the block bound
    /// read this one formula, so the bound cannot fall behind the rule).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn reach_max(&self, sigma_max_sum: Real, h: Real) -> Real {
        sigma_max_sum * self.k + SAMPLING_MARGIN * h
    }

    /// The rule's noise part, `max(0, d - h/2) <= (s_i + s_j) k` (`diff = x_j
    /// - x_i`, `d2` its squared norm, `h` the larger spacing).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn noise_reaches(
        &self,
        i: &PointNoise<'_>,
        j: &PointNoise<'_>,
        diff: Vector3,
        d2: Real,
        h: Real,
    ) -> bool {
        // `max(0, d - h/2) > s k` with `s >= 0` is `d > s k + h/2`: most pairs
        // are decided on the squared distance, without a square root.
        let reach_max = self.reach_max(i.sigma_max + j.sigma_max, h);
        if d2 > reach_max * reach_max {
            return false;
        }
        let d = d2.sqrt();
        let gap = (d - SAMPLING_MARGIN * h).max(0.0);
        if gap <= (i.sigma_min + j.sigma_min) * self.k {
            return true;
        }
        let u = diff / d;
        gap <= (i.std_along(&u) + j.std_along(&u)) * self.k
    }
}

/// Which points of the kept leaves are near the other cloud, by the near rule
/// with some point of it. The rule involves only distances, so it does not
/// depend on the frame the clouds are given in (leaf boundaries do). The
/// traversal, run with margins of `context` times each node's largest spacing,
/// keeps every leaf pair holding such a pair of points, so searching the
/// partner leaves finds every one.
///
/// `found`, when given, holds points already known to be near (such as the
/// core points under a wider context: the rule with a larger context holds
/// every pair the smaller one does): they are not searched for again, and a
/// pair of leaves whose points are all found is skipped. The answer is
/// `found` and the points the rule finds: the same as without it where
/// `found` holds only points the rule finds.
#[allow(clippy::too_many_arguments)]
pub fn near_points(
    leaf_pairs: &[(u32, u32)],
    rel: &Pose,
    a: &PointCloud,
    b: &PointCloud,
    epsilon: Real,
    context: Real,
    own_context: OwnContext<'_>,
    found: Option<(Vec<bool>, Vec<bool>)>,
) -> (Vec<bool>, Vec<bool>) {
    let (bvh_a, bvh_b) = (a.bvh(), b.bvh());
    // Each leaf is in many pairs: it is read once.
    let leaves = |side: fn(&(u32, u32)) -> u32| {
        let mut ids: Vec<u32> = leaf_pairs.iter().map(side).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    };
    let (ids_a, ids_b) = (leaves(|p| p.0), leaves(|p| p.1));
    // Every id is found: `ids` was made from the pairs.
    let position = |ids: &[u32], id: u32| ids.binary_search(&id).unwrap_or_default() as u32;
    let pairs: Vec<(u32, u32)> = leaf_pairs
        .iter()
        .map(|&(la, lb)| (position(&ids_a, la), position(&ids_b, lb)))
        .collect();
    let blocks_a: Vec<&[u32]> = ids_a.iter().map(|&l| bvh_a.node_points(l)).collect();
    let blocks_b: Vec<&[u32]> = ids_b.iter().map(|&l| bvh_b.node_points(l)).collect();
    let rule = NearRule::new(epsilon, context);
    near_points_in_blocks(
        (&blocks_a, &blocks_b),
        &pairs,
        rel,
        (a, b),
        rule,
        own_context,
        found,
    )
}

/// Per sample of A and of B, whether it measures its context in its own
/// spacing ([`NearRule`]); `None`: none does (the points model).
pub type OwnContext<'a> = (Option<&'a [bool]>, Option<&'a [bool]>);

/// The brute-force reference of [`near_points`]: the same rule tested on every
/// pair of points, `O(n_a n_b)`, without the hierarchy.
pub fn near_points_brute_force(
    rel: &Pose,
    a: &PointCloud,
    b: &PointCloud,
    epsilon: Real,
    context: Real,
    own_context: OwnContext<'_>,
) -> (Vec<bool>, Vec<bool>) {
    let all = |n: usize| (0..n as u32).collect::<Vec<u32>>();
    let (ia, ib) = (all(a.len()), all(b.len()));
    let rule = NearRule::new(epsilon, context);
    let blocks = (&[&ia[..]][..], &[&ib[..]][..]);
    near_points_in_blocks(blocks, &[(0, 0)], rel, (a, b), rule, own_context, None)
}

/// The near rule over every pair `(i, j)` of the blocks of point indices
/// paired by `pairs` (positions in `blocks.0` and `blocks.1`).
///
/// Each block's points are read once into a compact list with their noise,
/// and in each pair a point farther from the other block's box than the
/// rule's widest reach towards any point of that block
/// ([`NearRule::block_reach`]) is left out of the pair tests: it is near none
/// of them, and none of them near it, so the result is that of testing every
/// pair. A pair of blocks whose points have all been found near is skipped.
/// The flags start as the `found` ones (points already known near, see
/// [`near_points`]; none without), and only gain points.
fn near_points_in_blocks(
    blocks: (&[&[u32]], &[&[u32]]),
    pairs: &[(u32, u32)],
    rel: &Pose,
    (a, b): (&PointCloud, &PointCloud),
    rule: NearRule,
    own_context: OwnContext<'_>,
    found: Option<(Vec<bool>, Vec<bool>)>,
) -> (Vec<bool>, Vec<bool>) {
    // Directions in B's frame, rotated into A's own frame for A's covariances.
    let to_a = rel.rotation.inverse().to_rotation_matrix().into_inner();
    let noise_a = CloudNoise::new(a, to_a, own_context.0);
    let noise_b = CloudNoise::new(b, Matrix3::identity(), own_context.1);
    let read_a = Blocks::read(blocks.0, |i| noise_a.point(i, rel * a.points()[i]));
    let read_b = Blocks::read(blocks.1, |j| noise_b.point(j, b.points()[j]));
    // Per block, its points not yet found near: a pair of two blocks whose
    // points are all near can change nothing (deep in an overlap, most pairs).
    // With nothing found, every point of each block (no counting pass).
    let left = |read: &Blocks<'_>, near: Option<&[bool]>| -> Vec<usize> {
        read.bounds
            .iter()
            .map(|b| match near {
                Some(near) => read.points[b.run.clone()]
                    .iter()
                    .filter(|(i, _)| !near[*i])
                    .count(),
                None => b.run.len(),
            })
            .collect()
    };
    let mut left_a = left(&read_a, found.as_ref().map(|f| &f.0[..]));
    let mut left_b = left(&read_b, found.as_ref().map(|f| &f.1[..]));
    let (mut near_a, mut near_b) =
        found.unwrap_or_else(|| (vec![false; a.len()], vec![false; b.len()]));
    let (mut kept_a, mut kept_b) = (Vec::new(), Vec::new());
    for &(ka, kb) in pairs {
        let (la, lb) = (&mut left_a[ka as usize], &mut left_b[kb as usize]);
        if *la == 0 && *lb == 0 {
            continue;
        }
        read_a.within_reach_of(ka, &read_b, kb, &rule, &mut kept_a);
        read_b.within_reach_of(kb, &read_a, ka, &rule, &mut kept_b);
        let (block_a, block_b) = (read_a.block(ka), read_b.block(kb));
        for &na in &kept_a {
            let (i, pi) = &block_a[na];
            for &nb in &kept_b {
                let (j, pj) = &block_b[nb];
                if near_a[*i] && near_b[*j] {
                    continue;
                }
                let (ni, nj) = rule.near_sides(pi, pj);
                if ni && !near_a[*i] {
                    near_a[*i] = true;
                    *la -= 1;
                }
                if nj && !near_b[*j] {
                    near_b[*j] = true;
                    *lb -= 1;
                }
            }
        }
    }
    (near_a, near_b)
}

/// Blocks of points read with their noise: one list of every block's points
/// (one allocation per side, not one per leaf: a query near a miss keeps
/// few pairs of small leaves), and per block its run in the list
/// ([`BlockBound`]).
struct Blocks<'a> {
    points: Vec<(usize, PointNoise<'a>)>,
    bounds: Vec<BlockBound>,
}

/// One block's run of [`Blocks::points`], the box of their positions, and
/// their largest spacing and sensor standard deviation.
struct BlockBound {
    run: std::ops::Range<usize>,
    aabb: Aabb,
    spacing_max: Real,
    sigma_max: Real,
}

impl<'a> Blocks<'a> {
    /// Reads the points of each block of `blocks` (`point(i)`: point `i`
    /// with its noise).
    fn read(blocks: &[&[u32]], point: impl Fn(usize) -> PointNoise<'a>) -> Self {
        let mut points = Vec::with_capacity(blocks.iter().map(|b| b.len()).sum());
        let bounds = blocks
            .iter()
            .map(|idx| {
                let mut bound = BlockBound {
                    run: points.len()..points.len() + idx.len(),
                    aabb: Aabb::empty(),
                    spacing_max: 0.0,
                    sigma_max: 0.0,
                };
                for &i in *idx {
                    let p = point(i as usize);
                    bound.aabb.take_point(&p.x);
                    bound.spacing_max = bound.spacing_max.max(p.spacing);
                    bound.sigma_max = bound.sigma_max.max(p.sigma_max);
                    points.push((i as usize, p));
                }
                bound
            })
            .collect();
        Self { points, bounds }
    }

    /// The points of block `k`.
    fn block(&self, k: u32) -> &[(usize, PointNoise<'a>)] {
        &self.points[self.bounds[k as usize].run.clone()]
    }

    /// Into `out`, the positions within block `k` of its points that lie
    /// within the rule's reach of the box of `other`'s block `o`.
    fn within_reach_of(
        &self,
        k: u32,
        other: &Blocks<'_>,
        o: u32,
        rule: &NearRule,
        out: &mut Vec<usize>,
    ) {
        let o = &other.bounds[o as usize];
        out.clear();
        out.extend(self.block(k).iter().enumerate().filter_map(|(n, (_, p))| {
            let r = rule.block_reach(p, o.spacing_max, o.sigma_max);
            (o.aabb.distance_squared_to_point(&p.x) <= r * r).then_some(n)
        }));
    }
}

/// Merges kept leaf pairs into connected components: two leaf pairs are connected
/// when they share a leaf. Returns one patch per component with the leaves'
/// points for which `keep_a` / `keep_b` hold (all points when empty), components
/// ordered by their first leaf pair; a component left without points of either
/// cloud is dropped.
pub fn near_regions(
    leaf_pairs: &[(u32, u32)],
    bvh_a: &Bvh,
    bvh_b: &Bvh,
    keep_a: &[bool],
    keep_b: &[bool],
) -> Vec<Patch> {
    // Union-find over the leaves that occur, keyed by (leaf, whether it is B's).
    let mut id_of: HashMap<(u32, bool), usize> = HashMap::new();
    let mut parent: Vec<usize> = Vec::new();
    let mut node = |key: (u32, bool), parent: &mut Vec<usize>| -> usize {
        *id_of.entry(key).or_insert_with(|| {
            parent.push(parent.len());
            parent.len() - 1
        })
    };
    let mut leaves: Vec<(u32, bool)> = Vec::new();
    for &(la, lb) in leaf_pairs {
        let n_before = parent.len();
        let ia = node((la, false), &mut parent);
        if parent.len() > n_before {
            leaves.push((la, false));
        }
        let n_before = parent.len();
        let ib = node((lb, true), &mut parent);
        if parent.len() > n_before {
            leaves.push((lb, true));
        }
        let (ra, rb) = (find(&mut parent, ia), find(&mut parent, ib));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let mut comp_of_root: HashMap<usize, usize> = HashMap::new();
    let mut out: Vec<Patch> = Vec::new();
    for (k, &(leaf, is_b)) in leaves.iter().enumerate() {
        let root = find(&mut parent, k);
        let c = *comp_of_root.entry(root).or_insert_with(|| {
            out.push(Patch {
                component: out.len() as u32,
                ..Patch::default()
            });
            out.len() - 1
        });
        let keep = |k: &[bool], i: u32| k.is_empty() || k[i as usize];
        if is_b {
            let pts = bvh_b.node_points(leaf).iter().filter(|&&i| keep(keep_b, i));
            out[c].b.extend(pts);
        } else {
            let pts = bvh_a.node_points(leaf).iter().filter(|&&i| keep(keep_a, i));
            out[c].a.extend(pts);
        }
    }
    out.retain(|p| !p.a.is_empty() && !p.b.is_empty());
    for (k, p) in out.iter_mut().enumerate() {
        p.component = k as u32;
    }
    out
}

/// Root of `x` in a union-find forest, halving paths on the way.
fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Splits `region` (points given in one common frame) into patches of at most
/// `max_points` points, each holding points of both clouds.
///
/// A patch is cut in two at the median of the points' projections on the
/// direction of largest spread *along* the contact: the largest principal axis of
/// the points' scatter projected onto the plane orthogonal to the line between the
/// two clouds' centroids. Cutting along the contact keeps both clouds in each
/// half, and lets each patch follow a curved or wrapped contact with its own
/// surface. A cut that would leave one half without points of a cloud gives
/// that cloud's points to both halves when they are at most half of
/// `max_points` (a sparse cloud against a dense one: a point is then in
/// several patches and keeps the largest of its values); otherwise it is not
/// made.
pub fn split_patches(region: Patch, pa: &[Point3], pb: &[Point3], max_points: usize) -> Vec<Patch> {
    let mut out = Vec::new();
    let mut todo = vec![region];
    while let Some(p) = todo.pop() {
        if p.a.len() + p.b.len() <= max_points {
            out.push(p);
            continue;
        }
        // One cloud's halves, given all of its points when one is empty
        // and the cloud is small enough to share; `false` when it is not.
        let share = |l: &mut Vec<u32>, r: &mut Vec<u32>, whole: &Vec<u32>| {
            if l.is_empty() || r.is_empty() {
                if whole.len() > max_points / 2 {
                    return false;
                }
                l.clone_from(whole);
                r.clone_from(whole);
            }
            true
        };
        let halves = halves(&p, pa, pb).and_then(|(mut l, mut r)| {
            if !(share(&mut l.a, &mut r.a, &p.a) && share(&mut l.b, &mut r.b, &p.b)) {
                return None;
            }
            // Only one cloud may be shared, or nothing shrinks.
            let shrinks = l.a.len() + l.b.len() < p.a.len() + p.b.len()
                && r.a.len() + r.b.len() < p.a.len() + p.b.len();
            shrinks.then_some((l, r))
        });
        match halves {
            Some((l, r)) => {
                todo.push(r);
                todo.push(l);
            }
            None => out.push(p),
        }
    }
    out
}

/// Cuts a patch in two at the median along the contact (see [`split_patches`]);
/// `None` when a half would lose all points of a cloud.
pub fn cut(p: &Patch, pa: &[Point3], pb: &[Point3]) -> Option<(Patch, Patch)> {
    halves(p, pa, pb)
        .filter(|(l, r)| !(l.a.is_empty() || r.a.is_empty() || l.b.is_empty() || r.b.is_empty()))
}

/// The two halves of a patch cut at the median along the contact (see
/// [`split_patches`]), a half possibly without points of a cloud; `None` for
/// a patch without points.
fn halves(p: &Patch, pa: &[Point3], pb: &[Point3]) -> Option<(Patch, Patch)> {
    if p.a.is_empty() || p.b.is_empty() {
        return None;
    }
    let all: Vec<Point3> = (p.a.iter().map(|&i| pa[i as usize]))
        .chain(p.b.iter().map(|&i| pb[i as usize]))
        .collect();
    let (all_a, all_b) = all.split_at(p.a.len());
    let centre = mean(&all);
    // Across the contact: from A's points to B's, or the least spread where
    // their means coincide.
    let mut normal = mean(all_b) - mean(all_a);
    let spread = all
        .iter()
        .map(|x| (x.coords - centre).norm_squared())
        .sum::<Real>()
        .sqrt();
    if normal.norm() <= 1e-12 * spread.max(Real::MIN_POSITIVE) {
        normal = PrincipalAxes::of(all.iter().copied()).least();
    }
    let normal = normal.normalize();
    // Along the contact: the largest spread of the points projected onto the
    // plane normal to it.
    let axis = PrincipalAxes::of(all.iter().map(|x| {
        let d = x.coords - centre;
        Point3::from(d - normal * normal.dot(&d))
    }))
    .largest();
    let mut keys: Vec<Real> = all.iter().map(|x| x.coords.dot(&axis)).collect();
    let mid = keys.len() / 2;
    let (_, median, _) = keys.select_nth_unstable_by(mid, Real::total_cmp);
    let median = *median;
    let side = |pts: &[Point3], idx: &[u32]| -> (Vec<u32>, Vec<u32>) {
        idx.iter()
            .partition(|&&i| pts[i as usize].coords.dot(&axis) < median)
    };
    let (al, ar) = side(pa, &p.a);
    let (bl, br) = side(pb, &p.b);
    Some((
        Patch {
            component: p.component,
            a: al,
            b: bl,
        },
        Patch {
            component: p.component,
            a: ar,
            b: br,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n x n` points of spacing `h` in the plane `z`.
    fn grid(n: usize, h: Real, z: Real) -> Vec<Point3> {
        (0..n * n)
            .map(|k| Point3::new((k % n) as Real * h, (k / n) as Real * h, z))
            .collect()
    }

    fn all(n: usize) -> Vec<u32> {
        (0..n as u32).collect()
    }

    /// How many patches hold each point.
    fn counts(patches: &[Patch], n: usize, of: impl Fn(&Patch) -> &Vec<u32>) -> Vec<usize> {
        let mut c = vec![0; n];
        for p in patches {
            for &i in of(p) {
                c[i as usize] += 1;
            }
        }
        c
    }

    #[test]
    fn every_leaf_pair_finds_what_the_rule_written_out_finds() {
        // Two noisy grids with anisotropic sensor covariances (a camera's
        // noise along its rays, stronger for B), A turned and moved to a few
        // sigma under part of B; every leaf pair of leaves of 4 points, so
        // most points of a leaf pair lie beyond the other leaf's reach and
        // are left out of its tests. The reference is the rule written out,
        // pair by pair, with each point's sensor deviation along the line.
        use crate::sample::add_noise;
        use nalgebra::{Translation3, UnitQuaternion};
        let ray = |s_across: Real, s_along: Real, axis: Vector3| {
            let u = axis.normalize();
            Matrix3::identity() * s_across.powi(2)
                + u * u.transpose() * (s_along.powi(2) - s_across.powi(2))
        };
        let cloud = |n: usize, h: Real, cov: Matrix3, seed: u64| {
            let pts = add_noise(&grid(n, h, 0.0), cov.trace().sqrt() / 3.0, seed);
            let mut c = PointCloud::from_covariances(pts.clone(), vec![cov; pts.len()]).unwrap();
            c.set_bvh_settings(crate::bvh::BvhSettings { leaf_max_points: 4 })
                .unwrap();
            c
        };
        let a = cloud(
            14,
            0.004,
            ray(0.0005, 0.002, Vector3::new(0.2, 0.1, 1.0)),
            1,
        );
        let b = cloud(8, 0.005, ray(0.001, 0.004, Vector3::new(-0.3, 0.0, 1.0)), 2);
        let (ctx, eps) = (2.0, 1e-3);
        let k = -normal_quantile(0.5 * eps);
        for (lift, turn) in [(0.006, 0.0), (0.012, 0.4), (0.02, -0.3)] {
            let rel = Pose::from_parts(
                Translation3::new(-0.03, 0.003, lift),
                UnitQuaternion::from_euler_angles(turn, 0.5 * turn, 0.1),
            );
            let xa: Vec<Point3> = a.points().iter().map(|p| rel * p).collect();
            let to_a = rel.rotation.inverse().to_rotation_matrix().into_inner();
            let std = |c: &Matrix3, u: &Vector3| u.dot(&(c * u)).max(0.0).sqrt();
            let near = |i: usize, j: usize| {
                let diff = b.points()[j] - xa[i];
                let d = diff.norm();
                let h = a.spacing()[i].max(b.spacing()[j]);
                let u = diff / d;
                let s = std(&a.sensor_covariances()[i], &(to_a * u))
                    + std(&b.sensor_covariances()[j], &u);
                d <= ctx * h || (d - SAMPLING_MARGIN * h).max(0.0) <= s * k
            };
            let want_a: Vec<bool> = (0..a.len())
                .map(|i| (0..b.len()).any(|j| near(i, j)))
                .collect();
            let want_b: Vec<bool> = (0..b.len())
                .map(|j| (0..a.len()).any(|i| near(i, j)))
                .collect();
            let leaves = |c: &PointCloud| -> Vec<u32> {
                let nodes = c.bvh().nodes();
                (0..nodes.len() as u32)
                    .filter(|&n| nodes[n as usize].is_leaf())
                    .collect()
            };
            let pairs: Vec<(u32, u32)> = leaves(&a)
                .iter()
                .flat_map(|&la| leaves(&b).into_iter().map(move |lb| (la, lb)))
                .collect();
            assert!(pairs.len() > 1000);
            let got = near_points(&pairs, &rel, &a, &b, eps, ctx, (None, None), None);
            assert_eq!(got, (want_a.clone(), want_b.clone()), "lift {lift}");
            // Started from the points the rule finds with the core's half
            // spacing of context (a subset), or from every other point it
            // finds: the same answer.
            let core = near_points(
                &pairs,
                &rel,
                &a,
                &b,
                eps,
                SAMPLING_MARGIN,
                (None, None),
                None,
            );
            let every_other = |w: &[bool]| -> Vec<bool> {
                w.iter()
                    .enumerate()
                    .map(|(i, &x)| x && i % 2 == 0)
                    .collect()
            };
            let some = (every_other(&want_a), every_other(&want_b));
            for found in [&core, &some] {
                assert!(found.0.iter().any(|&x| x), "lift {lift}");
                let seeded = near_points(
                    &pairs,
                    &rel,
                    &a,
                    &b,
                    eps,
                    ctx,
                    (None, None),
                    Some(found.clone()),
                );
                assert_eq!(seeded, got, "lift {lift}");
            }
            let brute = near_points_brute_force(&rel, &a, &b, eps, ctx, (None, None));
            assert_eq!(brute, (want_a.clone(), want_b), "lift {lift}");
            // Some points near and some not: the test can tell.
            let n = want_a.iter().filter(|&&x| x).count();
            assert!(0 < n && n < a.len(), "lift {lift}: {n} of {}", a.len());
        }
    }

    #[test]
    fn a_sample_marked_own_context_measures_it_in_its_own_spacing() {
        // A plane sampled every 5 mm, 20 mm under one sampled every 10 mm,
        // without noise: the rule's noise part is `d <= h / 2` (`h` the larger
        // spacing of the pair), its context `d <= 2 h`, or `d <= 2 h_i` for a
        // sample `i` marked to measure it in its own spacing.
        let a = PointCloud::from_sigma(grid(9, 0.005, 0.0), 0.0).unwrap();
        let b = PointCloud::from_sigma(grid(5, 0.01, 0.02), 0.0).unwrap();
        let id = Pose::identity();
        let (ctx, eps) = (2.0, 1e-3);
        let (ha, hb) = (a.spacing(), b.spacing());
        let d = |i: usize, j: usize| (a.points()[i] - b.points()[j]).norm();
        let h = |i: usize, j: usize| ha[i].max(hb[j]);
        // Every other sample of A marked.
        let marked: Vec<bool> = (0..a.len()).map(|i| i % 2 == 0).collect();
        let mut kept = Vec::new();
        for own in [None, Some(&marked[..])] {
            let (ka, kb) = near_points_brute_force(&id, &a, &b, eps, ctx, (own, None));
            let (ta, tb) = near_points(&[(0, 0)], &id, &a, &b, eps, ctx, (own, None), None);
            assert_eq!((&ka, &kb), (&ta, &tb), "one leaf pair is every pair");
            let is_marked = |i: usize| own.is_some_and(|o| o[i]);
            for i in 0..a.len() {
                let reach = |j: usize| ctx * if is_marked(i) { ha[i] } else { h(i, j) };
                let want = (0..b.len()).any(|j| d(i, j) <= 0.5 * h(i, j) || d(i, j) <= reach(j));
                assert_eq!(ka[i], want, "a {i} marked {}", is_marked(i));
            }
            // B's samples keep the larger spacing, marked partners or not.
            for j in 0..b.len() {
                let want = (0..a.len()).any(|i| d(i, j) <= ctx * h(i, j));
                assert_eq!(kb[j], want, "b {j}");
            }
            kept.push((0..a.len()).filter(|&i| ka[i] && marked[i]).count());
        }
        // Two sparse spacings of context reach every marked sample; two of
        // their own, fewer than half of them.
        let n_marked = marked.iter().filter(|&&m| m).count();
        assert_eq!(kept[0], n_marked);
        assert!(kept[1] < n_marked / 2, "{kept:?} of {n_marked}");
    }

    #[test]
    fn a_sparse_cloud_is_shared_so_that_every_patch_is_bounded() {
        // Three points over a 4900-point plane: no cut keeps points of both
        // clouds in each half, so the sparse side goes to both halves.
        let pa = vec![
            Point3::new(0.01, 0.01, 0.002),
            Point3::new(0.03, 0.05, 0.002),
            Point3::new(0.06, 0.02, 0.002),
        ];
        let pb = grid(70, 0.001, 0.0);
        let region = Patch {
            component: 0,
            a: all(pa.len()),
            b: all(pb.len()),
        };
        let patches = split_patches(region, &pa, &pb, 400);
        assert!(patches.len() >= 4900 / 400, "{} patches", patches.len());
        for p in &patches {
            assert!(
                p.a.len() + p.b.len() <= 400,
                "{} + {}",
                p.a.len(),
                p.b.len()
            );
            assert!(!p.a.is_empty() && !p.b.is_empty());
        }
        // The dense cloud is partitioned; every sparse point is in some patch.
        assert!(counts(&patches, pb.len(), |p| &p.b).iter().all(|&c| c == 1));
        assert!(counts(&patches, pa.len(), |p| &p.a).iter().all(|&c| c >= 1));
    }

    #[test]
    fn dense_clouds_are_partitioned_and_a_large_sparse_side_is_not_shared() {
        // Two planes of 900 points: each point in exactly one patch.
        let (pa, pb) = (grid(30, 0.001, 0.001), grid(30, 0.001, 0.0));
        let region = Patch {
            component: 0,
            a: all(pa.len()),
            b: all(pb.len()),
        };
        let patches = split_patches(region, &pa, &pb, 200);
        assert!(patches.iter().all(|p| p.a.len() + p.b.len() <= 200));
        assert!(counts(&patches, pa.len(), |p| &p.a).iter().all(|&c| c == 1));
        assert!(counts(&patches, pb.len(), |p| &p.b).iter().all(|&c| c == 1));
        // A cloud of more than half the bound on one side of every cut is not
        // copied into both halves: the patch stays whole.
        let pa: Vec<Point3> = (0..150).map(|_| Point3::new(0.0, 0.0, 0.001)).collect();
        let region = Patch {
            component: 0,
            a: all(pa.len()),
            b: all(pb.len()),
        };
        let patches = split_patches(region, &pa, &pb, 200);
        assert_eq!(patches.len(), 1);
        assert_eq!(patches[0].a.len() + patches[0].b.len(), 1050);
    }
}
