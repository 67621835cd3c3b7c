//! A signed-distance grid in a mesh's own frame, built once, with a rigorous
//! bound on its interpolation error: see [`DistanceField`] for what the nodes
//! hold and the derivation of the bound.

use std::sync::Arc;

use rayon::prelude::*;

use super::signed_bvh::{closest_on_triangle, Box3, TriangleBvh};
use super::signed_distance::{Cap, MeshDistance, SignMethod};
use super::signed_topology::NONE;
use crate::error::{Error, Result};
use crate::math::{Point3, Vector3};
use crate::Real;

/// Nodes per side of a super-block (the hierarchy lists the triangles near each).
const SUPER: usize = 8;
/// Nodes per side of a block (each narrows its super-block's list).
const BLOCK: usize = 4;
/// Nodes per side of a sub-block (each narrows its block's list; the nodes
/// search its list).
const PAIR: usize = 2;
/// Cells per side of the largest box the sign certificates try.
const CERTIFY: usize = 8;
/// The most nodes a field may have (about 0.6 GB while building).
const MAX_NODES: usize = 1 << 25;
/// The grid's offset from the mesh's box, in cells per axis: irrational
/// fractions, so that grid lines rarely pass through the vertices and edges of
/// meshes with round coordinates (such lines need the exact sign).
const JITTER: [Real; 3] = [
    0.381_966_011_250_105_1,
    0.271_828_182_845_904_5,
    0.141_421_356_237_309_5,
];

/// A cell interpolates.
const CELL_INTERPOLATED: u8 = 0;
/// A cell answers with the exact query (a corner beyond the band, or near a hole).
const CELL_EXACT: u8 = 1;
/// Every corner of the cell is beyond the band.
const CELL_BEYOND: u8 = 2;
/// A cell interpolates with a bound that holds whatever the side (near a hole).
const CELL_AGNOSTIC: u8 = 3;

/// One answer of a [`DistanceField`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldSample {
    /// The signed distance (metres, negative inside): interpolated, or exact
    /// when `exact`.
    pub distance: Real,
    /// The gradient of `distance`: of the trilinear interpolant (not unit in
    /// general), or the exact unit gradient when `exact`.
    pub gradient: Vector3,
    /// A bound on the error: `|s(x) - distance| <= bound` for the exact signed
    /// distance `s` (0 when `exact`). See [`DistanceField`].
    pub bound: Real,
    /// Whether the answer is the exact query's ([`MeshDistance::closest`]).
    pub exact: bool,
}

impl FieldSample {
    const NAN: FieldSample = FieldSample {
        distance: Real::NAN,
        gradient: Vector3::new(Real::NAN, Real::NAN, Real::NAN),
        bound: Real::NAN,
        exact: true,
    };
}

/// What [`DistanceField::evaluate_in_band`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldValue {
    /// Within the band (or in a cell that needs the exact query): the sample.
    Near(FieldSample),
    /// Farther than the band: the distance is at least `lower_bound`, and
    /// `inside` is the side (that of the cell's corners, which agree and are
    /// certified; outside the grid, always outside).
    Beyond {
        /// A lower bound on the unsigned distance (metres).
        lower_bound: Real,
        /// Whether the point is inside.
        inside: bool,
    },
}

/// What building a [`DistanceField`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FieldStats {
    /// Nodes of the grid.
    pub nodes: usize,
    /// Nodes within the band (exact values).
    pub nodes_in_band: usize,
    /// Cells that interpolate.
    pub cells_interpolated: usize,
    /// Cells that interpolate with the bound that holds whatever the side
    /// (near a hole of an open mesh, where the side is not certified).
    pub cells_sign_agnostic: usize,
    /// Cells that answer with the exact query.
    pub cells_exact: usize,
    /// Cells wholly beyond the band.
    pub cells_beyond: usize,
    /// Nodes whose sign needed an exact test: their grid line grazes an edge or
    /// a corner, or they lie near a hole.
    pub exact_sign_nodes: usize,
}

