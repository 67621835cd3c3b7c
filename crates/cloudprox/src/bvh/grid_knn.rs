//! A uniform grid over a cloud, for exact k-nearest-neighbour queries on
//! millions of points.
//!
//! Points are sorted once by the Morton code of a fine cell, so that the cells
//! of every coarser level (cell size doubled per level) are contiguous runs of
//! the same order: one sort gives a whole hierarchy of grids. The main level is
//! the one whose non-empty cells hold about `max(k / 2, 8)` points; a cell of it
//! much denser than that (a near object in a depth image) is split into its
//! children, down to the finest level, so the work per query follows the local
//! density. Non-empty cells of a level are found through an open-addressing
//! hash table of their keys.
//!
//! Queries are answered cell by cell: the points of the 3x3x3 block of cells
//! around a query cell are gathered once (single precision, relative to the
//! cell's corner, struct of arrays) and shared by all queries of the cell. A
//! query computes its single-precision distances to the block in one vectorized
//! pass, keeps those within a radius guessed from the previous query of the cell
//! (or from the cell's density), and recomputes the kept ones exactly in double
//! precision; it is settled when at least `k` lie within a radius that does not
//! exceed the distance to the outside of the block, and its `k` nearest are then
//! selected (not sorted). The few queries a block cannot settle (isolated
//! points) are retried by shells of cells on the main level, then on ever
//! coarser levels, so that an isolated point never walks thousands of empty
//! cells. Every distance handed to the caller is the exact double-precision
//! `|p - q|²`, so the neighbours are those of a brute-force search up to ties.

use std::f64::consts::PI;
use std::ops::Range;

use rayon::prelude::*;

use crate::math::Point3;

/// Bits of a fine cell coordinate (three of them make a Morton code).
const AXIS_BITS: u32 = 21;
/// Most fine cells along one axis.
const AXIS_CELLS: u32 = (1 << AXIS_BITS) - 1;
/// Marks an empty hash slot (a Morton code has 63 bits, so no key is all ones).
const EMPTY: u64 = u64::MAX;
/// Shells a query may scan on one level before it is retried two levels coarser.
const MAX_SHELLS: i64 = 2;
/// A level with at most this many cells along every axis is searched exhaustively.
const COARSE_CELLS: i64 = 8;
/// Levels finer than the first guess of the main cell size that the sort resolves.
const FINE_LEVELS: u32 = 2;
/// A cell holding more than this many times the target occupancy is split.
const DENSE: f64 = 3.0;
/// Least target occupancy of a main-level cell (below it, the 27 cell look-ups
/// of a block cost more than the distances they save).
const MIN_OCCUPANCY: f64 = 8.0;

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

/// Spreads the low 21 bits of `v` two bits apart.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The Morton code of cell coordinates (each below 2^21): 63 bits. The code of
/// a cell `level` levels coarser is this code shifted right by `3 level`.
fn morton(c: [u32; 3]) -> u64 {
    (spread(c[0]) << 2) | (spread(c[1]) << 1) | spread(c[2])
}

/// Sorts `(key, index)` pairs by key (keys below `2^bits`), stably, by least
/// significant digit first (a few passes, where a comparison sort of millions of
/// pairs costs several times more).
fn radix_sort(pairs: &mut Vec<(u64, u32)>, bits: u32) {
    const DIGIT: u32 = 11;
    let passes = bits.div_ceil(DIGIT);
    let mut other = vec![(0u64, 0u32); pairs.len()];
    for pass in 0..passes {
        let shift = pass * DIGIT;
        let digit = |key: u64| ((key >> shift) & ((1 << DIGIT) - 1)) as usize;
        let mut count = vec![0usize; 1 << DIGIT];
        for &(key, _) in pairs.iter() {
            count[digit(key)] += 1;
        }
        if count.contains(&pairs.len()) {
            continue; // every key has this digit
        }
        let mut sum = 0;
        for c in &mut count {
            let here = *c;
            *c = sum;
            sum += here;
        }
        for &pair in pairs.iter() {
            let d = digit(pair.0);
            other[count[d]] = pair;
            count[d] += 1;
        }
        std::mem::swap(pairs, &mut other);
    }
}

