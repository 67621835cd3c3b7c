use crate::bvh::bvh_traverse_bvtt::{kept_without_bound, pruned_within};
use crate::bvh::{prune_bound, Bvh, BvhSettings, BvhWorkspace, NodeMargins};
use crate::math::{Point3, Pose, Vector3};
use crate::probability::{normal_cdf, normal_quantile};

fn lcg_points(n: usize, seed: u64) -> Vec<Point3> {
    let mut next = crate::sample::lcg_uniform(seed);
    (0..n)
        .map(|_| Point3::new(next(), next(), next()))
        .collect()
}

#[test]
fn build_is_well_formed_and_refit_follows_points() {
    let pts = lcg_points(1000, 1);
    let sig: Vec<f64> = (0..pts.len()).map(|i| 0.001 * (i % 7) as f64).collect();
    let mut bvh = Bvh::build(&pts, &sig, &BvhSettings { leaf_max_points: 8 }).unwrap();
    bvh.assert_well_formed(&pts, &sig);
    assert!(bvh
        .nodes()
        .iter()
        .filter(|n| n.is_leaf())
        .all(|n| n.count <= 8));
    let moved: Vec<Point3> = pts
        .iter()
        .map(|p| p + Vector3::new(0.5, -2.0, p.x))
        .collect();
    bvh.refit(&moved, &sig).unwrap();
    bvh.assert_well_formed(&moved, &sig);
}

#[test]
fn identical_points_do_not_break_the_build() {
    let pts = vec![Point3::new(1.0, 1.0, 1.0); 100];
    let sig = vec![0.0; 100];
    let bvh = Bvh::build(&pts, &sig, &BvhSettings::default()).unwrap();
    bvh.assert_well_formed(&pts, &sig);
}

#[test]
fn nearest_k_matches_brute_force() {
    let pts = lcg_points(500, 7);
    let sig = vec![0.0; pts.len()];
    let bvh = Bvh::build(&pts, &sig, &BvhSettings { leaf_max_points: 5 }).unwrap();
    let mut ws = BvhWorkspace::default();
    let mut out = Vec::new();
    for q in lcg_points(20, 99) {
        bvh.nearest_k(&pts, &q, 7, &mut ws, &mut out);
        let mut brute: Vec<(f64, u32)> = pts
            .iter()
            .enumerate()
            .map(|(i, p)| ((p - q).norm_squared(), i as u32))
            .collect();
        brute.sort_by(|a, b| a.0.total_cmp(&b.0));
        let got: Vec<f64> = out.iter().map(|x| x.0).collect();
        let want: Vec<f64> = brute[..7].iter().map(|x| x.0).collect();
        assert_eq!(got, want);
    }
}

#[test]
fn within_radius_matches_brute_force() {
    // Points on a coarse lattice put many exactly on the query spheres (the
    // radii are lattice distances): the rounding of the boxes must lose none.
    let mut pts = lcg_points(400, 3);
    for i in 0..6 {
        for j in 0..6 {
            for k in 0..6 {
                pts.push(Point3::new(f64::from(i), f64::from(j), f64::from(k)) * 0.2);
            }
        }
    }
    let sig = vec![0.0; pts.len()];
    let bvh = Bvh::build(&pts, &sig, &BvhSettings { leaf_max_points: 5 }).unwrap();
    let mut ws = BvhWorkspace::default();
    let mut out = Vec::new();
    let queries = lcg_points(10, 5)
        .into_iter()
        .chain(pts[400..].iter().step_by(37).copied());
    let mut found = 0;
    for q in queries {
        for radius in [0.0, 0.2, 0.2 * 2f64.sqrt(), 0.3, 0.4, 2.0] {
            bvh.within_radius(&pts, &q, radius, &mut ws, &mut out);
            let mut got = out.clone();
            got.sort_unstable();
            let want: Vec<u32> = (0..pts.len() as u32)
                .filter(|&i| (pts[i as usize] - q).norm() <= radius)
                .collect();
            assert_eq!(got, want, "radius {radius} at {q:?}");
            found += got.len();
        }
    }
    assert!(found > 1000, "{found}");
    bvh.within_radius(&pts, &pts[0], -1.0, &mut ws, &mut out);
    assert!(out.is_empty());
    bvh.within_radius(&pts, &pts[0], f64::NAN, &mut ws, &mut out);
    assert!(out.is_empty());
}