/// A signed-distance grid in a mesh's own frame, with a rigorous bound on its
/// interpolation error.
///
/// # Values at the nodes
///
/// Every node within `band` of the surface holds the exact signed distance of
/// [`MeshDistance`]: the same closest-point routine over the same triangles,
/// and the same side (a closed mesh's inside is where its winding number is 1,
/// an open mesh's where it exceeds 1/2), though found another way. The nodes
/// are computed a block of `8^3` at a time: one exact query at the block's
/// centre bounds how far its nearest triangles can be, the hierarchy lists
/// the triangles that close to the block, each block of `4^3` and then of
/// `2^3` narrows its parent's list, and each node takes the nearest of its
/// last list (which provably holds the nearest triangle of every node within
/// the band). The side comes from the winding
/// number: its integer part `k` counted along the grid's z-lines (signed
/// crossings of the surface closed by fans over its holes), its fractional
/// part from the fans (certified over boxes of cells, below); where a line
/// grazes an edge or a corner within rounding, its nodes ask
/// [`MeshDistance`] instead (the closest feature's pseudo-normal, or the
/// exact winding number). Nodes farther than `band` keep only their side
/// (where it is certified).
///
/// # The error bound
///
/// The signed distance `s` is 1-Lipschitz wherever it is continuous: `|s(x) -
/// s(y)| <= |x - y|` (across the surface the sign changes where `|s| = 0`). So
/// at a point `x` of a cell whose corners `v_i` hold the exact `s_i`, with
/// `r_i = |x - v_i|`,
///
/// ```text
/// L(x) = max_i (s_i - r_i)  <=  s(x)  <=  min_i (s_i + r_i) = U(x)
/// ```
///
/// and the trilinear interpolant `I(x) = sum_i w_i s_i` is off by at most
///
/// ```text
/// bound(x) = max(I(x) - L(x), U(x) - I(x)) + eps,
/// ```
///
/// with `eps` a rounding allowance of `1e-13` times the grid's coordinates.
/// Because `min_i (s_i + r_i) <= sum_i w_i (s_i + r_i)` (and likewise for the
/// maximum), `bound(x) <= sum_i w_i r_i <= sqrt(sum_i w_i r_i^2) = h
/// sqrt(sum_k t_k (1 - t_k))` (`t` the point's position in the cell): never
/// more than the cell's half diagonal `sqrt(3) h / 2` (at its centre), 0 at
/// the nodes. At the centre of a cell cut by a plane it is `0.37 h`, where `I`
/// is exact but the bound cannot know it.
///
/// Continuity holds in every cell of a mesh read by pseudo-normals (a closed
/// surface's signed distance is 1-Lipschitz everywhere). With the winding
/// number the sign can also jump away from the surface, where `w` crosses 1/2
/// across a hole. Write `w = k + w_C`, with `k` the (integer) winding number
/// of the surface closed by fans `C` over its holes and `w_C` the fans' own.
/// A box of cells (from `8^3` cells down to one) is *certified* when no fan
/// crosses it and `w_C` provably stays within `(m - 1/2, m + 1/2)` for an
/// integer `m` over it: `w_C` and its gradient exactly at the box's centre
/// `c`, and `|w_C(x) - w_C(c) - grad w_C(c) . (x - c)| <= H |x - c|^2 / 2`
/// with `H = sum_e l_e / (2 pi g_e^3)` over the fans' boundary edges `e` (of
/// length `l_e` and at least `g_e` away): the gradient of a solid angle is
/// the Biot-Savart field of the boundary loop, whose derivative per length
/// element is at most `2 / |y - x|^3`; fans far from the box are bounded by
/// `A / (4 pi g^2)` (area `A`, ball at least `g` away). There the side is
/// `k + m >= 1`, which changes only across the surface, so `s` is continuous
/// and the bound holds. Cells that are not certified (near holes) answer with
/// the exact query, or, when a corner lies within a cell diagonal of the
/// surface, with a bound that holds whatever the side: `|s(x)| <= min_i
/// (|s_i| + r_i) = R(x)` (the unsigned distance is 1-Lipschitz everywhere), so
/// `|s(x) - I(x)| <= R(x) + |I(x)|`, at most four cell diagonals.
///
/// # Beyond the band
///
/// [`DistanceField::evaluate`] answers a point outside the grid, or in a cell
/// with a corner beyond the band or near a hole, with the exact query (bound
/// 0); [`DistanceField::evaluate_in_band`] reports a point whose whole cell is
/// beyond the band as [`FieldValue::Beyond`] with a lower bound on its
/// distance instead.
///
/// # Example
///
/// ```
/// use std::sync::Arc;
/// use cloudprox::prelude::*;
/// use cloudprox::shape::{DistanceField, MeshDistance};
///
/// let mesh = Arc::new(MeshDistance::new(&Mesh::cuboid(0.1, 0.1, 0.1).unwrap()).unwrap());
/// let field = DistanceField::new(Arc::clone(&mesh), 0.005, 0.02).unwrap();
/// let p = Point3::new(0.104, 0.01, 0.02);
/// let s = field.evaluate(&p);
/// assert!((s.distance - mesh.signed_distance(&p)).abs() <= s.bound);
/// ```
#[derive(Debug, Clone)]
pub struct DistanceField {
    source: Arc<MeshDistance>,
    origin: Point3,
    resolution: Real,
    band: Real,
    dims: [usize; 3],
    /// Signed distance at node `(i, j, k)`, index `(i * ny + j) * nz + k`;
    /// plus or minus infinity beyond the band (the sign is the node's side),
    /// NaN there where the side is not certified.
    values: Vec<Real>,
    /// Per cell (indexed like the nodes, dims minus one), its `CELL_*` state.
    cells: Vec<u8>,
    /// The rounding allowance added to every bound.
    eps: Real,
    stats: FieldStats,
}

