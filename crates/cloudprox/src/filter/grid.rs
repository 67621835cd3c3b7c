//! A hashed uniform grid over a cloud, for k-nearest-neighbour queries on
//! millions of points.
//!
//! Points are sorted by cell (so that a cell's points are contiguous and queries
//! made in cell order stay in cache); non-empty cells are found through an
//! open-addressing hash table. A query scans Chebyshev shells of cells around the
//! query's cell and stops when the k-th candidate is nearer than anything outside
//! the scanned box. The cell size is calibrated so that a non-empty cell holds
//! about half of k points (whatever the cloud's dimension: a surface, a volume),
//! so most queries finish after the first shell. Queries that would need many
//! shells (isolated points) are retried on a grid with 4x larger cells, and so
//! on, so that an isolated point never walks thousands of empty cells.

use std::f64::consts::PI;

use rayon::prelude::*;

use crate::math::Point3;

/// Bits of a cell coordinate in a packed key.
const AXIS_BITS: u32 = 21;
/// Most cells along one axis.
const AXIS_CELLS: i64 = (1 << AXIS_BITS) - 1;
/// Marks an empty hash slot (no valid key has all bits set on the top bit).
const EMPTY: u64 = u64::MAX;
/// Shells a query may scan on a fine grid before it is retried on a coarser one.
const MAX_SHELLS: i64 = 2;
/// A grid with at most this many cells along every axis is searched exhaustively.
const COARSE_CELLS: i64 = 8;

/// The bounding box of a non-empty cloud.
fn bounds(points: &[Point3]) -> ([f64; 3], [f64; 3]) {
    points
        .par_iter()
        .fold(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(mut lo, mut hi), p| {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
                (lo, hi)
            },
        )
        .reduce(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(mut lo, mut hi), (l, h)| {
                for a in 0..3 {
                    lo[a] = lo[a].min(l[a]);
                    hi[a] = hi[a].max(h[a]);
                }
                (lo, hi)
            },
        )
}

fn pack(c: [i64; 3]) -> u64 {
    ((c[0] as u64) << (2 * AXIS_BITS)) | ((c[1] as u64) << AXIS_BITS) | c[2] as u64
}

/// Cell size and cells per axis of a box.
#[derive(Debug, Clone, Copy)]
struct Layout {
    origin: [f64; 3],
    cell: f64,
    inv: f64,
    dims: [i64; 3],
}

impl Layout {
    fn new(lo: [f64; 3], hi: [f64; 3], cell: f64) -> Self {
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        // Never more than AXIS_CELLS cells along an axis; never a zero cell.
        let min_cell = (extent / (AXIS_CELLS - 2) as f64).max(f64::MIN_POSITIVE);
        let mut cell = if cell.is_finite() && cell > 0.0 {
            cell.max(min_cell)
        } else {
            1.0
        };
        if extent == 0.0 {
            cell = cell.max(1.0);
        }
        let inv = 1.0 / cell;
        let mut dims = [1; 3];
        for a in 0..3 {
            dims[a] = (((hi[a] - lo[a]) * inv).floor() as i64 + 1).clamp(1, AXIS_CELLS);
        }
        Self {
            origin: lo,
            cell,
            inv,
            dims,
        }
    }

    fn cell_of(&self, p: &[f64; 3]) -> [i64; 3] {
        let mut c = [0; 3];
        for a in 0..3 {
            c[a] = (((p[a] - self.origin[a]) * self.inv).floor() as i64).clamp(0, self.dims[a] - 1);
        }
        c
    }

    fn key_of(&self, p: &Point3) -> u64 {
        pack(self.cell_of(&[p.x, p.y, p.z]))
    }
}

/// The points of a 3x3x3 block of cells, in single precision relative to the
/// centre cell's corner (struct of arrays, so distances vectorize).
#[derive(Debug, Default)]
struct Block {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    /// Sorted position of each point.
    pos: Vec<u32>,
    /// Scratch: squared distances to the current query.
    d2: Vec<f32>,
}