/// The fine cells of a box: origin, cell size and cells per axis.
#[derive(Debug, Clone, Copy)]
struct Frame {
    origin: [f64; 3],
    unit: f64,
    inv: f64,
    dims: [u32; 3],
}

impl Frame {
    fn new(lo: [f64; 3], hi: [f64; 3], unit: f64) -> Self {
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        // Never more than AXIS_CELLS cells along an axis; never a zero cell.
        let min_unit = (extent / f64::from(AXIS_CELLS - 2)).max(f64::MIN_POSITIVE);
        let mut unit = if unit.is_finite() && unit > 0.0 {
            unit.max(min_unit)
        } else {
            1.0
        };
        if extent == 0.0 {
            unit = unit.max(1.0);
        }
        let inv = 1.0 / unit;
        let dims = std::array::from_fn(|a| {
            (((hi[a] - lo[a]) * inv).floor() as i64 + 1).clamp(1, i64::from(AXIS_CELLS)) as u32
        });
        Self {
            origin: lo,
            unit,
            inv,
            dims,
        }
    }

    /// The fine cell of a point (clamped into the box).
    fn cell_of(&self, p: &[f64; 3]) -> [u32; 3] {
        std::array::from_fn(|a| {
            // Truncation is the floor here (the origin is the lowest corner of
            // the cloud), and much cheaper than `floor` without SSE4.1.
            (((p[a] - self.origin[a]) * self.inv) as i64).clamp(0, i64::from(self.dims[a]) - 1)
                as u32
        })
    }
}

/// The non-empty cells of one level of the hierarchy.
#[derive(Debug)]
struct Level {
    /// Levels above the fine cells (cell size `unit · 2^depth`).
    depth: u32,
    /// Origin of the cells (the frame's).
    origin: [f64; 3],
    /// Cell size.
    cell: f64,
    /// Cells per axis.
    dims: [i64; 3],
    /// Cell `c`'s points are the sorted positions `starts[c]..starts[c + 1]`.
    starts: Vec<u32>,
    /// Open-addressing hash table of the non-empty cells.
    table: Vec<Slot>,
    shift: u32,
}

/// A hash slot: a cell's key and sorted range (one cache line per probe).
#[derive(Debug, Clone, Copy)]
struct Slot {
    key: u64,
    start: u32,
    end: u32,
}

impl Level {
    fn build(frame: &Frame, codes: &[u64], level: u32) -> Self {
        let s = 3 * level;
        let mut keys = Vec::new();
        let mut starts = Vec::new();
        let mut last = EMPTY;
        for (pos, &code) in codes.iter().enumerate() {
            let key = code >> s;
            if key != last {
                keys.push(key);
                starts.push(pos as u32);
                last = key;
            }
        }
        starts.push(codes.len() as u32);
        let capacity = (2 * keys.len()).next_power_of_two().max(2);
        let shift = 64 - capacity.trailing_zeros();
        let mut table = vec![
            Slot {
                key: EMPTY,
                start: 0,
                end: 0
            };
            capacity
        ];
        let mask = capacity - 1;
        for (c, &key) in keys.iter().enumerate() {
            let mut slot = Self::hash(key, shift);
            while table[slot].key != EMPTY {
                slot = (slot + 1) & mask;
            }
            table[slot] = Slot {
                key,
                start: starts[c],
                end: starts[c + 1],
            };
        }
        Self {
            depth: level,
            origin: frame.origin,
            cell: frame.unit * f64::from(1u32 << level),
            dims: std::array::from_fn(|a| i64::from((frame.dims[a] - 1) >> level) + 1),
            starts,
            table,
            shift,
        }
    }

