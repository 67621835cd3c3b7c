//! Near regions: connected groups of kept leaf pairs, split into patches.

use std::collections::HashMap;

use crate::bvh::Bvh;
use crate::math::{Matrix3, Point3, Vector3};
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

/// Merges kept leaf pairs into connected components: two leaf pairs are connected
/// when they share a leaf. Returns one patch per component, leaves' points
/// unioned, components ordered by their first leaf pair.
pub fn near_regions(leaf_pairs: &[(u32, u32)], bvh_a: &Bvh, bvh_b: &Bvh) -> Vec<Patch> {
    // Union-find over the leaves that occur: A leaves as 2k, B leaves as 2k + 1.
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
        if is_b {
            out[c].b.extend_from_slice(bvh_b.node_points(leaf));
        } else {
            out[c].a.extend_from_slice(bvh_a.node_points(leaf));
        }
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
/// surface. A cut that would leave one half without points of a cloud is not made.
pub fn split_patches(region: Patch, pa: &[Point3], pb: &[Point3], max_points: usize) -> Vec<Patch> {
    let mut out = Vec::new();
    let mut todo = vec![region];
    while let Some(p) = todo.pop() {
        if p.a.len() + p.b.len() <= max_points {
            out.push(p);
            continue;
        }
        match cut(&p, pa, pb) {
            Some((l, r)) => {
                todo.push(r);
                todo.push(l);
            }
            None => out.push(p),
        }
    }
    out
}

fn cut(p: &Patch, pa: &[Point3], pb: &[Point3]) -> Option<(Patch, Patch)> {
    let xa = p.a.iter().map(|&i| pa[i as usize].coords);
    let xb = p.b.iter().map(|&i| pb[i as usize].coords);
    let mean_a = xa.clone().sum::<Vector3>() / p.a.len() as Real;
    let mean_b = xb.clone().sum::<Vector3>() / p.b.len() as Real;
    let all: Vec<Vector3> = xa.chain(xb).collect();
    let mean = all.iter().sum::<Vector3>() / all.len() as Real;
    let mut scatter = Matrix3::zeros();
    for x in &all {
        let d = x - mean;
        scatter += d * d.transpose();
    }
    let mut normal = mean_b - mean_a;
    if normal.norm() <= 1e-12 * scatter.trace().sqrt().max(Real::MIN_POSITIVE) {
        let eig = scatter.symmetric_eigen();
        normal = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
    }
    let normal = normal.normalize();
    let proj = Matrix3::identity() - normal * normal.transpose();
    let eig = (proj * scatter * proj).symmetric_eigen();
    let axis = eig.eigenvectors.column(eig.eigenvalues.imax()).into_owned();
    let mut keys: Vec<Real> = all.iter().map(|x| x.dot(&axis)).collect();
    let mid = keys.len() / 2;
    let (_, median, _) = keys.select_nth_unstable_by(mid, Real::total_cmp);
    let median = *median;
    let side = |pts: &[Point3], idx: &[u32]| -> (Vec<u32>, Vec<u32>) {
        idx.iter()
            .partition(|&&i| pts[i as usize].coords.dot(&axis) < median)
    };
    let (al, ar) = side(pa, &p.a);
    let (bl, br) = side(pb, &p.b);
    if al.is_empty() || ar.is_empty() || bl.is_empty() || br.is_empty() {
        return None;
    }
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
