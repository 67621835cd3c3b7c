//! What a scan did not see: the space behind its observed surfaces along the
//! sensor's viewing rays ([`Occlusion`]).
//!
//! A single view observes the first surface along each ray from the sensor.
//! Space in front of it is seen to be free; space behind it is unknown, not
//! free: a collision there leaves no point in the scan. [`Occlusion`] keeps
//! the nearest return per direction (a cube map of the rays, cells of the
//! scan's own angular spacing) and tells, for any point, whether it lies in
//! front of the observed surface, behind it (with the probability, under the
//! range noise, that it does), or along a direction the scan holds no return
//! for.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Vector3};
use crate::probability::normal_cdf;
use crate::Real;

/// Where a point lies as the scan saw it ([`Occlusion::visibility`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Visibility {
    /// In front of the observed surface along its ray: seen to be free.
    Seen,
    /// Behind the observed surface (more likely than not): in its shadow.
    Hidden,
    /// Along a direction with no return near it (outside the field of view,
    /// beyond the sensor's range, or no-return pixels).
    Unobserved,
}

/// How many cells of the scan's own angular spacing one cube-map cell spans.
const CELL_SPACINGS: Real = 2.0;

/// The nearest return of one cell: its range and that range's standard
/// deviation along the ray.
#[derive(Debug, Clone, Copy)]
struct Return {
    range: Real,
    std: Real,
}

/// The nearest return per viewing direction of one scan, from its sensor's
/// origin.
///
/// A single view observes the first surface along each ray from the sensor.
/// Space in front of it is seen to be free; space behind it is unknown, not
/// free: a collision there leaves no point in the scan. The returns are kept
/// per cell of a cube map of the rays (cells of the scan's own angular
/// spacing); a point is read against the nearest return of its cell
/// ([`Occlusion::visibility`],
/// [`Occlusion::hidden_probability`]).
#[derive(Debug, Clone)]
pub struct Occlusion {
    origin: Point3,
    cell: Real,
    cells: HashMap<(u8, i32, i32), Return>,
    median_range: Real,
}

/// The cube-map face and its coordinates `(a / |k|, b / |k|)` of direction `d`
/// (`k` its largest component): gnomonic, without poles.
fn face(d: &Vector3) -> (u8, Real, Real) {
    let (x, y, z) = (d.x, d.y, d.z);
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    if ax >= ay && ax >= az {
        (u8::from(x < 0.0), y / ax, z / ax)
    } else if ay >= az {
        (2 + u8::from(y < 0.0), x / ay, z / ay)
    } else {
        (4 + u8::from(z < 0.0), x / az, y / az)
    }
}

impl Occlusion {
    /// The scan `points` (world frame) seen from `origin`, with their
    /// covariances `covariances` (the range noise is read along each ray;
    /// `None`: exact ranges) and the angular cell `cell` in radians (`None`:
    /// twice the scan's median angular spacing, from `spacing`, each point's
    /// sampling spacing in metres).
    ///
    /// # Errors
    /// An empty scan, a non-finite point or origin, a point at the origin, a
    /// covariance count that is not the points', or a cell (given or
    /// measured) that is not positive and finite.
    pub fn new(
        points: &[Point3],
        covariances: Option<&[Matrix3]>,
        spacing: &[Real],
        origin: Point3,
        cell: Option<Real>,
    ) -> Result<Self> {
        validate(points, covariances, spacing, &origin)?;
        let cell = match cell {
            Some(c) => c,
            None => CELL_SPACINGS * median_angle(points, spacing, &origin),
        };
        if !(cell.is_finite() && cell > 0.0) {
            return Err(Error::invalid(format!(
                "occlusion: the angular cell must be positive and finite, got {cell}"
            )));
        }
        let mut cells: HashMap<(u8, i32, i32), Return> = HashMap::new();
        for (i, p) in points.iter().enumerate() {
            let d = p - origin;
            let range = d.norm();
            let dir = d / range;
            let std = covariances.map_or(0.0, |c| (dir.dot(&(c[i] * dir))).max(0.0).sqrt());
            let key = Self::key(cell, &dir);
            let here = Return { range, std };
            cells
                .entry(key)
                .and_modify(|r| {
                    if range < r.range {
                        *r = here;
                    }
                })
                .or_insert(here);
        }
        let mut ranges: Vec<Real> = points.iter().map(|p| (p - origin).norm()).collect();
        let k = ranges.len() / 2;
        let median_range = *ranges.select_nth_unstable_by(k, Real::total_cmp).1;
        Ok(Self {
            origin,
            cell,
            cells,
            median_range,
        })
    }