impl DistanceField {
    /// Builds the field of `source` with nodes every `resolution` metres over
    /// the mesh's box grown by `band`, exact within `band` of the surface.
    /// Runs on rayon's pool.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `resolution` or `band` is not finite and
    /// positive, or the grid would have more than 2^25 nodes.
    pub fn new(source: Arc<MeshDistance>, resolution: Real, band: Real) -> Result<Self> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(Error::invalid(format!(
                "resolution must be finite and > 0, got {resolution}"
            )));
        }
        if !(band.is_finite() && band > 0.0) {
            return Err(Error::invalid(format!(
                "band must be finite and > 0, got {band}"
            )));
        }
        let h = resolution;
        let (lo, hi) = source.bounds();
        let origin = Point3::from(std::array::from_fn::<Real, 3, _>(|k| {
            lo[k] - band - JITTER[k] * h
        }));
        let mut dims = [0usize; 3];
        let mut nodes: usize = 1;
        for k in 0..3 {
            let cells = ((hi[k] + band - origin[k]) / h).ceil();
            if cells.is_nan() || cells >= MAX_NODES as Real {
                return Err(too_many(h, band));
            }
            dims[k] = (cells as usize + 1).max(2);
            nodes = nodes
                .checked_mul(dims[k])
                .ok_or_else(|| too_many(h, band))?;
        }
        if nodes > MAX_NODES {
            return Err(too_many(h, band));
        }
        let far = (0..3)
            .map(|k| origin[k].abs().max((origin[k] + dims[k] as Real * h).abs()))
            .fold(band, Real::max);
        let grid = Grid { origin, h, dims };
        let (unsigned, nearest) = node_distances(&source, &grid, band);
        let (values, certs, exact_sign_nodes) = node_signs(&source, &grid, &unsigned, &nearest);
        let cells = cell_states(&grid, &values, &certs, band);
        let mut counts = [0usize; 4];
        for &c in &cells {
            counts[c as usize] += 1;
        }
        let count = |s: u8| counts[s as usize];
        let stats = FieldStats {
            nodes,
            nodes_in_band: unsigned.iter().filter(|u| u.is_finite()).count(),
            cells_interpolated: count(CELL_INTERPOLATED),
            cells_sign_agnostic: count(CELL_AGNOSTIC),
            cells_exact: count(CELL_EXACT),
            cells_beyond: count(CELL_BEYOND),
            exact_sign_nodes,
        };
        Ok(Self {
            source,
            origin,
            resolution: h,
            band,
            dims,
            values,
            cells,
            eps: 1e-13 * far,
            stats,
        })
    }

    /// The exact queries the field falls back to.
    pub fn source(&self) -> &Arc<MeshDistance> {
        &self.source
    }

    /// The node spacing (metres).
    pub fn resolution(&self) -> Real {
        self.resolution
    }

    /// The band within which nodes hold exact values (metres).
    pub fn band(&self) -> Real {
        self.band
    }

    /// Nodes per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The position of node `(0, 0, 0)`.
    pub fn origin(&self) -> Point3 {
        self.origin
    }

    /// The position of node `(i, j, k)`.
    pub fn node_position(&self, i: usize, j: usize, k: usize) -> Point3 {
        Grid {
            origin: self.origin,
            h: self.resolution,
            dims: self.dims,
        }
        .node(i, j, k)
    }

    /// The signed distance at node `(i, j, k)`: exact within the band, plus or
    /// minus infinity beyond it (the sign is the node's side), NaN beyond it
    /// where the side was not certified (near a hole of an open mesh); `None`
    /// outside the grid.
    pub fn node_value(&self, i: usize, j: usize, k: usize) -> Option<Real> {
        let [nx, ny, nz] = self.dims;
        (i < nx && j < ny && k < nz).then(|| self.values[(i * ny + j) * nz + k])
    }

    /// What the build found.
    pub fn stats(&self) -> &FieldStats {
        &self.stats
    }

    /// The bytes the grid holds (values and cell states).
    pub fn memory_bytes(&self) -> usize {
        self.values.len() * size_of::<Real>() + self.cells.len()
    }

    /// The signed distance at `p` (in the mesh's frame), its gradient and a
    /// bound on the error (see [`FieldSample`]): interpolated in the band, the
    /// exact query elsewhere. NaN for a non-finite `p`.
    pub fn evaluate(&self, p: &Point3) -> FieldSample {
        match self.locate(p) {
            Locate::NotFinite => FieldSample::NAN,
            Locate::Cell(cell, t) => match self.cells[cell.index] {
                CELL_INTERPOLATED => self.interpolate(&cell, &t, true),
                CELL_AGNOSTIC => self.interpolate(&cell, &t, false),
                _ => self.exact(p),
            },
            Locate::Outside => self.exact(p),
        }
    }

    /// [`DistanceField::evaluate`], but a point whose cell is wholly beyond the
    /// band, or outside the grid, is [`FieldValue::Beyond`] with a lower bound
    /// on its distance (no exact query).
    pub fn evaluate_in_band(&self, p: &Point3) -> FieldValue {
        let outside = |p: &Point3| {
            let (lo, hi) = self.source.bounds();
            let b = Box3 {
                mins: lo.into(),
                maxs: hi.into(),
            };
            // Less the rounding allowance: the box's distance and the
            // triangles' are computed differently.
            (b.distance2_to_point(p).sqrt() - self.eps).max(0.0)
        };
        match self.locate(p) {
            Locate::NotFinite => FieldValue::Near(FieldSample::NAN),
            Locate::Outside => FieldValue::Beyond {
                lower_bound: outside(p),
                inside: false,
            },
            Locate::Cell(cell, t) => match self.cells[cell.index] {
                CELL_INTERPOLATED => FieldValue::Near(self.interpolate(&cell, &t, true)),
                CELL_AGNOSTIC => FieldValue::Near(self.interpolate(&cell, &t, false)),
                CELL_BEYOND => {
                    let (mut nearest, mut r_min) = (0, Real::INFINITY);
                    for c in 0..8 {
                        let r = corner_distance(&t, c) * self.resolution;
                        if r < r_min {
                            (nearest, r_min) = (c, r);
                        }
                    }
                    FieldValue::Beyond {
                        lower_bound: (self.band - r_min - self.eps).max(outside(p)),
                        inside: self.values[cell.corner(nearest)] < 0.0,
                    }
                }
                _ => FieldValue::Near(self.exact(p)),
            },
        }
    }

    /// [`DistanceField::evaluate`] of each point (in parallel for large batches).
    pub fn evaluate_many(&self, points: &[Point3]) -> Vec<FieldSample> {
        if points.len() < 256 {
            points.iter().map(|p| self.evaluate(p)).collect()
        } else {
            points
                .par_iter()
                .with_min_len(256)
                .map(|p| self.evaluate(p))
                .collect()
        }
    }

    /// The exact query's answer as a sample.
    fn exact(&self, p: &Point3) -> FieldSample {
        let c = self.source.closest(p);
        FieldSample {
            distance: c.signed_distance,
            gradient: c.normal,
            bound: 0.0,
            exact: true,
        }
    }

    /// Which cell holds `p`, and where in it (fractions in `[0, 1]`).
    fn locate(&self, p: &Point3) -> Locate {
        if !p.coords.iter().all(|c| c.is_finite()) {
            return Locate::NotFinite;
        }
        let [_, ny, nz] = self.dims;
        let mut ijk = [0usize; 3];
        let mut t = [0.0; 3];
        for k in 0..3 {
            let f = (p[k] - self.origin[k]) / self.resolution;
            let last = (self.dims[k] - 1) as Real;
            if !(0.0..=last).contains(&f) {
                return Locate::Outside;
            }
            let i = (f.floor() as usize).min(self.dims[k] - 2);
            ijk[k] = i;
            t[k] = f - i as Real;
        }
        let index = (ijk[0] * (ny - 1) + ijk[1]) * (nz - 1) + ijk[2];
        Locate::Cell(
            Cell {
                index,
                node: (ijk[0] * ny + ijk[1]) * nz + ijk[2],
                strides: [ny * nz, nz, 1],
            },
            t,
        )
    }

    /// The trilinear interpolant, its gradient and the Lipschitz bound; with
    /// `continuous` false, the bound that holds whichever the side.
    fn interpolate(&self, cell: &Cell, t: &[Real; 3], continuous: bool) -> FieldSample {
        let v: [Real; 8] = std::array::from_fn(|c| self.values[cell.corner(c)]);
        let [tx, ty, tz] = *t;
        let (sx, sy, sz) = (1.0 - tx, 1.0 - ty, 1.0 - tz);
        // Corner c has offsets (c >> 2 & 1, c >> 1 & 1, c & 1).
        let x00 = sx * v[0] + tx * v[4];
        let x01 = sx * v[1] + tx * v[5];
        let x10 = sx * v[2] + tx * v[6];
        let x11 = sx * v[3] + tx * v[7];
        let y0 = sy * x00 + ty * x10;
        let y1 = sy * x01 + ty * x11;
        let value = sz * y0 + tz * y1;
        let h = self.resolution;
        let dz = (y1 - y0) / h;
        let dy = (sz * (x10 - x00) + tz * (x11 - x01)) / h;
        let dxf = |a: usize, b: usize| v[b] - v[a];
        let dx =
            (sy * (sz * dxf(0, 4) + tz * dxf(1, 5)) + ty * (sz * dxf(2, 6) + tz * dxf(3, 7))) / h;
        let mut lower = Real::NEG_INFINITY;
        let mut upper = Real::INFINITY;
        let mut reach = Real::INFINITY;
        for (c, &s) in v.iter().enumerate() {
            let r = corner_distance(t, c) * h;
            lower = lower.max(s - r);
            upper = upper.min(s + r);
            reach = reach.min(s.abs() + r);
        }
        let bound = if continuous {
            (value - lower).max(upper - value).max(0.0)
        } else {
            // |s(x)| <= reach whatever its sign.
            reach + value.abs()
        };
        FieldSample {
            distance: value,
            gradient: Vector3::new(dx, dy, dz),
            bound: bound + self.eps,
            exact: false,
        }
    }
}