impl Block {
    fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.pos.clear();
    }

    fn push(&mut self, p: &[f64; 3], corner: &[f64; 3], pos: u32) {
        self.x.push((p[0] - corner[0]) as f32);
        self.y.push((p[1] - corner[1]) as f32);
        self.z.push((p[2] - corner[2]) as f32);
        self.pos.push(pos);
    }
}

/// A uniform grid over a cloud, with its points sorted by cell.
#[derive(Debug)]
pub(crate) struct PointGrid {
    layout: Layout,
    /// The points in cell order.
    sorted: Vec<[f64; 3]>,
    /// For each sorted point, its index in the caller's cloud.
    index: Vec<u32>,
    /// Cell `c`'s points are `sorted[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    table_keys: Vec<u64>,
    table_cells: Vec<u32>,
    shift: u32,
}

impl PointGrid {
    /// A grid whose non-empty cells hold about `k / 2` points on average
    /// (at least 2). `points` must be non-empty, finite and fewer than 2^32.
    pub(crate) fn for_neighbours(points: &[Point3], k: usize) -> Self {
        let (lo, hi) = bounds(points);
        let n = points.len() as f64;
        let target = (k as f64 * 0.5).max(2.0);
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        if extent == 0.0 {
            return Self::with_layout(points, Layout::new(lo, hi, 1.0));
        }
        // First guess: a surface spanning the two largest extents (a depth
        // image); then correct by the measured occupancy (a surface, a volume
        // or a curve all converge in a few steps).
        let mut e: Vec<f64> = (0..3).map(|a| (hi[a] - lo[a]).max(extent * 1e-3)).collect();
        e.sort_by(f64::total_cmp);
        let mut cell = (e[1] * e[2] * target / n).sqrt();
        let mut layout = Layout::new(lo, hi, cell);
        for _ in 0..4 {
            let grid = Self::with_layout(points, layout);
            let occupancy = n / (grid.starts.len() - 1) as f64;
            if occupancy > 0.5 * target && occupancy < 2.0 * target {
                return grid;
            }
            cell = layout.cell * (target / occupancy).sqrt().clamp(0.125, 8.0);
            layout = Layout::new(lo, hi, cell);
        }
        Self::with_layout(points, layout)
    }