    /// A cell's footprint at the scan's median range (metres): the spacing
    /// at which a surface's samples each meet a cell of their own.
    pub fn footprint(&self) -> Real {
        self.cell * self.median_range
    }

    /// The cell of unit direction `dir`.
    fn key(cell: Real, dir: &Vector3) -> (u8, i32, i32) {
        let (f, a, b) = face(dir);
        (f, (a / cell).floor() as i32, (b / cell).floor() as i32)
    }

    /// The angular cell in radians.
    pub fn cell(&self) -> Real {
        self.cell
    }

    /// The nearest return of the cell of `x`, or `None` without one; and
    /// `x`'s range. The cell alone, not its neighbours: the nearest return
    /// of a neighbourhood puts a point beside an object's silhouette, with
    /// the background seen behind it, in the object's shadow (on the robot
    /// bench, a third of the free configurations near the scene instead of a
    /// tenth, within 5 cm behind the surfaces).
    fn nearest(&self, x: &Point3) -> (Option<Return>, Real) {
        let d = x - self.origin;
        let range = d.norm();
        if range == 0.0 {
            return (None, 0.0);
        }
        let key = Self::key(self.cell, &(d / range));
        (self.cells.get(&key).copied(), range)
    }

    /// The probability that `x` lies behind the observed surface along its
    /// ray: `Phi((|x - o| - r) / s)` with `r` the nearest return of its
    /// direction's cell and `s` that range's standard deviation (a step for exact
    /// ranges); 0 along a direction without a return (see
    /// [`Occlusion::visibility`] for those).
    pub fn hidden_probability(&self, x: &Point3) -> Real {
        self.hidden_within(x, Real::INFINITY)
    }

    /// The probability that `x` lies behind the observed surface along its
    /// ray by at most `depth` (metres): inside an object seen from the front
    /// whose thickness is at most `depth`, rather than anywhere in the
    /// shadow. `Phi((d - r) / s) - Phi((d - r - depth) / s)` with `d = |x - o|`
    /// ([`Occlusion::hidden_probability`] is `depth` infinite); 0 along a
    /// direction without a return.
    pub fn hidden_within(&self, x: &Point3, depth: Real) -> Real {
        let behind = |t: Real, r: &Return| {
            if r.std > 0.0 {
                normal_cdf(t / r.std)
            } else {
                Real::from(u8::from(t > 0.0))
            }
        };
        match self.nearest(x) {
            (Some(r), range) => {
                let far = if depth.is_finite() {
                    behind(range - r.range - depth, &r)
                } else {
                    0.0
                };
                (behind(range - r.range, &r) - far).max(0.0)
            }
            (None, _) => 0.0,
        }
    }

    /// Where `x` lies as the scan saw it ([`Visibility`]): hidden where its
    /// range exceeds the return's (its hidden probability above 1/2).
    pub fn visibility(&self, x: &Point3) -> Visibility {
        match self.nearest(x) {
            (None, _) => Visibility::Unobserved,
            (Some(r), range) if range > r.range => Visibility::Hidden,
            _ => Visibility::Seen,
        }
    }
}

/// The checks of [`Occlusion::new`].
fn validate(
    points: &[Point3],
    covariances: Option<&[Matrix3]>,
    spacing: &[Real],
    origin: &Point3,
) -> Result<()> {
    if points.is_empty() {
        return Err(Error::invalid("occlusion: the scan has no points"));
    }
    if !origin.coords.iter().all(|v| v.is_finite()) {
        return Err(Error::invalid(format!(
            "occlusion: the sensor origin must be finite, got {origin}"
        )));
    }
    if let Some(c) = covariances {
        if c.len() != points.len() {
            return Err(Error::invalid(format!(
                "occlusion: {} covariances for {} points",
                c.len(),
                points.len()
            )));
        }
    }
    if spacing.len() != points.len() {
        return Err(Error::invalid(format!(
            "occlusion: {} spacings for {} points",
            spacing.len(),
            points.len()
        )));
    }
    for (i, p) in points.iter().enumerate() {
        if !p.coords.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(format!(
                "occlusion: point {i} is not finite"
            )));
        }
        if p == origin {
            return Err(Error::invalid(format!(
                "occlusion: point {i} lies at the sensor origin (a no-return point: \
                 leave it out)"
            )));
        }
    }
    Ok(())
}