/// The error for a grid too large.
fn too_many(h: Real, band: Real) -> Error {
    Error::invalid(format!(
        "a distance field at resolution {h} with band {band} would have more than {MAX_NODES} nodes; \
         use a coarser resolution or a smaller band"
    ))
}

/// The distance, in cells, from fractional position `t` to corner `c`.
fn corner_distance(t: &[Real; 3], c: usize) -> Real {
    let off = [(c >> 2) & 1, (c >> 1) & 1, c & 1];
    (0..3)
        .map(|k| (t[k] - off[k] as Real).powi(2))
        .sum::<Real>()
        .sqrt()
}

/// Where a point falls.
enum Locate {
    NotFinite,
    Outside,
    Cell(Cell, [Real; 3]),
}

/// A cell: its index, its lowest node and the node strides.
struct Cell {
    index: usize,
    node: usize,
    strides: [usize; 3],
}

impl Cell {
    /// The node index of corner `c` (offsets `(c >> 2, c >> 1, c) & 1`).
    fn corner(&self, c: usize) -> usize {
        self.node
            + ((c >> 2) & 1) * self.strides[0]
            + ((c >> 1) & 1) * self.strides[1]
            + (c & 1) * self.strides[2]
    }
}

/// The grid's geometry.
#[derive(Debug, Clone, Copy)]
struct Grid {
    origin: Point3,
    h: Real,
    dims: [usize; 3],
}

impl Grid {
    fn node(&self, i: usize, j: usize, k: usize) -> Point3 {
        Point3::new(
            self.origin.x + i as Real * self.h,
            self.origin.y + j as Real * self.h,
            self.origin.z + k as Real * self.h,
        )
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (i * self.dims[1] + j) * self.dims[2] + k
    }

    /// The box of the nodes `lo ..= hi`.
    fn nodes_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Box3 {
        Box3 {
            mins: self.node(lo[0], lo[1], lo[2]).into(),
            maxs: self.node(hi[0], hi[1], hi[2]).into(),
        }
    }
}

/// A triangle that may be nearest to some node of a block: its box and its
/// plane (unit normal shortened by 1e-12, for rounding, and offset; zero for a
/// degenerate triangle), both lower bounds on the distance to it.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    lo: [Real; 3],
    hi: [Real; 3],
    normal: [Real; 3],
    offset: Real,
    id: u32,
}