#[test]
fn pairs_kept_without_the_bound_have_a_bound_of_at_least_epsilon() {
    for eps in [1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5, 1.0] {
        let z = kept_without_bound(eps);
        let exact = -normal_quantile(0.5 * eps);
        assert!(
            z <= exact && z >= exact * (1.0 - 1e-5),
            "{eps}: {z} vs {exact}"
        );
        // At the shortcut's edge, the smallest pair (2 points) is kept by the
        // bound too, whatever the split of the deviations.
        for (sa, sb) in [(1.0, 0.0), (0.3, 0.7), (1e-3, 2e-3)] {
            let gap = z * (sa + sb);
            assert!(prune_bound(gap, sa, sb, 2) >= eps, "{eps} {sa} {sb}");
        }
    }
    assert_eq!(kept_without_bound(0.0), f64::INFINITY);
    for eps in [1.5, 2.0, -1e-3, f64::NAN, f64::from_bits(1)] {
        assert_eq!(kept_without_bound(eps), f64::NEG_INFINITY, "{eps}");
    }
}

#[test]
fn the_shortcut_changes_no_traversal() {
    // Two noisy clouds a few deviations apart, overlapping, and far: many
    // node pairs near the pruning threshold, on both sides of the shortcut's
    // edge. The traversal with the shortcut equals the one deciding every
    // pair by the bound: the same leaf pairs, visits and pruned sum.
    let a = lcg_points(3000, 11);
    let (sa, sb) = (vec![0.004; a.len()], vec![0.006; a.len()]);
    let settings = BvhSettings { leaf_max_points: 8 };
    let ta = Bvh::build(&a, &sa, &settings).unwrap();
    let mut ws = BvhWorkspace::default();
    let mut fired = 0;
    for (shift, eps, margin) in [
        (1.02, 1e-6, 0.0),
        (1.02, 1e-12, 0.01),
        (0.5, 1e-6, 0.0),
        (0.95, 0.3, 0.0),
        (3.0, 1e-6, 0.0),
    ] {
        let b: Vec<Point3> = lcg_points(3000, 12)
            .into_iter()
            .map(|p| p + Vector3::new(shift, 0.0, 0.0))
            .collect();
        let tb = Bvh::build(&b, &sb, &settings).unwrap();
        let margins = vec![margin; tb.nodes().len()];
        let fast = ta.traverse_pairs(&tb, &Pose::identity(), eps, &[], &margins, &mut ws);
        let by_bound = ta.traverse_pairs_keeping(
            &tb,
            &Pose::identity(),
            eps,
            NodeMargins {
                a: &[],
                b: &margins,
                scale: 1.0,
            },
            f64::NEG_INFINITY,
            &mut ws,
        );
        assert_eq!(fast, by_bound, "shift {shift}, epsilon {eps}");
        let z = kept_without_bound(eps);
        for &(la, lb) in &fast.leaf_pairs {
            let (na, nb) = (&ta.nodes()[la as usize], &tb.nodes()[lb as usize]);
            let gap = (na.aabb.distance(&nb.aabb) - margin).max(0.0);
            fired += usize::from(gap <= z * (na.sigma_max + nb.sigma_max));
        }
    }
    assert!(fired > 100, "{fired}");
}