/// The median over the points of their spacing divided by their range: the
/// scan's angular spacing in radians.
fn median_angle(points: &[Point3], spacing: &[Real], origin: &Point3) -> Real {
    let mut a: Vec<Real> = points
        .iter()
        .zip(spacing)
        .map(|(p, s)| s / (p - origin).norm())
        .filter(|v| v.is_finite())
        .collect();
    if a.is_empty() {
        return Real::NAN;
    }
    let k = a.len() / 2;
    *a.select_nth_unstable_by(k, Real::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall at x = 1 m (y, z in [-0.5, 0.5], 1 cm grid) seen from the origin.
    fn wall() -> (Vec<Point3>, Vec<Real>) {
        let n = 101;
        let pts: Vec<Point3> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as Real, (k / n) as Real);
                Point3::new(1.0, -0.5 + 0.01 * i, -0.5 + 0.01 * j)
            })
            .collect();
        let spacing = vec![0.01; pts.len()];
        (pts, spacing)
    }

    #[test]
    fn behind_the_wall_is_hidden_in_front_is_seen_beside_is_unobserved() {
        let (pts, spacing) = wall();
        let sigma = 0.002;
        let cov = vec![Matrix3::identity() * (sigma * sigma); pts.len()];
        let o = Occlusion::new(&pts, Some(&cov), &spacing, Point3::origin(), None).unwrap();
        assert!((o.cell() - 0.02).abs() < 2e-3, "cell {}", o.cell());
        for (x, want) in [
            (Point3::new(1.2, 0.1, 0.0), Visibility::Hidden),
            (Point3::new(0.8, 0.1, 0.0), Visibility::Seen),
            (Point3::new(1.0, 3.0, 0.0), Visibility::Unobserved),
            (Point3::new(-1.0, 0.0, 0.0), Visibility::Unobserved),
        ] {
            assert_eq!(o.visibility(&x), want, "{x}");
        }
        // The range noise: 1 sigma behind the wall along its ray.
        let x = Point3::new(1.0 + sigma, 0.0, 0.0);
        let p = o.hidden_probability(&x);
        assert!((p - normal_cdf(1.0)).abs() < 0.02, "P {p}");
        assert!(o.hidden_probability(&Point3::new(0.9, 0.0, 0.0)) < 1e-12);
        // Within a 5 cm thickness: 3 cm behind is in it, 10 cm is not.
        assert!(o.hidden_within(&Point3::new(1.03, 0.0, 0.0), 0.05) > 0.999);
        assert!(o.hidden_within(&Point3::new(1.10, 0.0, 0.0), 0.05) < 1e-9);
        assert!(o.hidden_within(&Point3::new(0.90, 0.0, 0.0), 0.05) < 1e-9);
        let x = Point3::new(1.07, 0.01, 0.0);
        assert_eq!(
            o.hidden_within(&x, Real::INFINITY),
            o.hidden_probability(&x)
        );
    }

    #[test]
    fn a_rigid_motion_of_scan_origin_and_point_changes_nothing() {
        let (pts, spacing) = wall();
        let t = crate::math::Pose::new(Vector3::new(0.3, -2.0, 1.0), Vector3::new(0.2, 0.9, -0.4));
        let moved: Vec<Point3> = pts.iter().map(|p| t * p).collect();
        let a = Occlusion::new(&pts, None, &spacing, Point3::origin(), Some(0.02)).unwrap();
        let b = Occlusion::new(&moved, None, &spacing, t * Point3::origin(), Some(0.02)).unwrap();
        for x in [
            Point3::new(1.3, 0.05, 0.02),
            Point3::new(0.7, -0.2, 0.1),
            Point3::new(1.0, 2.0, 0.0),
        ] {
            assert_eq!(a.visibility(&x), b.visibility(&(t * x)), "{x}");
        }
    }

    #[test]
    fn bad_input_is_named() {
        let (pts, spacing) = wall();
        let err = |r: Result<Occlusion>| r.unwrap_err().to_string();
        assert!(err(Occlusion::new(&[], None, &[], Point3::origin(), None)).contains("no points"));
        let mut at_origin = pts.clone();
        at_origin[3] = Point3::origin();
        assert!(err(Occlusion::new(
            &at_origin,
            None,
            &spacing,
            Point3::origin(),
            None
        ))
        .contains("point 3"));
        let nan = Point3::new(Real::NAN, 0.0, 0.0);
        assert!(err(Occlusion::new(&pts, None, &spacing, nan, None)).contains("origin"));
        assert!(err(Occlusion::new(
            &pts,
            None,
            &spacing,
            Point3::origin(),
            Some(0.0)
        ))
        .contains("cell"));
        assert!(err(Occlusion::new(
            &pts,
            None,
            &spacing[1..],
            Point3::origin(),
            None
        ))
        .contains("spacings"));
    }
}