impl Candidate {
    fn new(id: u32, b: &Box3, corners: &[Point3; 3]) -> Self {
        let [a, bb, c] = corners;
        let n = (bb - a)
            .cross(&(c - a))
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros)
            * (1.0 - 1e-12);
        Self {
            lo: b.mins,
            hi: b.maxs,
            normal: [n.x, n.y, n.z],
            offset: n.dot(&a.coords),
            id,
        }
    }

    /// The squared distance from `p` to the box.
    #[inline]
    fn box_distance2(&self, p: &Point3) -> Real {
        let dx = (self.lo[0] - p.x).max(p.x - self.hi[0]).max(0.0);
        let dy = (self.lo[1] - p.y).max(p.y - self.hi[1]).max(0.0);
        let dz = (self.lo[2] - p.z).max(p.z - self.hi[2]).max(0.0);
        dx * dx + dy * dy + dz * dz
    }

    /// The squared lower bound at `p`: box or plane, the larger.
    #[inline]
    fn lower2(&self, p: &Point3) -> Real {
        let z = self.normal[0] * p.x + self.normal[1] * p.y + self.normal[2] * p.z - self.offset;
        self.box_distance2(p).max(z * z)
    }

    /// The squared distance between the box and box `b`.
    #[inline]
    fn box_box2(&self, b: &Box3) -> Real {
        let mut d2 = 0.0;
        for k in 0..3 {
            let d = (self.lo[k] - b.maxs[k])
                .max(b.mins[k] - self.hi[k])
                .max(0.0);
            d2 += d * d;
        }
        d2
    }
}

/// The candidates of a block.
#[derive(Debug, Default)]
struct Candidates {
    list: Vec<Candidate>,
}

impl Candidates {
    /// The candidates whose boxes are within `sqrt(reach2)` of `b`, into `out`.
    fn filter_into(&self, b: &Box3, reach2: Real, out: &mut Candidates) {
        out.list.clear();
        out.list.extend(
            self.list
                .iter()
                .filter(|c| c.box_box2(b) <= reach2)
                .copied(),
        );
    }

    /// The nearest to `p` of the candidates and `hint`, and its squared
    /// distance: the triangles whose lower bound is below the best so far.
    fn nearest(&self, bvh: &TriangleBvh, p: &Point3, hint: u32) -> (u32, Real) {
        let mut best = bvh.distance2(p, hint);
        let mut arg = hint;
        for c in &self.list {
            if c.lower2(p) < best {
                let d2 = bvh.distance2(p, c.id);
                if d2 < best {
                    best = d2;
                    arg = c.id;
                }
            }
        }
        (arg, best)
    }
}

/// The unsigned distance of every node within `band` of the surface
/// (infinity beyond) and its nearest triangle (leaf order; `NONE` beyond).
fn node_distances(source: &MeshDistance, grid: &Grid, band: Real) -> (Vec<Real>, Vec<u32>) {
    let nb = grid.dims.map(|n| n.div_ceil(SUPER));
    let blocks: Vec<[usize; 3]> = (0..nb[0])
        .flat_map(|a| {
            (0..nb[1]).flat_map(move |b| (0..nb[2]).map(move |c| [a * SUPER, b * SUPER, c * SUPER]))
        })
        .collect();
    let found: Vec<Vec<(usize, Real, u32)>> = blocks
        .par_iter()
        .map_init(<[Candidates; 3]>::default, |lists, &lo| {
            block_distances(source, grid, lo, band, lists)
        })
        .collect();
    let n = grid.dims.iter().product();
    let mut unsigned = vec![Real::INFINITY; n];
    let mut nearest = vec![NONE; n];
    for (at, u, t) in found.into_iter().flatten() {
        unsigned[at] = u;
        nearest[at] = t;
    }
    (unsigned, nearest)
}

/// A box of nodes: its extent, centre and half diagonal.
struct NodeBox {
    lo: [usize; 3],
    hi: [usize; 3],
    bounds: Box3,
    centre: Point3,
    radius: Real,
}

impl NodeBox {
    /// The nodes `lo .. lo + side` (clipped to the grid).
    fn new(grid: &Grid, lo: [usize; 3], side: usize) -> Self {
        let hi: [usize; 3] = std::array::from_fn(|k| (lo[k] + side).min(grid.dims[k]));
        let bounds = grid.nodes_box(lo, hi.map(|x| x - 1));
        Self {
            lo,
            hi,
            centre: bounds.center(),
            radius: 0.5 * bounds.diagonal(),
            bounds,
        }
    }

    /// The boxes of `side` nodes inside this one.
    fn split(&self, grid: &Grid, side: usize) -> impl Iterator<Item = NodeBox> + '_ {
        let g = *grid;
        (self.lo[0]..self.hi[0]).step_by(side).flat_map(move |i| {
            (self.lo[1]..self.hi[1]).step_by(side).flat_map(move |j| {
                // The sides nest (8, 4, 2): a child never passes its parent.
                (self.lo[2]..self.hi[2])
                    .step_by(side)
                    .map(move |k| NodeBox::new(&g, [i, j, k], side))
            })
        })
    }
}