#[test]
fn the_screened_bound_prunes_exactly_the_pairs_the_bound_prunes() {
    // Gaps around every decision edge: for each n and epsilon, the gap
    // where n Phi(-x) = epsilon, and a spread around it, where Mills'
    // bracket decides and where it leaves the pair to the bound.
    let (mut checked, mut mills) = ([0usize; 2], 0);
    for eps in [1e-9, 1e-6, 1e-3, 0.1] {
        for n in [2usize, 17, 400, 20_000] {
            let edge = -normal_quantile(eps / n as f64);
            for k in -400..=400 {
                let x = edge * (1.0 + k as f64 * 1e-3);
                for (sa, sb) in [(1.0, 0.0), (0.3, 0.7), (2e-3, 5e-4)] {
                    let gap = x * (sa + sb);
                    let exact = prune_bound(gap, sa, sb, n);
                    if let Some(b) = pruned_within(gap, sa, sb, n, eps) {
                        assert!(exact < eps, "{eps} {n} {x}: {exact}");
                        assert!(b >= exact && b < eps, "{eps} {n} {x}: {b} vs {exact}");
                        checked[0] += 1;
                        // Mills' upper end, not the bound itself.
                        mills += usize::from(b > exact);
                    } else {
                        assert!(exact >= eps, "{eps} {n} {x}: {exact}");
                        checked[1] += 1;
                    }
                }
            }
        }
    }
    assert!(checked[0] > 10_000 && checked[1] > 10_000, "{checked:?}");
    assert!(mills > checked[0] / 2, "{mills} of {}", checked[0]);
    // No deviation: pruned at any positive gap, with a zero bound.
    assert_eq!(pruned_within(1e-9, 0.0, 0.0, 5, 1e-3), Some(0.0));
    assert_eq!(pruned_within(0.0, 0.0, 0.0, 5, 1e-3), None);
    // Far beyond the normal numbers (x = 40, 45), at epsilon 0, NaN or
    // subnormal, and at a huge count: the bound's own decision.
    for (x, n, eps) in [
        (40.0, 3, 1e-300),
        (45.0, 3, f64::from_bits(1)),
        (5.0, 10, 0.0),
        (5.0, 10, f64::NAN),
        (6.0, 1 << 40, 1e-3),
    ] {
        let exact = prune_bound(x, 1.0, 0.0, n);
        let got = pruned_within(x, 1.0, 0.0, n, eps);
        assert_eq!(got.is_some(), exact < eps, "{x} {n} {eps}");
        assert!(got.is_none_or(|b| b >= exact), "{x} {n} {eps}");
    }
}

#[test]
fn the_nested_traversal_is_the_two_traversals() {
    // Inner margins (half a spacing) and outer ones (two spacings) per node,
    // noisy clouds overlapping, near and apart, moved and turned: the nested
    // descent gives each traversal's leaf pairs in its order, visits and
    // pruned sum.
    let a = lcg_points(3000, 21);
    let (sa, sb) = (vec![0.004; a.len()], vec![0.006; 2500]);
    let settings = BvhSettings { leaf_max_points: 8 };
    let ta = Bvh::build(&a, &sa, &settings).unwrap();
    let mut ws = BvhWorkspace::default();
    let spacing = |t: &Bvh| -> Vec<f64> {
        (0..t.nodes().len())
            .map(|i| 0.01 * (1.0 + (i % 7) as f64 / 7.0))
            .collect()
    };
    let mut differ = 0;
    for (shift, eps, angle) in [
        (1.02, 1e-6, 0.0),
        (1.05, 1e-3, 0.3),
        (0.5, 1e-3, 0.0),
        (1.1, 1e-9, -0.7),
        (3.0, 1e-3, 0.0),
        // Sums past the cap of 1, where the far pairs' bounds are skipped.
        (0.95, 0.3, 0.2),
        (0.7, 0.05, 0.0),
    ] {
        let b: Vec<Point3> = lcg_points(2500, 22)
            .into_iter()
            .map(|p| p + Vector3::new(shift, 0.0, 0.0))
            .collect();
        let tb = Bvh::build(&b, &sb, &settings).unwrap();
        let pose = Pose::from_parts(
            nalgebra::Translation3::new(0.01, -0.02, 0.0),
            nalgebra::UnitQuaternion::from_euler_angles(angle, 0.5 * angle, 0.0),
        );
        // Margins as the near set gives them: each node's spacing times a
        // factor (half a spacing inside, two outside).
        let (sa_nodes, sb_nodes) = (spacing(&ta), spacing(&tb));
        let times = |v: &[f64], k: f64| -> Vec<f64> { v.iter().map(|x| x * k).collect() };
        let (ia, ib) = (times(&sa_nodes, 0.5), times(&sb_nodes, 0.5));
        let (oa, ob) = (times(&sa_nodes, 2.0), times(&sb_nodes, 2.0));
        let inner = ta.traverse_pairs(&tb, &pose, eps, &ia, &ib, &mut ws);
        let outer = ta.traverse_pairs(&tb, &pose, eps, &oa, &ob, &mut ws);
        for (t, m) in [(&inner, (&ia[..], &ib[..])), (&outer, (&oa[..], &ob[..]))] {
            let (pairs, visited, pruned) = by_definition(&ta, &tb, &pose, eps, m);
            assert_eq!(t.leaf_pairs, pairs, "shift {shift}, epsilon {eps}");
            assert_eq!(t.node_pairs_visited, visited);
            // Mills' ratio sums a little more: by 1/x^2 or so of a pair, x
            // above 3 at epsilon <= 1e-3 here; both are capped at 1 (and the
            // larger epsilons' sums reach the cap).
            let pruned = pruned.min(1.0);
            assert!(
                t.pruned_bound >= pruned && t.pruned_bound <= (1.12 * pruned).min(1.0),
                "{} vs {pruned}",
                t.pruned_bound
            );
            if eps > 0.01 {
                assert_eq!((t.pruned_bound, pruned), (1.0, 1.0));
            }
        }
        let (n_in, wider) = ta.traverse_pairs_nested(
            &tb,
            &pose,
            eps,
            NodeMargins {
                a: &sa_nodes,
                b: &sb_nodes,
                scale: 0.5,
            },
            NodeMargins {
                a: &sa_nodes,
                b: &sb_nodes,
                scale: 2.0,
            },
            &mut ws,
        );
        let n_out = wider.finish(&mut ws);
        assert_eq!(n_in, inner, "shift {shift}, epsilon {eps}");
        assert_eq!(n_out, outer, "shift {shift}, epsilon {eps}");
        differ += usize::from(outer.leaf_pairs.len() > inner.leaf_pairs.len());
    }
    assert!(differ >= 3, "{differ}");
}

