//! Bottom-up repair of the top-down split: neighbouring elements that together
//! still pass the tests are merged.
//!
//! The top-down split halves a group at its median wherever the group fails,
//! which cuts a flat face into pieces wherever an edge or a second face was in
//! the same group higher up. Merging neighbours whose union is still one
//! element (the same residual and curvature tests) gives the face back its
//! size, and lets the single points left at an edge join the face they lie on.

use crate::bvh::{Bvh, BvhSettings, BvhWorkspace};
use crate::element::element_fit::{fit_element, Fit};
use crate::element::{ElementSettings, SurfaceElement};
use crate::math::{Matrix3, Point3};
use crate::Real;

/// Neighbours of each element tried for a merge, per pass.
const MERGE_NEIGHBOURS: usize = 6;
/// Passes at most (each can double an element's size).
const MERGE_PASSES: usize = 12;

/// Merges neighbouring `groups` (point indices, with their elements `fits`)
/// while their unions pass the element tests; returns the groups left.
pub(crate) fn merge_neighbours(
    points: &[Point3],
    sensor: &[Matrix3],
    spacing: &[Real],
    settings: &ElementSettings,
    mut groups: Vec<(Vec<u32>, SurfaceElement)>,
) -> Vec<(Vec<u32>, SurfaceElement)> {
    let mut ws = BvhWorkspace::default();
    let mut nn: Vec<(Real, u32)> = Vec::new();
    for _ in 0..MERGE_PASSES {
        if groups.len() < 2 {
            break;
        }
        let means: Vec<Point3> = groups.iter().map(|(_, e)| e.mean).collect();
        let zeros = vec![0.0; means.len()];
        let Ok(tree) = Bvh::build(&means, &zeros, &BvhSettings::default()) else {
            break;
        };
        let mut pairs: Vec<(Real, u32, u32)> = Vec::new();
        for (i, m) in means.iter().enumerate() {
            tree.nearest_k(&means, m, MERGE_NEIGHBOURS + 1, &mut ws, &mut nn);
            pairs.extend(
                nn.iter()
                    .filter(|&&(_, j)| j as usize > i)
                    .map(|&(d2, j)| (d2, i as u32, j)),
            );
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut touched = vec![false; groups.len()];
        let mut merged_any = false;
        for (_, i, j) in pairs {
            let (i, j) = (i as usize, j as usize);
            if touched[i] || touched[j] {
                continue;
            }
            let mut union = groups[i].0.clone();
            union.extend_from_slice(&groups[j].0);
            if let Fit::Element(e) = fit_element(points, sensor, spacing, &union, 0, settings) {
                groups[i] = (union, *e);
                groups[j].0.clear();
                touched[i] = true;
                touched[j] = true;
                merged_any = true;
            }
        }
        groups.retain(|(g, _)| !g.is_empty());
        if !merged_any {
            break;
        }
    }
    groups
}