/// The nodes within `band` of the surface among the block of `SUPER^3`
/// nodes from `lo`: `(index, distance, nearest triangle)`.
///
/// Every node `x` of a box whose centre `c` is at most `m` from the surface
/// has its nearest triangle, if within `band`, among the triangles whose box
/// is within `min(band, m + r)` of the box (`r` its half diagonal), since
/// `d(x) <= d(c) + r`. The hierarchy lists them for the block; each block of
/// `BLOCK^3`, then each of `PAIR^3`, keeps those of its parent's list near
/// enough to it; each node takes the nearest of its last list. A box is
/// skipped when a lower bound on its centre's distance (the parent's, less
/// the distance between the centres) exceeds `band + r`.
fn block_distances(
    source: &MeshDistance,
    grid: &Grid,
    lo: [usize; 3],
    band: Real,
    lists: &mut [Candidates; 3],
) -> Vec<(usize, Real, u32)> {
    let bvh = source.bvh();
    let slack = 1e-9 * grid.h;
    let band2 = (band + slack) * (band + slack);
    let mut out = Vec::new();
    let outer = NodeBox::new(grid, lo, SUPER);
    let Some((t_outer, d2)) = bvh.nearest(&outer.centre, Real::INFINITY, None) else {
        return out;
    };
    let m_outer = d2.sqrt();
    if m_outer - outer.radius > band + slack {
        return out;
    }
    let reach_outer = band.min(m_outer + outer.radius) + slack;
    let mut near = Vec::new();
    bvh.near_box(&outer.bounds, reach_outer * reach_outer, &mut near);
    let [l8, l4, l2] = lists;
    l8.list.clear();
    l8.list.extend(
        near.iter()
            .map(|&t| Candidate::new(t, bvh.tri_box(t), &bvh.tris()[t as usize].corners)),
    );
    for block in outer.split(grid, BLOCK) {
        let below = m_outer - (block.centre - outer.centre).norm();
        if below - block.radius > band + slack {
            continue;
        }
        let (t_block, d2) = l8.nearest(bvh, &block.centre, t_outer);
        let m = d2.sqrt();
        // The list holds the centre's nearest triangle when that is within
        // the list's reach: then `m` is exact, else only an upper bound.
        let below = if m <= reach_outer { m } else { below };
        if below - block.radius > band + slack {
            continue;
        }
        let reach = band.min(m + block.radius) + slack;
        l8.filter_into(&block.bounds, reach * reach, l4);
        for pair in block.split(grid, PAIR) {
            let below = below - (pair.centre - block.centre).norm();
            if below - pair.radius > band + slack {
                continue;
            }
            let above = bvh.distance2(&pair.centre, t_block).sqrt();
            let reach = band.min(above + pair.radius) + slack;
            l4.filter_into(&pair.bounds, reach * reach, l2);
            let mut hint = t_block;
            for i in pair.lo[0]..pair.hi[0] {
                for j in pair.lo[1]..pair.hi[1] {
                    for k in pair.lo[2]..pair.hi[2] {
                        let x = grid.node(i, j, k);
                        let (arg, best) = l2.nearest(bvh, &x, hint);
                        hint = arg;
                        if best <= band2 {
                            out.push((grid.index(i, j, k), best.sqrt(), arg));
                        }
                    }
                }
            }
        }
    }
    out
}

/// What is known of the fans' winding number `w_C` over a cell.
#[derive(Debug, Clone, Copy)]
enum Cert {
    /// `w_C` stays in `(m - 1/2, m + 1/2)` and no fan crosses the cell: the
    /// side is `k + m >= 1`, which changes only across the surface.
    Certified(i32),
    /// Not certified, but no fan crosses the cell: `w_C` to first order about
    /// a centre, with a bound on the remainder (index into the list).
    Taylor(u32),
    /// A fan may cross the cell (or its edges come too near).
    Unknown,
}

/// `w_C` about `centre`: `w_C(x) = w + gradient . (x - centre) +- (hessian
/// |x - centre|^2 / 2 + far)`.
#[derive(Debug, Clone, Copy)]
struct Taylor {
    centre: Point3,
    w: Real,
    gradient: Vector3,
    hessian: Real,
    far: Real,
}

impl Taylor {
    /// The side at `x` given the integer winding number `k` there, if the
    /// remainder cannot change it.
    fn inside(&self, x: &Point3, k: i32) -> Option<bool> {
        let dx = x - self.centre;
        let w = Real::from(k) + self.w + self.gradient.dot(&dx);
        let doubt = 0.5 * self.hessian * dx.norm_squared() + self.far;
        ((w - 0.5).abs() > doubt).then_some(w > 0.5)
    }
}

/// Per cell, what is known of `w_C` over it (see [`Cert`]), and the first-order
/// expansions the cells refer to. Certified top-down: a block of `8^3` cells,
/// else its eight blocks of `4^3`, and so on down to single cells; a block
/// with no node within the band is tried once.
fn certificates(source: &MeshDistance, grid: &Grid, unsigned: &[Real]) -> (Vec<Cert>, Vec<Taylor>) {
    let cells = grid.dims.map(|n| n - 1);
    let count: usize = cells.iter().product();
    let caps = source.caps();
    if caps.is_empty() {
        return (vec![Cert::Certified(0); count], Vec::new());
    }
    let nb = cells.map(|n| n.div_ceil(CERTIFY));
    let blocks: Vec<[usize; 3]> = (0..nb[0])
        .flat_map(|a| {
            (0..nb[1])
                .flat_map(move |b| (0..nb[2]).map(move |c| [a * CERTIFY, b * CERTIFY, c * CERTIFY]))
        })
        .collect();
    let found: Vec<Vec<([usize; 3], usize, BoxCert)>> = blocks
        .par_iter()
        .map(|&lo| {
            let mut out = Vec::new();
            let hi: [usize; 3] = std::array::from_fn(|k| (lo[k] + CERTIFY).min(grid.dims[k] - 1));
            let in_band = (lo[0]..=hi[0]).any(|i| {
                (lo[1]..=hi[1])
                    .any(|j| (lo[2]..=hi[2]).any(|k| unsigned[grid.index(i, j, k)].is_finite()))
            });
            let smallest = if in_band { 1 } else { CERTIFY };
            certify_block(caps, grid, lo, CERTIFY, smallest, &mut out);
            out
        })
        .collect();
    let mut certs = vec![Cert::Unknown; count];
    let mut taylors = Vec::new();
    for (lo, size, cert) in found.into_iter().flatten() {
        let cert = match cert {
            BoxCert::Certified(m) => Cert::Certified(m),
            BoxCert::Taylor(t) => {
                taylors.push(t);
                Cert::Taylor((taylors.len() - 1) as u32)
            }
            BoxCert::Unknown => Cert::Unknown,
        };
        for i in lo[0]..(lo[0] + size).min(cells[0]) {
            for j in lo[1]..(lo[1] + size).min(cells[1]) {
                for k in lo[2]..(lo[2] + size).min(cells[2]) {
                    certs[(i * cells[1] + j) * cells[2] + k] = cert;
                }
            }
        }
    }
    (certs, taylors)
}