    fn hash(key: u64, shift: u32) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize
    }

    fn cells(&self) -> usize {
        self.starts.len() - 1
    }

    fn range(&self, cell: usize) -> Range<usize> {
        self.starts[cell] as usize..self.starts[cell + 1] as usize
    }

    /// This level's coordinates of a fine cell.
    fn coords(&self, fine: [u32; 3]) -> [i64; 3] {
        std::array::from_fn(|a| i64::from(fine[a] >> self.depth))
    }

    /// The sorted range of the cell with these coordinates (empty if none).
    fn cell_range(&self, c: [i64; 3]) -> Range<usize> {
        let key = morton([c[0] as u32, c[1] as u32, c[2] as u32]);
        let mask = self.table.len() - 1;
        let mut slot = Self::hash(key, self.shift);
        loop {
            let e = self.table[slot];
            if e.key == key {
                return e.start as usize..e.end as usize;
            }
            if e.key == EMPTY {
                return 0..0;
            }
            slot = (slot + 1) & mask;
        }
    }

    /// The lowest coordinate of cell coordinate `c` along axis `a`.
    fn wall(&self, a: usize, c: i64) -> f64 {
        self.origin[a] + c as f64 * self.cell
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
    /// Scratch: block slots passing the single-precision test.
    kept: Vec<u32>,
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

/// Per-thread scratch of the block pass.
#[derive(Debug, Default)]
struct Scratch {
    block: Block,
    buf: Vec<(f64, u32)>,
}

/// The cloud sorted by Morton code, with the levels built so far.
#[derive(Debug)]
struct PointGrid {
    frame: Frame,
    /// The points in Morton order.
    sorted: Vec<[f64; 3]>,
    /// For each sorted point, its index in the caller's cloud.
    index: Vec<u32>,
    /// For each sorted point, the Morton code of its fine cell (ascending).
    codes: Vec<u64>,
    /// Levels by number, built on demand.
    levels: Vec<Option<Level>>,
}

impl PointGrid {
    /// Sorts the cloud by the fine cells of `frame`.
    fn new(points: &[Point3], frame: Frame) -> Self {
        let mut pairs: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (morton(frame.cell_of(&[p.x, p.y, p.z])), i as u32))
            .collect();
        let bits = frame
            .dims
            .iter()
            .map(|&d| 32 - d.leading_zeros())
            .max()
            .unwrap_or(1);
        radix_sort(&mut pairs, 3 * bits);
        let sorted = pairs
            .par_iter()
            .map(|&(_, i)| {
                let p = &points[i as usize];
                [p.x, p.y, p.z]
            })
            .collect();
        let index = pairs.par_iter().map(|&(_, i)| i).collect();
        let codes = pairs.par_iter().map(|&(c, _)| c).collect();
        Self {
            frame,
            sorted,
            index,
            codes,
            levels: (0..=AXIS_BITS).map(|_| None).collect(),
        }
    }

    /// Number of non-empty cells on every level (one pass over the codes).
    fn cell_counts(&self) -> Vec<usize> {
        let mut first_diff = self
            .codes
            .par_windows(2)
            .fold(
                || vec![0usize; AXIS_BITS as usize + 1],
                |mut h, w| {
                    let x = w[0] ^ w[1];
                    if x != 0 {
                        h[(x.ilog2() / 3) as usize] += 1;
                    }
                    h
                },
            )
            .reduce(
                || vec![0usize; AXIS_BITS as usize + 1],
                |mut a, b| {
                    for (x, y) in a.iter_mut().zip(b) {
                        *x += y;
                    }
                    a
                },
            );
        // Cells on level l: one plus the adjacent pairs differing at level l or above.
        let mut above = 1;
        for h in first_diff.iter_mut().rev() {
            above += *h;
            *h = above;
        }
        first_diff
    }

    fn ensure(&mut self, level: u32) {
        if self.levels[level as usize].is_none() {
            self.levels[level as usize] = Some(Level::build(&self.frame, &self.codes, level));
        }
    }

    #[allow(clippy::expect_used)] // every caller builds the level first
    fn level(&self, level: u32) -> &Level {
        self.levels[level as usize]
            .as_ref()
            .expect("levels are built before use")
    }

    /// Answers the queries of cell `cell` of `level`, or of its children if it
    /// is denser than `dense` points and a finer level is built.
    fn cell_queries<T, F>(
        &self,
        level: u32,
        cell: usize,
        k: usize,
        dense: usize,
        f: &F,
        scratch: &mut Scratch,
        acc: &mut Vec<(u32, Option<T>)>,
    ) where
        F: Fn(usize, &[(f64, u32)]) -> T,
    {
        let l = self.level(level);
        let range = l.range(cell);
        if range.len() > dense && level > 0 {
            if let Some(fine) = &self.levels[level as usize - 1] {
                let mut child = fine.starts.partition_point(|&s| (s as usize) < range.start);
                while (fine.starts[child] as usize) < range.end {
                    self.cell_queries(level - 1, child, k, dense, f, scratch, acc);
                    child += 1;
                }
                return;
            }
        }
        self.block_queries(l, range, k, f, scratch, acc);
    }

    /// Answers the queries of every point of one cell of `l` (its sorted range
    /// `members`) against the 3x3x3 block of cells around it, pushing `(index,
    /// Some(f(...)))` into `acc`, or `(index, None)` when the block cannot settle
    /// the query.
    fn block_queries<T, F>(
        &self,
        l: &Level,
        members: Range<usize>,
        k: usize,
        f: &F,
        scratch: &mut Scratch,
        acc: &mut Vec<(u32, Option<T>)>,
    ) where
        F: Fn(usize, &[(f64, u32)]) -> T,
    {
        let Scratch { block, buf } = scratch;
        let c = l.coords(self.frame.cell_of(&self.sorted[members.start]));
        let corner: [f64; 3] = std::array::from_fn(|a| l.wall(a, c[a]));
        block.clear();
        for x in (c[0] - 1).max(0)..=(c[0] + 1).min(l.dims[0] - 1) {
            for y in (c[1] - 1).max(0)..=(c[1] + 1).min(l.dims[1] - 1) {
                for z in (c[2] - 1).max(0)..=(c[2] + 1).min(l.dims[2] - 1) {
                    for s in l.cell_range([x, y, z]) {
                        block.push(&self.sorted[s], &corner, s as u32);
                    }
                }
            }
        }
        let n = block.pos.len();
        block.d2.resize(n, 0.0);
        block.kept.resize(n + 1, 0);
        // Distance bound of the block, per axis side (infinite at the level's
        // edge), pulled in a little against rounding in the cell assignment.
        let margin = 1e-9 * l.cell;
        let mut lower = [f64::NEG_INFINITY; 3];
        let mut upper = [f64::INFINITY; 3];
        for a in 0..3 {
            if c[a] - 1 > 0 {
                lower[a] = l.wall(a, c[a] - 1) + margin;
            }
            if c[a] + 1 < l.dims[a] - 1 {
                upper[a] = l.wall(a, c[a] + 2) - margin;
            }
        }
        let cell2 = l.cell * l.cell;
        // The first guess of a cell: the radius holding 2.5 k points on a surface
        // of the cell's density.
        let density_guess2 = 2.5 * k as f64 * cell2 / (PI * members.len() as f64);
        // The previous query of the cell and its k-th distance.
        let mut previous: Option<([f64; 3], f64)> = None;
        for s in members {
            let q = &self.sorted[s];
            let exclude = s as u32;
            let mut bound = f64::INFINITY;
            for a in 0..3 {
                bound = bound.min(q[a] - lower[a]).min(upper[a] - q[a]);
            }
            let bound2 = (bound * bound).max(0.0);
            // Vectorized single-precision distances to the whole block.
            let qf: [f32; 3] = std::array::from_fn(|a| (q[a] - corner[a]) as f32);
            for (((d, x), y), z) in block
                .d2
                .iter_mut()
                .zip(&block.x)
                .zip(&block.y)
                .zip(&block.z)
            {
                let (dx, dy, dz) = (x - qf[0], y - qf[1], z - qf[2]);
                *d = dx * dx + dy * dy + dz * dz;
            }
            // Radii to try: near the previous query's k-th distance (most
            // queries), then its triangle-inequality bound (the previous query
            // and its k nearest are k + 1 points within it), then the block's.
            let mut radii2 = [bound2; 3];
            match previous {
                Some((p, kth)) => {
                    let delta =
                        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                            .sqrt();
                    radii2[0] = (kth + 0.25 * delta).powi(2) * 1.1;
                    radii2[1] = (kth + delta).powi(2) * (1.0 + 1e-9);
                }
                None => radii2[0] = density_guess2,
            }
            let mut settled = false;
            let mut tried = 0.0;
            for limit2 in radii2 {
                let limit2 = limit2.min(bound2);
                if limit2 <= tried {
                    continue;
                }
                tried = limit2;
                // Single-precision error is below 1e-6 (|p - q|² + cell²) here
                // (coordinates within two cells of the corner).
                let loose = (limit2 * (1.0 + 1e-5) + 2e-6 * cell2) as f32;
                let kept = &mut block.kept[..];
                let mut m = 0;
                for (j, &d) in block.d2.iter().enumerate() {
                    kept[m] = j as u32;
                    m += usize::from(d <= loose);
                }
                // The query itself is among them.
                if m <= k {
                    continue;
                }
                buf.clear();
                for &j in &block.kept[..m] {
                    let sp = block.pos[j as usize];
                    let p = &self.sorted[sp as usize];
                    let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
                    let d2 = dx * dx + dy * dy + dz * dz;
                    if d2 <= limit2 && sp != exclude {
                        buf.push((d2, sp));
                    }
                }
                if buf.len() >= k {
                    settled = true;
                    break;
                }
            }
            let i = self.index[s];
            if settled {
                let kth = if buf.len() > k {
                    // Non-negative doubles order as their bits.
                    buf.select_nth_unstable_by_key(k - 1, |e| e.0.to_bits());
                    buf.truncate(k);
                    buf[k - 1].0
                } else {
                    buf.iter().fold(0.0_f64, |m, &(d, _)| m.max(d))
                };
                previous = Some((*q, kth.sqrt()));
                for e in buf.iter_mut() {
                    e.1 = self.index[e.1 as usize];
                }
                acc.push((i, Some(f(i as usize, buf))));
            } else {
                previous = None;
                acc.push((i, None));
            }
        }
    }

    /// Scans the sorted range `range` for nearer candidates of `q`.
    fn scan(
        &self,
        range: Range<usize>,
        q: &[f64; 3],
        exclude: usize,
        k: usize,
        out: &mut Vec<(f64, u32)>,
    ) {
        for s in range {
            let p = &self.sorted[s];
            let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            let d2 = dx * dx + dy * dy + dz * dz;
            if (out.len() == k && d2 >= out[k - 1].0) || s == exclude {
                continue;
            }
            if out.len() == k {
                out.pop();
            }
            let at = out.partition_point(|&(d, _)| d <= d2);
            out.insert(at, (d2, self.index[s]));
        }
    }

    /// The `k` nearest points to sorted point `s` (other than itself), as
    /// `(squared distance, index)` by increasing distance, into `out`; fewer if
    /// the cloud has fewer. Scans shells of cells of `l`; returns `false` (and
    /// an incomplete `out`) if more than `max_shells` shells would be needed.
    fn nearest(
        &self,
        l: &Level,
        s: usize,
        k: usize,
        max_shells: i64,
        out: &mut Vec<(f64, u32)>,
    ) -> bool {
        out.clear();
        let q = &self.sorted[s];
        let c = l.coords(self.frame.cell_of(q));
        let mut r = 0i64;
        loop {
            if r > max_shells {
                return false;
            }
            for x in (c[0] - r).max(0)..=(c[0] + r).min(l.dims[0] - 1) {
                for y in (c[1] - r).max(0)..=(c[1] + r).min(l.dims[1] - 1) {
                    if (x - c[0]).abs() == r || (y - c[1]).abs() == r {
                        for z in (c[2] - r).max(0)..=(c[2] + r).min(l.dims[2] - 1) {
                            self.scan(l.cell_range([x, y, z]), q, s, k, out);
                        }
                    } else {
                        for z in [c[2] - r, c[2] + r] {
                            if z >= 0 && z < l.dims[2] {
                                self.scan(l.cell_range([x, y, z]), q, s, k, out);
                            }
                        }
                    }
                }
            }
            // Distance from q to the nearest cell outside the scanned box.
            let margin = 1e-9 * l.cell;
            let mut bound = f64::INFINITY;
            for a in 0..3 {
                if c[a] - r > 0 {
                    bound = bound.min(q[a] - l.wall(a, c[a] - r) - margin);
                }
                if c[a] + r < l.dims[a] - 1 {
                    bound = bound.min(l.wall(a, c[a] + r + 1) - q[a] - margin);
                }
            }
            if bound == f64::INFINITY {
                return true; // the box covers the whole level
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
#[allow(clippy::expect_used)] // every query finishes on the coarsest level, which holds every point
pub(crate) fn for_each_knn<T, F>(points: &[Point3], k: usize, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &[(f64, u32)]) -> T + Sync,
{
    if k == 0 {
        return (0..points.len()).map(|i| f(i, &[])).collect();
    }
    let n = points.len();
    let target = (k as f64 * 0.5).max(MIN_OCCUPANCY);
    let (lo, hi) = bounds(points);
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    // First guess of the cell size: a surface spanning the two largest extents
    // (a depth image); the sort resolves FINE_LEVELS levels below it, and the
    // main level is then chosen by measured occupancy.
    let mut e: Vec<f64> = (0..3).map(|a| (hi[a] - lo[a]).max(extent * 1e-3)).collect();
    e.sort_by(f64::total_cmp);
    let guess = (e[1] * e[2] * target / n as f64).sqrt();
    let unit = if extent > 0.0 {
        guess / f64::from(1u32 << FINE_LEVELS)
    } else {
        1.0
    };
    let mut grid = PointGrid::new(points, Frame::new(lo, hi, unit));
    let counts = grid.cell_counts();
    let main = (0..=AXIS_BITS)
        .min_by(|&a, &b| {
            let err = |l: u32| (n as f64 / counts[l as usize] as f64 / target).ln().abs();
            err(a).total_cmp(&err(b))
        })
        .expect("levels exist");
    // Levels for dense cells, each built only if the one above has one.
    let dense = (DENSE * target) as usize;
    grid.ensure(main);
    let mut finest = main;
    while finest > 0 {
        let l = grid.level(finest);
        if !(0..l.cells()).any(|c| l.range(c).len() > dense) {
            break;
        }
        finest -= 1;
        grid.ensure(finest);
    }
    // First pass: cell by cell, each query against the 27 cells around its own.
    let top = grid.level(main).cells();
    let first: Vec<Vec<(u32, Option<T>)>> = (0..top)
        .into_par_iter()
        .fold(
            || (Vec::new(), Scratch::default()),
            |(mut acc, mut scratch), cell| {
                grid.cell_queries(main, cell, k, dense, &f, &mut scratch, &mut acc);
                (acc, scratch)
            },
        )
        .map(|(acc, _)| acc)
        .collect();
    let mut results: Vec<Option<T>> = Vec::with_capacity(n);
    results.resize_with(n, || None);
    let mut pending = Vec::new();
    for (i, outcome) in first.into_iter().flatten() {
        match outcome {
            Some(t) => results[i as usize] = Some(t),
            None => pending.push(i),
        }
    }
    // Then shell by shell on the main level, then on ever coarser levels.
    let mut position = Vec::new();
    if !pending.is_empty() {
        position = vec![0u32; n];
        for (s, &i) in grid.index.iter().enumerate() {
            position[i as usize] = s as u32;
        }
    }
    let mut level = main;
    while !pending.is_empty() {
        grid.ensure(level);
        let l = grid.level(level);
        let coarse = l.dims.iter().all(|&d| d <= COARSE_CELLS);
        let max_shells = if coarse { i64::MAX } else { MAX_SHELLS };
        let outcomes: Vec<(u32, Option<T>)> = pending
            .par_iter()
            .map_init(
                || Vec::with_capacity(k + 1),
                |buf, &i| {
                    let done = grid.nearest(l, position[i as usize] as usize, k, max_shells, buf);
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
        level = (level + 2).min(AXIS_BITS);
    }
    results
        .into_iter()
        .map(|r| r.expect("every query finishes on the coarsest level"))
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

    /// The `k` smallest of `values`, ascending (a selection, then a sort of
    /// those alone: the reference below scans every pair).
    fn smallest(mut values: Vec<f64>, k: usize) -> Vec<f64> {
        if k < values.len() {
            values.select_nth_unstable_by(k, f64::total_cmp);
            values.truncate(k);
        }
        values.sort_by(f64::total_cmp);
        values
    }

    /// Checks `for_each_knn` against a brute-force search: the same squared
    /// distances (bit for bit), distinct valid neighbours, never the query.
    fn check_against_brute_force(points: &[Point3], k: usize) {
        let got = for_each_knn(points, k, |_, nb| nb.to_vec());
        for (i, nb) in got.iter().enumerate() {
            let q = &points[i];
            let d2 = |j: usize| {
                let p = &points[j];
                let (dx, dy, dz) = (p.x - q.x, p.y - q.y, p.z - q.z);
                dx * dx + dy * dy + dz * dz
            };
            let brute = smallest((0..points.len()).filter(|&j| j != i).map(d2).collect(), k);
            let mut mine: Vec<f64> = nb.iter().map(|&(d, _)| d).collect();
            mine.sort_by(f64::total_cmp);
            assert_eq!(mine, brute, "point {i}, k {k}");
            let mut seen: Vec<u32> = nb.iter().map(|&(_, j)| j).collect();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), nb.len(), "point {i}: repeated neighbour");
            for &(d, j) in nb {
                assert_ne!(j as usize, i);
                assert_eq!(d, d2(j as usize), "point {i}: distance of {j}");
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(48))]

        /// Random clouds of uneven density: a sparse plane, a patch 20x
        /// denser, a line, scattered far points and exact duplicates.
        #[test]
        fn knn_matches_brute_force_on_uneven_clouds(
            seed in 0u64..1_000_000,
            sparse in 50usize..600,
            dense in 0usize..800,
            far in 0usize..10,
            copies in 0usize..40,
            k in 1usize..25,
        ) {
            let mut rng = NormalRng::new(seed);
            let mut points: Vec<Point3> = (0..sparse)
                .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.002 * rng.normal()))
                .collect();
            points.extend((0..dense).map(|_| {
                Point3::new(0.3 + 0.2 * rng.uniform(), 0.3 + 0.2 * rng.uniform(), 0.1 + 0.001 * rng.normal())
            }));
            points.extend((0..dense / 4).map(|i| Point3::new(1.5, i as f64 * 1e-3, 0.0)));
            points.extend((0..far).map(|_| {
                Point3::new(20.0 * rng.uniform() - 10.0, 20.0 * rng.uniform(), 5.0 * rng.normal())
            }));
            for c in 0..copies {
                let j = (c * 7919) % points.len();
                points.push(points[j]);
                if c % 5 == 0 {
                    points.push(points[j]); // three at one spot
                }
            }
            // Also a lattice (many exact ties).
            points.extend((0..64).map(|i| Point3::new(2.0 + (i / 8) as f64 * 0.01, (i % 8) as f64 * 0.01, 0.0)));
            let k = k.min(points.len() - 1);
            check_against_brute_force(&points, k);
        }
    }

    #[test]
    fn dense_patch_in_sparse_plane_matches_brute_force() {
        // Enough points that the main level has cells split into children.
        let mut rng = NormalRng::new(5);
        let mut points: Vec<Point3> = (0..6000)
            .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.001 * rng.normal()))
            .collect();
        points.extend((0..12000).map(|_| {
            Point3::new(
                0.4 + 0.1 * rng.uniform(),
                0.4 + 0.1 * rng.uniform(),
                0.05 + 0.001 * rng.normal(),
            )
        }));
        for k in [3, 20] {
            check_against_brute_force(&points, k);
        }
    }
}