/// The pair traversal by its definition: every node pair whose boxes'
/// gap (less the larger margin) has `prune_bound >= epsilon` is descended,
/// the larger node split first: leaf pairs in order, visits, pruned sum.
fn by_definition(
    ta: &Bvh,
    tb: &Bvh,
    pose: &Pose,
    eps: f64,
    (ma, mb): (&[f64], &[f64]),
) -> (Vec<(u32, u32)>, usize, f64) {
    let (mut pairs, mut visited, mut pruned) = (Vec::new(), 0, 0.0);
    let mut stack = vec![(0u32, 0u32)];
    while let Some((ia, ib)) = stack.pop() {
        visited += 1;
        let (na, nb) = (&ta.nodes()[ia as usize], &tb.nodes()[ib as usize]);
        let gap = (na.aabb.transformed(pose).distance(&nb.aabb)
            - ma[ia as usize].max(mb[ib as usize]))
        .max(0.0);
        let bound = prune_bound(
            gap,
            na.sigma_max,
            nb.sigma_max,
            (na.count + nb.count) as usize,
        );
        if bound < eps {
            pruned += bound;
            continue;
        }
        let split_a = na.count >= nb.count;
        match (na.children, nb.children) {
            (None, None) => pairs.push((ia, ib)),
            (Some([l, r]), None) => stack.extend([(l, ib), (r, ib)]),
            (Some([l, r]), Some(_)) if split_a => stack.extend([(l, ib), (r, ib)]),
            (_, Some([l, r])) => stack.extend([(ia, l), (ia, r)]),
        }
    }
    (pairs, visited, pruned)
}

#[test]
fn prune_bound_formula() {
    assert_eq!(prune_bound(1.0, 0.0, 0.0, 10), 0.0);
    assert_eq!(prune_bound(0.0, 0.0, 0.0, 10), 10.0);
    let b = prune_bound(0.3, 0.05, 0.05, 4);
    assert!((b - 4.0 * normal_cdf(-3.0)).abs() < 1e-15);
}