/// What [`certify`] found over one box.
#[derive(Debug, Clone, Copy)]
enum BoxCert {
    Certified(i32),
    Taylor(Taylor),
    Unknown,
}

/// Certifies the block of `size^3` cells from cell `lo`, or its eight halves
/// while they are larger than `smallest` (a box of `smallest` or fewer cells
/// that fails keeps its expansion).
fn certify_block(
    caps: &[Cap],
    grid: &Grid,
    lo: [usize; 3],
    size: usize,
    smallest: usize,
    out: &mut Vec<([usize; 3], usize, BoxCert)>,
) {
    let hi: [usize; 3] = std::array::from_fn(|k| (lo[k] + size).min(grid.dims[k] - 1));
    let cert = certify(caps, &grid.nodes_box(lo, hi));
    if matches!(cert, BoxCert::Certified(_)) || size <= smallest {
        out.push((lo, size, cert));
        return;
    }
    let half = size / 2;
    for a in [0, half] {
        for b in [0, half] {
            for c in [0, half] {
                let sub = [lo[0] + a, lo[1] + b, lo[2] + c];
                if (0..3).all(|k| sub[k] < grid.dims[k] - 1) {
                    certify_block(caps, grid, sub, half, smallest, out);
                }
            }
        }
    }
}

/// The certificate of one box (see [`certificates`]): `w_C` and its gradient
/// exactly at the box's centre `c`, and over the box (half diagonal `r`)
/// `|w_C(x) - w_C(c) - grad w_C(c) . (x - c)| <= H r^2 / 2`, with `H` the
/// bound on the Hessian from the fans' boundary edges (see
/// [`Cap::derivatives`]), once no fan triangle meets the box. A fan whose
/// ball misses the box by `g` and that can change `w_C` by little there
/// (`|w| <= A / (4 pi g^2)`, area `A`) is only bounded.
fn certify(caps: &[Cap], b: &Box3) -> BoxCert {
    let four_pi = 4.0 * std::f64::consts::PI;
    let c = b.center();
    let r = 0.5 * b.diagonal();
    let mut w = 0.0;
    let mut gradient = Vector3::zeros();
    let mut hessian = 0.0;
    let mut far = 0.0;
    for cap in caps {
        let gap = b.distance2_to_point(&cap.apex).sqrt() - cap.radius;
        if gap > 0.0 {
            let bound = cap.area / (four_pi * gap * gap);
            if bound < 0.02 {
                far += bound;
                continue;
            }
        } else {
            for [p, q] in &cap.edges {
                let (x, _) = closest_on_triangle(&c, p, q, &cap.apex);
                if (x - c).norm() <= r {
                    return BoxCert::Unknown;
                }
            }
        }
        let Some((wc, gc, h)) = cap.derivatives(&c, b) else {
            return BoxCert::Unknown;
        };
        w += wc;
        gradient += gc;
        hessian += h;
    }
    let slack = gradient.norm() * r + 0.5 * hessian * r * r + far;
    let m = w.round();
    if (w - m).abs() + slack < 0.5 {
        BoxCert::Certified(m as i32)
    } else {
        BoxCert::Taylor(Taylor {
            centre: c,
            w,
            gradient,
            hessian,
            far,
        })
    }
}

/// The integer winding number of the surface closed by its fans, counted
/// along each z-line from above, and which lines graze an edge or a corner.
fn line_windings(source: &MeshDistance, grid: &Grid) -> (Vec<i32>, Vec<bool>) {
    let [nx, ny, nz] = grid.dims;
    let h = grid.h;
    let o = grid.origin;
    let mut hits: Vec<(u32, Real, i8)> = Vec::new();
    let mut grazed = vec![false; nx * ny];
    let mut scan = |a: &Point3, b: &Point3, c: &Point3| {
        let lo_x = a.x.min(b.x).min(c.x);
        let hi_x = a.x.max(b.x).max(c.x);
        let lo_y = a.y.min(b.y).min(c.y);
        let hi_y = a.y.max(b.y).max(c.y);
        let i0 = ((lo_x - o.x) / h).ceil().max(0.0) as usize;
        let i1 = (((hi_x - o.x) / h).floor().max(-1.0) + 1.0).min(nx as Real) as usize;
        let j0 = ((lo_y - o.y) / h).ceil().max(0.0) as usize;
        let j1 = (((hi_y - o.y) / h).floor().max(-1.0) + 1.0).min(ny as Real) as usize;
        if i0 >= i1 || j0 >= j1 {
            return;
        }
        let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        let area_scale = ((b.x - a.x) * (c.y - a.y)).abs() + ((b.y - a.y) * (c.x - a.x)).abs();
        let flat = area.abs() <= 1e-12 * area_scale;
        let sign: Real = if area > 0.0 { 1.0 } else { -1.0 };
        for i in i0..i1 {
            let px = o.x + i as Real * h;
            for j in j0..j1 {
                let py = o.y + j as Real * h;
                let e = [edge(a, b, px, py), edge(b, c, px, py), edge(c, a, px, py)];
                if flat {
                    if e.iter().all(|(v, tol)| v.abs() <= *tol) {
                        grazed[i * ny + j] = true;
                    }
                    continue;
                }
                let e = e.map(|(v, tol)| (v * sign, tol));
                if e.iter().any(|(v, tol)| *v < -*tol) {
                    continue;
                }
                if e.iter().all(|(v, tol)| *v > *tol) {
                    let sum = e[0].0 + e[1].0 + e[2].0;
                    let z = (e[1].0 * a.z + e[2].0 * b.z + e[0].0 * c.z) / sum;
                    hits.push(((i * ny + j) as u32, z, sign as i8));
                } else {
                    grazed[i * ny + j] = true;
                }
            }
        }
    };
    for t in source.bvh().tris() {
        let [a, b, c] = &t.corners;
        scan(a, b, c);
    }
    // The surface minus its fans is closed: the fans count reversed.
    for cap in source.caps() {
        for [a, b] in &cap.edges {
            scan(b, a, &cap.apex);
        }
    }
    hits.sort_unstable_by(|x, y| x.0.cmp(&y.0).then(y.1.total_cmp(&x.1)));
    let mut k = vec![0i32; nx * ny * nz];
    for line in hits.chunk_by(|x, y| x.0 == y.0) {
        let l = line[0].0 as usize;
        let mut acc = 0i32;
        let mut next = 0;
        for kz in (0..nz).rev() {
            let z = o.z + kz as Real * h;
            while next < line.len() && line[next].1 > z {
                acc += i32::from(line[next].2);
                next += 1;
            }
            k[l * nz + kz] = acc;
        }
    }
    (k, grazed)
}

