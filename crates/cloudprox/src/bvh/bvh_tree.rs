//! The hierarchy's types.

use crate::bvh::Aabb;
use crate::error::{Error, Result};
use crate::Real;

/// One node of a [`Bvh`].
#[derive(Debug, Clone, PartialEq)]
pub struct BvhNode {
    /// Box of the node's point positions (not inflated; inflation depends on the query).
    pub aabb: Aabb,
    /// Largest standard deviation, over all directions, of any point in the node.
    pub sigma_max: Real,
    /// Index of the node's first point in [`Bvh::indices`].
    pub first: u32,
    /// Number of points below the node.
    pub count: u32,
    /// The two children (node indices), or `None` for a leaf.
    pub children: Option<[u32; 2]>,
}

impl BvhNode {
    /// Whether the node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.children.is_none()
    }
}

/// How a [`Bvh`] is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhSettings {
    /// A node with at most this many points is a leaf (FCL used 20).
    pub leaf_max_points: usize,
}

impl Default for BvhSettings {
    fn default() -> Self {
        Self {
            leaf_max_points: 16,
        }
    }
}

impl BvhSettings {
    /// Checks `leaf_max_points >= 1`.
    pub fn validate(&self) -> Result<()> {
        if self.leaf_max_points == 0 {
            return Err(Error::invalid("leaf_max_points must be >= 1"));
        }
        Ok(())
    }
}

/// A binary tree over the point indices of one cloud, in the cloud's own frame.
///
/// Nodes are stored in pre-order: node 0 is the root and every child has a larger
/// index than its parent, so a reverse sweep visits children before parents.
/// Leaves cover contiguous runs of [`Bvh::indices`].
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    pub(crate) nodes: Vec<BvhNode>,
    pub(crate) indices: Vec<u32>,
}

impl Bvh {
    /// All nodes, root first.
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// The permutation of point indices the leaves refer to.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The point indices below `node`.
    pub fn node_points(&self, node: u32) -> &[u32] {
        let n = &self.nodes[node as usize];
        &self.indices[n.first as usize..(n.first + n.count) as usize]
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }
}

/// Reusable scratch space for traversals, so repeated queries do not allocate.
#[derive(Debug, Clone, Default)]
pub struct BvhWorkspace {
    pub(crate) pair_stack: Vec<(u32, u32)>,
    pub(crate) node_heap: Vec<(Real, u32)>,
    pub(crate) node_stack: Vec<u32>,
}