#[test]
fn traversal_without_pruning_visits_every_leaf_pair() {
    let a = lcg_points(200, 3);
    let b = lcg_points(150, 4);
    let sa = vec![0.01; a.len()];
    let sb = vec![0.01; b.len()];
    let ta = Bvh::build(
        &a,
        &sa,
        &BvhSettings {
            leaf_max_points: 10,
        },
    )
    .unwrap();
    let tb = Bvh::build(
        &b,
        &sb,
        &BvhSettings {
            leaf_max_points: 10,
        },
    )
    .unwrap();
    let mut ws = BvhWorkspace::default();
    let far = Pose::translation(100.0, 0.0, 0.0);
    let all = ta.traverse_pairs(&tb, &far, 0.0, &[], &[], &mut ws);
    assert_eq!(all.leaf_pairs.len(), ta.leaf_count() * tb.leaf_count());
    let pruned = ta.traverse_pairs(&tb, &far, 1e-9, &[], &[], &mut ws);
    assert!(pruned.leaf_pairs.is_empty());
    assert_eq!(pruned.node_pairs_visited, 1);
    assert!(pruned.pruned_bound < 1e-9);
}

#[test]
fn traversal_keeps_every_close_point_pair() {
    // Property: any point pair closer than the pruning distance must lie in a kept leaf pair.
    let a = lcg_points(300, 5);
    let b = lcg_points(300, 6);
    let sigma = 0.01;
    let sa = vec![sigma; a.len()];
    let sb = vec![sigma; b.len()];
    let ta = Bvh::build(&a, &sa, &BvhSettings { leaf_max_points: 8 }).unwrap();
    let tb = Bvh::build(&b, &sb, &BvhSettings { leaf_max_points: 8 }).unwrap();
    let pose = Pose::new(Vector3::new(0.9, 0.1, 0.0), Vector3::new(0.2, 0.4, 0.9));
    let mut ws = BvhWorkspace::default();
    let eps = 1e-3;
    let t = ta.traverse_pairs(&tb, &pose, eps, &[], &[], &mut ws);
    let mut kept = std::collections::HashSet::new();
    for &(la, lb) in &t.leaf_pairs {
        for &i in ta.node_points(la) {
            for &j in tb.node_points(lb) {
                kept.insert((i, j));
            }
        }
    }
    for (i, pa) in a.iter().enumerate() {
        for (j, pb) in b.iter().enumerate() {
            let d = (pose * pa - pb).norm();
            // A pruned node pair has bound n * Phi(-gap / 2 sigma) < eps with n >= 2 and
            // gap <= d, so any point pair whose two-point bound reaches eps must be kept.
            if prune_bound(d, sigma, sigma, 2) >= eps {
                assert!(
                    kept.contains(&(i as u32, j as u32)),
                    "pair {i},{j} at {d} pruned"
                );
            }
        }
    }
}

/// The serial build as it was before the parallel one: nodes pushed in
/// pre-order, one thread. The reference the parallel build must equal.
fn serial_reference(points: &[Point3], sigmas: &[f64], leaf_max: usize) -> Bvh {
    fn node(
        bvh: &mut Bvh,
        points: &[Point3],
        sigmas: &[f64],
        first: u32,
        count: u32,
        leaf_max: usize,
    ) -> u32 {
        let id = bvh.nodes.len() as u32;
        let range = first as usize..(first + count) as usize;
        let mut aabb = crate::bvh::Aabb::empty();
        let mut sigma_max: f64 = 0.0;
        for &i in &bvh.indices[range.clone()] {
            aabb.take_point(&points[i as usize]);
            sigma_max = sigma_max.max(sigmas[i as usize]);
        }
        bvh.nodes.push(crate::bvh::BvhNode {
            aabb,
            sigma_max,
            first,
            count,
            children: None,
        });
        if count as usize <= leaf_max {
            return id;
        }
        let axis = crate::math::PrincipalAxes::of(
            bvh.indices[range.clone()]
                .iter()
                .map(|&i| points[i as usize]),
        )
        .largest();
        let slice = &mut bvh.indices[range];
        let mid = slice.len() / 2;
        let key = |i: &u32| points[*i as usize].coords.dot(&axis);
        slice.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let left = node(bvh, points, sigmas, first, mid as u32, leaf_max);
        let right = node(
            bvh,
            points,
            sigmas,
            first + mid as u32,
            count - mid as u32,
            leaf_max,
        );
        bvh.nodes[id as usize].children = Some([left, right]);
        id
    }
    let mut bvh = Bvh {
        nodes: Vec::new(),
        indices: (0..points.len() as u32).collect(),
    };
    node(&mut bvh, points, sigmas, 0, points.len() as u32, leaf_max);
    bvh
}

