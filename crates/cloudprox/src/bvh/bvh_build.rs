//! Top-down construction: split along the largest principal axis at the median.

use crate::bvh::{Aabb, Bvh, BvhNode, BvhSettings};
use crate::error::{Error, Result};
use crate::math::{Point3, PrincipalAxes, Vector3};
use crate::Real;

impl Bvh {
    /// Builds the hierarchy over `points` with per-point largest standard deviations
    /// `sigmas` (see [`crate::uncertainty::max_std`]).
    ///
    /// Each node is split at the median of the points' projections on the largest
    /// principal axis of their scatter (the thesis version of the method), which
    /// keeps the tree balanced and follows thin surfaces. Build time is
    /// `O(n log n)`.
    pub fn build(points: &[Point3], sigmas: &[Real], settings: &BvhSettings) -> Result<Bvh> {
        settings.validate()?;
        if points.is_empty() {
            return Err(Error::invalid(
                "cannot build a hierarchy over an empty cloud",
            ));
        }
        if sigmas.len() != points.len() {
            return Err(Error::Shape {
                what: "per-point sigmas".into(),
                expected: points.len(),
                got: sigmas.len(),
            });
        }
        let n = u32::try_from(points.len())
            .map_err(|_| Error::invalid("clouds are limited to 2^32 - 1 points"))?;
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * points.len() / settings.leaf_max_points.max(1) + 1),
            indices: (0..n).collect(),
        };
        bvh.build_node(points, sigmas, 0, n, settings.leaf_max_points);
        Ok(bvh)
    }

    fn build_node(
        &mut self,
        points: &[Point3],
        sigmas: &[Real],
        first: u32,
        count: u32,
        leaf_max: usize,
    ) -> u32 {
        let id = self.nodes.len() as u32;
        let range = first as usize..(first + count) as usize;
        let mut aabb = Aabb::empty();
        let mut sigma_max: Real = 0.0;
        for &i in &self.indices[range.clone()] {
            aabb.take_point(&points[i as usize]);
            sigma_max = sigma_max.max(sigmas[i as usize]);
        }
        self.nodes.push(BvhNode {
            aabb,
            sigma_max,
            first,
            count,
            children: None,
        });
        if count as usize <= leaf_max {
            return id;
        }
        let axis = principal_axis(points, &self.indices[range.clone()]);
        let slice = &mut self.indices[range];
        let mid = slice.len() / 2;
        let key = |i: &u32| points[*i as usize].coords.dot(&axis);
        slice.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let left = self.build_node(points, sigmas, first, mid as u32, leaf_max);
        let right = self.build_node(
            points,
            sigmas,
            first + mid as u32,
            count - mid as u32,
            leaf_max,
        );
        self.nodes[id as usize].children = Some([left, right]);
        id
    }
}

/// Unit eigenvector of the largest eigenvalue of the points' scatter matrix.
fn principal_axis(points: &[Point3], idx: &[u32]) -> Vector3 {
    PrincipalAxes::of(idx.iter().map(|&i| points[i as usize])).largest()
}