    fn with_layout(points: &[Point3], layout: Layout) -> Self {
        let mut pairs: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (layout.key_of(p), i as u32))
            .collect();
        pairs.par_sort_unstable();
        let sorted = pairs
            .par_iter()
            .map(|&(_, i)| {
                let p = &points[i as usize];
                [p.x, p.y, p.z]
            })
            .collect();
        let index = pairs.par_iter().map(|&(_, i)| i).collect();
        let mut keys = Vec::new();
        let mut starts = Vec::new();
        for (pos, &(key, _)) in pairs.iter().enumerate() {
            if keys.last() != Some(&key) {
                keys.push(key);
                starts.push(pos as u32);
            }
        }
        starts.push(pairs.len() as u32);
        let capacity = (2 * keys.len()).next_power_of_two().max(2);
        let shift = 64 - capacity.trailing_zeros();
        let mut table_keys = vec![EMPTY; capacity];
        let mut table_cells = vec![0u32; capacity];
        let mask = capacity - 1;
        for (c, &key) in keys.iter().enumerate() {
            let mut slot = Self::hash(key, shift);
            while table_keys[slot] != EMPTY {
                slot = (slot + 1) & mask;
            }
            table_keys[slot] = key;
            table_cells[slot] = c as u32;
        }
        Self {
            layout,
            sorted,
            index,
            starts,
            table_keys,
            table_cells,
            shift,
        }
    }

    fn hash(key: u64, shift: u32) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize
    }

    /// The sorted range of the cell with these coordinates (empty if none).
    fn cell_range(&self, c: [i64; 3]) -> std::ops::Range<usize> {
        let key = pack(c);
        let mask = self.table_keys.len() - 1;
        let mut slot = Self::hash(key, self.shift);
        loop {
            let k = self.table_keys[slot];
            if k == key {
                let cell = self.table_cells[slot] as usize;
                return self.starts[cell] as usize..self.starts[cell + 1] as usize;
            }
            if k == EMPTY {
                return 0..0;
            }
            slot = (slot + 1) & mask;
        }
    }

    fn scan(&self, c: [i64; 3], q: &[f64; 3], exclude: u32, k: usize, out: &mut Vec<(f64, u32)>) {
        for s in self.cell_range(c) {
            let p = &self.sorted[s];
            let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            let d2 = dx * dx + dy * dy + dz * dz;
            if out.len() == k && d2 >= out[k - 1].0 {
                continue;
            }
            let i = self.index[s];
            if i == exclude {
                continue;
            }
            if out.len() == k {
                out.pop();
            }
            let pos = out.partition_point(|&(d, _)| d <= d2);
            out.insert(pos, (d2, i));
        }
    }

    /// Answers the queries of every point of cell `cell` (by rank) against the
    /// 3x3x3 block of cells around it, pushing `(index, Some(f(...)))` into
    /// `acc`, or `(index, None)` when the block cannot settle the query.
    fn block_queries<T, F>(
        &self,
        cell: usize,
        k: usize,
        f: &F,
        block: &mut Block,
        buf: &mut Vec<(f64, u32)>,
        acc: &mut Vec<(u32, Option<T>)>,
    ) where
        F: Fn(usize, &[(f64, u32)]) -> T,
    {
        let l = &self.layout;
        let members = self.starts[cell] as usize..self.starts[cell + 1] as usize;
        let members_len = members.len();
        let first = &self.sorted[members.start];
        let c = l.cell_of(first);
        let corner: [f64; 3] = std::array::from_fn(|a| l.origin[a] + c[a] as f64 * l.cell);
        block.clear();
        for dx in -1..=1 {
            let x = c[0] + dx;
            if x < 0 || x >= l.dims[0] {
                continue;
            }
            for dy in -1..=1 {
                let y = c[1] + dy;
                if y < 0 || y >= l.dims[1] {
                    continue;
                }
                for dz in -1..=1 {
                    let z = c[2] + dz;
                    if z >= 0 && z < l.dims[2] {
                        for s in self.cell_range([x, y, z]) {
                            block.push(&self.sorted[s], &corner, s as u32);
                        }
                    }
                }
            }
        }
        // Distance bound of the block, per axis side (infinite at the grid's edge).
        let mut lower = [f64::NEG_INFINITY; 3];
        let mut upper = [f64::INFINITY; 3];
        for a in 0..3 {
            if c[a] - 1 > 0 {
                lower[a] = l.origin[a] + (c[a] - 1) as f64 * l.cell;
            }
            if c[a] + 1 < l.dims[a] - 1 {
                upper[a] = l.origin[a] + (c[a] + 2) as f64 * l.cell;
            }
        }
        for s in members {
            let q = &self.sorted[s];
            let exclude = self.index[s];
            // Only candidates nearer than everything outside the block can be
            // among the k nearest of a settled query.
            let mut bound = f64::INFINITY;
            for a in 0..3 {
                bound = bound.min(q[a] - lower[a]).min(upper[a] - q[a]);
            }
            let bound2 = bound * bound;
            // A vectorized single-precision pass (coordinates relative to the
            // cell's corner), then the exact distance of the few that may pass.
            let qf: [f32; 3] = std::array::from_fn(|a| (q[a] - corner[a]) as f32);
            block.d2.clear();
            block.d2.extend(
                block
                    .x
                    .iter()
                    .zip(&block.y)
                    .zip(&block.z)
                    .map(|((x, y), z)| {
                        let (dx, dy, dz) = (x - qf[0], y - qf[1], z - qf[2]);
                        dx * dx + dy * dy + dz * dz
                    }),
            );
            // In a dense cell the k nearest lie well inside the block: first
            // look within the radius k of them would need on a surface of the
            // cell's density (with a margin), then, if too few, within the bound.
            let guess2 = 2.5 * k as f64 * l.cell * l.cell / (PI * members_len as f64);
            for limit2 in [guess2.min(bound2), bound2] {
                let loose = (limit2 * (1.0 + 1e-4) + 1e-12 * l.cell * l.cell) as f32;
                buf.clear();
                for (j, &d2f) in block.d2.iter().enumerate() {
                    if d2f > loose {
                        continue;
                    }
                    let sp = block.pos[j] as usize;
                    let p = &self.sorted[sp];
                    let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
                    let d2 = dx * dx + dy * dy + dz * dz;
                    let i = self.index[sp];
                    if d2 <= limit2 && i != exclude {
                        buf.push((d2, i));
                    }
                }
                if buf.len() >= k {
                    break;
                }
            }
            let settled = buf.len() >= k;
            if buf.len() > k {
                buf.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
                buf.truncate(k);
            }
            acc.push((exclude, settled.then(|| f(exclude as usize, buf))));
        }
    }

    /// The `k` nearest points to `q` other than point `exclude`, as `(squared
    /// distance, index)` by increasing distance, into `out`; fewer if the cloud
    /// has fewer. Returns `false` (and an incomplete `out`) if more than
    /// `max_shells` shells of cells would be needed.
    fn nearest(
        &self,
        q: &[f64; 3],
        exclude: u32,
        k: usize,
        max_shells: i64,
        out: &mut Vec<(f64, u32)>,
    ) -> bool {
        out.clear();
        let l = &self.layout;
        let c = l.cell_of(q);
        let mut r = 0i64;
        loop {
            if r > max_shells {
                return false;
            }
            for dx in -r..=r {
                let x = c[0] + dx;
                if x < 0 || x >= l.dims[0] {
                    continue;
                }
                for dy in -r..=r {
                    let y = c[1] + dy;
                    if y < 0 || y >= l.dims[1] {
                        continue;
                    }
                    if dx.abs() == r || dy.abs() == r {
                        for dz in -r..=r {
                            let z = c[2] + dz;
                            if z >= 0 && z < l.dims[2] {
                                self.scan([x, y, z], q, exclude, k, out);
                            }
                        }
                    } else {
                        for z in [c[2] - r, c[2] + r] {
                            if z >= 0 && z < l.dims[2] {
                                self.scan([x, y, z], q, exclude, k, out);
                            }
                        }
                    }
                }
            }
            // Distance from q to the nearest cell outside the scanned box.
            let mut bound = f64::INFINITY;
            for a in 0..3 {
                if c[a] - r > 0 {
                    bound = bound.min(q[a] - (l.origin[a] + (c[a] - r) as f64 * l.cell));
                }
                if c[a] + r < l.dims[a] - 1 {
                    bound = bound.min(l.origin[a] + (c[a] + r + 1) as f64 * l.cell - q[a]);
                }
            }
            if bound == f64::INFINITY {
                return true; // the box covers the whole grid
            }
            if out.len() == k && bound >= 0.0 && out[k - 1].0 <= bound * bound {
                return true;
            }
            r += 1;
        }
    }
}