/// The edge function of `(a, b)` at `(px, py)` (positive left of the edge)
/// and the rounding tolerance under which its sign is not trusted.
fn edge(a: &Point3, b: &Point3, px: Real, py: Real) -> (Real, Real) {
    let s = (b.x - a.x) * (py - a.y);
    let t = (b.y - a.y) * (px - a.x);
    (s - t, 1e-12 * (s.abs() + t.abs()))
}

/// The nodes' signed distances (the exact query's sign: pseudo-normal or
/// winding number; beyond the band, plus or minus infinity, or NaN where the
/// side is not certified), the sub-brick certificates, and how many nodes
/// needed an exact winding number or containment test for their sign.
fn node_signs(
    source: &MeshDistance,
    grid: &Grid,
    unsigned: &[Real],
    nearest: &[u32],
) -> (Vec<Real>, Vec<Cert>, usize) {
    let (windings, grazed) = line_windings(source, grid);
    let (certs, taylors) = certificates(source, grid, unsigned);
    let [nx, ny, nz] = grid.dims;
    let method = source.sign_method();
    let caps = source.caps();
    let tris = source.bvh().tris();
    let mut values = unsigned.to_vec();
    let fallbacks: usize = values
        .par_chunks_mut(nz)
        .enumerate()
        .map(|(line, column)| {
            let (i, j) = (line / ny, line % ny);
            let mut fallbacks = 0;
            for (kz, value) in column.iter_mut().enumerate() {
                let at = line * nz + kz;
                let x = grid.node(i, j, kz);
                let in_band = nearest[at] != NONE;
                // The cell whose lowest corner is this node (or the last one)
                // holds it.
                let cell = (i.min(nx - 2) * (ny - 1) + j.min(ny - 2)) * (nz - 1) + kz.min(nz - 2);
                let cert = certs[cell];
                // Pseudo-normals forced on an open mesh: the exact query's
                // sign, node by node.
                let pseudo = grazed[line] || !caps.is_empty();
                let inside = if method == SignMethod::PseudoNormal && in_band && pseudo {
                    let [a, b, c] = &tris[nearest[at] as usize].corners;
                    let (q, feature) = closest_on_triangle(&x, a, b, c);
                    source.inside_given(&x, &q, nearest[at], feature)
                } else if grazed[line] {
                    fallbacks += 1;
                    source.contains(&x)
                } else {
                    let k = windings[at];
                    let known = match cert {
                        Cert::Certified(m) => Some(k + m >= 1),
                        Cert::Taylor(t) => taylors[t as usize].inside(&x, k),
                        Cert::Unknown => None,
                    };
                    match known {
                        Some(inside) => inside,
                        None if in_band => {
                            fallbacks += 1;
                            let w = Real::from(k)
                                + caps.iter().map(|c| c.winding_number(&x)).sum::<Real>();
                            w > 0.5
                        }
                        None => {
                            *value = Real::NAN;
                            continue;
                        }
                    }
                };
                if inside {
                    *value = -*value;
                }
            }
            fallbacks
        })
        .sum();
    (values, certs, fallbacks)
}

/// Each cell's state: interpolated (every corner in the band, side
/// certified), sign-agnostic (every corner in the band, side not certified,
/// the surface within a cell diagonal of a corner), beyond (every corner
/// beyond the band on one certified side, and the band wider than the cell's
/// half diagonal: no surface inside), or exact otherwise.
fn cell_states(grid: &Grid, values: &[Real], certs: &[Cert], band: Real) -> Vec<u8> {
    let [nx, ny, nz] = grid.dims;
    let diagonal = 3f64.sqrt() * grid.h;
    let wide = band > 0.5 * diagonal;
    let mut cells = vec![CELL_INTERPOLATED; (nx - 1) * (ny - 1) * (nz - 1)];
    cells
        .par_chunks_mut(nz - 1)
        .enumerate()
        .for_each(|(column, states)| {
            let (i, j) = (column / (ny - 1), column % (ny - 1));
            for (k, state) in states.iter_mut().enumerate() {
                let certified = matches!(certs[column * (nz - 1) + k], Cert::Certified(_));
                let (mut finite, mut inside, mut outside) = (0, 0, 0);
                let mut nearest = Real::INFINITY;
                for c in 0..8 {
                    let v = values[grid.index(i + ((c >> 2) & 1), j + ((c >> 1) & 1), k + (c & 1))];
                    if v.is_finite() {
                        finite += 1;
                        nearest = nearest.min(v.abs());
                    } else if v == Real::NEG_INFINITY {
                        inside += 1;
                    } else if v == Real::INFINITY {
                        outside += 1;
                    }
                }
                *state = if finite == 8 && certified {
                    CELL_INTERPOLATED
                } else if finite == 8 && nearest <= diagonal {
                    CELL_AGNOSTIC
                } else if (inside == 8 || outside == 8) && certified && wide {
                    CELL_BEYOND
                } else {
                    CELL_EXACT
                };
            }
        });
    cells
}