#[test]
fn parallel_build_equals_the_serial_build() {
    // Sizes around the parallel threshold (4096) and well above it, odd and
    // even counts, leaves of 1, 5 and 16 points; a thin surface with repeated
    // points (ties in the median split).
    for (n, leaf_max, seed) in [
        (1, 16, 1),
        (17, 16, 2),
        (4095, 5, 3),
        (4097, 16, 4),
        (50_001, 16, 5),
        (120_000, 1, 6),
    ] {
        let mut pts = lcg_points(n, seed);
        for (i, p) in pts.iter_mut().enumerate() {
            p.z = 0.01 * p.x * p.y;
            if i % 5 == 0 {
                *p = Point3::new(0.5, 0.5, 0.0);
            }
        }
        let sig: Vec<f64> = (0..n).map(|i| 1e-3 * (i % 11) as f64).collect();
        let settings = BvhSettings {
            leaf_max_points: leaf_max,
        };
        let parallel = Bvh::build(&pts, &sig, &settings).unwrap();
        let serial = serial_reference(&pts, &sig, leaf_max);
        assert_eq!(parallel.nodes.len(), serial.nodes.len(), "n = {n}");
        assert!(parallel == serial, "n = {n}, leaf_max = {leaf_max}");
        parallel.assert_well_formed(&pts, &sig);
    }
}

#[test]
fn moved_boxes_enclose_the_moved_corners_and_bound_their_distance() {
    use crate::bvh::{Aabb, BoxMotion};
    use nalgebra::{Translation3, UnitQuaternion};
    let b = Aabb {
        mins: Point3::new(-0.1, 0.2, -0.3),
        maxs: Point3::new(0.4, 0.25, 0.1),
    };
    let other = Aabb {
        mins: Point3::new(1.0, 1.0, 1.0),
        maxs: Point3::new(1.5, 1.2, 1.1),
    };
    let corners: Vec<Point3> = (0..8)
        .map(|k| {
            let pick = |bit: usize, lo: f64, hi: f64| if k & bit == 0 { lo } else { hi };
            Point3::new(
                pick(1, b.mins.x, b.maxs.x),
                pick(2, b.mins.y, b.maxs.y),
                pick(4, b.mins.z, b.maxs.z),
            )
        })
        .collect();
    for (k, angles) in [(0.0, 0.0, 0.0), (0.3, -1.1, 2.0), (1.2, 0.4, -0.7)]
        .into_iter()
        .enumerate()
    {
        let pose = Pose::from_parts(
            Translation3::new(0.1 * k as f64, -0.2, 0.3),
            UnitQuaternion::from_euler_angles(angles.0, angles.1, angles.2),
        );
        let motion = BoxMotion::new(&pose);
        let moved = b.moved(&motion);
        assert_eq!(moved, b.transformed(&pose));
        for c in &corners {
            assert!(moved.distance_squared_to_point(&(pose * c)) <= 1e-24);
        }
        // A lower bound on the distance of every moved corner to `other`.
        let d = moved.distance(&other);
        assert!((d * d - moved.distance_squared(&other)).abs() <= 1e-15);
        for c in &corners {
            assert!(other.distance_squared_to_point(&(pose * c)).sqrt() >= d - 1e-12);
        }
        assert_eq!(motion.keeps_axes(), k == 0, "{angles:?}");
    }
    // A quarter turn maps the axes onto the axes: the moved box is exact.
    let quarter = Pose::from_parts(
        Translation3::new(0.0, 0.0, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
    );
    assert!(BoxMotion::new(&quarter).keeps_axes());
}