/// For every point `i` of a non-empty, finite cloud (fewer than 2^32 points),
/// `f(i, neighbours)` with its `k` nearest other points as `(squared distance,
/// index)`, in no particular order (fewer if the cloud has fewer than `k + 1`
/// points). Runs in parallel; results in point order.
pub(crate) fn for_each_knn<T, F>(points: &[Point3], k: usize, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &[(f64, u32)]) -> T + Sync,
{
    let mut results: Vec<Option<T>> = Vec::with_capacity(points.len());
    results.resize_with(points.len(), || None);
    if k == 0 {
        return (0..points.len()).map(|i| f(i, &[])).collect();
    }
    let mut grid = PointGrid::for_neighbours(points, k);
    let (lo, hi) = (grid.layout.origin, bounds(points).1);
    // First pass: cell by cell, each query against the 27 cells around its own.
    let first: Vec<(u32, Option<T>)> = (0..grid.starts.len() - 1)
        .into_par_iter()
        .fold(
            || (Vec::new(), Block::default(), Vec::with_capacity(k + 1)),
            |(mut acc, mut block, mut buf), cell| {
                grid.block_queries(cell, k, &f, &mut block, &mut buf, &mut acc);
                (acc, block, buf)
            },
        )
        .map(|(acc, _, _)| acc)
        .flatten()
        .collect();
    let mut pending = Vec::new();
    for (i, outcome) in first {
        match outcome {
            Some(t) => results[i as usize] = Some(t),
            None => pending.push(i),
        }
    }
    // Then shell by shell on the same grid, then on ever coarser grids.
    while !pending.is_empty() {
        let coarse = grid.layout.dims.iter().all(|&d| d <= COARSE_CELLS);
        let max_shells = if coarse { i64::MAX } else { MAX_SHELLS };
        let outcomes: Vec<(u32, Option<T>)> = pending
            .par_iter()
            .map_init(
                || Vec::with_capacity(k + 1),
                |buf, &i| {
                    let p = &points[i as usize];
                    let done = grid.nearest(&[p.x, p.y, p.z], i, k, max_shells, buf);
                    (i, done.then(|| f(i as usize, buf)))
                },
            )
            .collect();
        pending.clear();
        for (i, outcome) in outcomes {
            match outcome {
                Some(t) => results[i as usize] = Some(t),
                None => pending.push(i),
            }
        }
        if pending.is_empty() {
            break;
        }
        grid = PointGrid::with_layout(points, Layout::new(lo, hi, grid.layout.cell * 4.0));
    }
    results
        .into_iter()
        .map(|r| r.expect("every query finishes on the coarsest grid"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::NormalRng;

    #[test]
    fn grid_neighbours_match_brute_force() {
        let mut rng = NormalRng::new(3);
        // A noisy plane, a line and a few far points: every regime of the grid.
        let mut points: Vec<Point3> = (0..3000)
            .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.01 * rng.normal()))
            .collect();
        points.extend((0..200).map(|i| Point3::new(2.0 + i as f64 * 0.001, 0.5, 0.0)));
        points.extend((0..20).map(|_| {
            Point3::new(
                50.0 * rng.uniform(),
                50.0 * rng.uniform(),
                50.0 * rng.uniform(),
            )
        }));
        points.push(points[7]); // a duplicate
        for k in [1, 5, 20] {
            let got = for_each_knn(&points, k, |_, nb| nb.to_vec());
            for (i, nb) in got.iter().enumerate() {
                let mut nb = nb.clone();
                nb.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut d: Vec<f64> = (0..points.len())
                    .filter(|&j| j != i)
                    .map(|j| (points[j] - points[i]).norm_squared())
                    .collect();
                d.sort_by(f64::total_cmp);
                assert_eq!(nb.len(), k);
                for (m, &(d2, j)) in nb.iter().enumerate() {
                    assert!(
                        (d2 - d[m]).abs() <= 1e-12 * (1.0 + d[m]),
                        "point {i}, k {k}"
                    );
                    assert_ne!(j as usize, i);
                }
            }
        }
    }

    #[test]
    fn tiny_and_degenerate_clouds() {
        let points = vec![Point3::new(1.0, 1.0, 1.0); 5];
        let got = for_each_knn(&points, 3, |_, nb| nb.len());
        assert_eq!(got, vec![3; 5]);
        let got = for_each_knn(&points[..2], 3, |_, nb| nb.len());
        assert_eq!(got, vec![1; 2]);
    }
}
