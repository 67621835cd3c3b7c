//! What readers return: [`CloudData`] and [`MeshData`].

use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::shape::Mesh;

/// The names of the six covariance fields cloudprox writes and reads (the upper
/// triangle, row by row), in PLY, PCD and CSV.
pub const COV_FIELDS: [&str; 6] = ["cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"];

/// The upper triangle of a symmetric covariance, in [`COV_FIELDS`] order.
pub(crate) fn cov_to_fields(c: &Matrix3) -> [f64; 6] {
    [
        c[(0, 0)],
        c[(0, 1)],
        c[(0, 2)],
        c[(1, 1)],
        c[(1, 2)],
        c[(2, 2)],
    ]
}

/// The symmetric covariance of its [`COV_FIELDS`] values.
pub(crate) fn cov_from_fields([xx, xy, xz, yy, yz, zz]: [f64; 6]) -> Matrix3 {
    Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}

/// The layout of an organized cloud (a depth image): `width x height` pixels in
/// row-major order, and the pixel of every point that was kept.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// For each kept point, its pixel `row * width + column`.
    pub pixels: Vec<u32>,
}

/// A point cloud as read from (or to be written to) a file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CloudData {
    /// The points with finite coordinates, in file order (metres).
    pub points: Vec<Point3>,
    /// Per-point covariances when the file carries them (fields `cov_xx, cov_xy,
    /// cov_xz, cov_yy, cov_yz, cov_zz`, as cloudprox writes them).
    pub covariances: Option<Vec<Matrix3>>,
    /// Per-point normals when the file carries them (`nx, ny, nz` or `normal_x, ...`).
    pub normals: Option<Vec<Vector3>>,
    /// The sensor's pose in the cloud's frame when the file records it (PCD
    /// `VIEWPOINT`); its translation is the sensor origin of the noise models.
    pub sensor: Option<Pose>,
    /// Whether `sensor` is the PCD format's default viewpoint: the identity
    /// (`VIEWPOINT 0 0 0 1 0 0 0`), written or left out. PCL reads it as the
    /// sensor at the origin looking along +z, as a raw lidar or camera frame
    /// has it; a file written without knowing its viewpoint carries it too.
    pub sensor_is_default: bool,
    /// The organized layout (PCD with `HEIGHT > 1`, organized PointCloud2).
    pub grid: Option<Grid>,
    /// The names of all per-point fields in the file, in file order.
    pub fields: Vec<String>,
    /// How many points were skipped because a coordinate was NaN or infinite.
    pub skipped: usize,
    /// How many points of an organized scan were skipped because they lie at
    /// exactly the sensor origin: the driver's no-return points (a lidar beam
    /// or a depth pixel that measured nothing is written as the origin of the
    /// sensor's frame). Their pixels are left out of [`Grid::pixels`], as the
    /// NaN holes are; an unorganized cloud keeps such points (0 here).
    pub at_origin: usize,
}

impl CloudData {
    /// The no-return points of an organized scan: the points at exactly the
    /// sensor origin ([`CloudData::at_origin`]) and the NaN or infinite ones
    /// ([`CloudData::skipped`]), none of which is in [`CloudData::points`].
    /// 0 for an unorganized cloud, whose non-finite points are only skipped.
    pub fn no_returns(&self) -> usize {
        if self.grid.is_some() {
            self.skipped + self.at_origin
        } else {
            0
        }
    }

    /// Moves the cloud by the rigid `pose`: points `p -> pose * p`, normals
    /// rotated, covariances `R C R^T`, the sensor pose `pose * sensor`
    /// (then no longer the format's default unless `pose` is the identity).
    /// Everything else (grid, fields, counts) is kept.
    pub fn transform(&mut self, pose: &Pose) {
        if *pose == Pose::identity() {
            return;
        }
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let t = pose.translation.vector;
        for p in &mut self.points {
            p.coords = r * p.coords + t;
        }
        if let Some(normals) = self.normals.as_mut() {
            for n in normals {
                *n = r * *n;
            }
        }
        if let Some(covs) = self.covariances.as_mut() {
            for c in covs {
                *c = r * *c * r.transpose();
            }
        }
        if let Some(s) = self.sensor.as_mut() {
            *s = pose * *s;
            self.sensor_is_default = false;
        }
    }

    /// Checks that the normals and covariances, when present, have one entry
    /// per point (what every writer needs).
    ///
    /// # Errors
    /// [`crate::Error::InvalidInput`] naming the count that differs.
    pub fn check_lengths(&self) -> crate::Result<()> {
        let n = self.points.len();
        for (what, len) in [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("covariances", self.covariances.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&len| len != n) {
                return Err(crate::Error::invalid(format!(
                    "cloud has {n} points but {len} {what}"
                )));
            }
        }
        Ok(())
    }

    /// The data of the points where `keep` is `true`, in their order: the
    /// points, their covariances, normals and (organized cloud) pixels stay
    /// aligned; the grid keeps its `width x height`, the sensor pose, field
    /// names and `skipped` count are kept as they are.
    ///
    /// # Errors
    /// [`crate::Error::Shape`] if `keep` does not have one entry per point, or
    /// if the normals, covariances or grid pixels do not (naming which).
    pub fn select(&self, keep: &[bool]) -> crate::Result<Self> {
        if keep.len() != self.points.len() {
            return Err(crate::Error::Shape {
                what: "CloudData::select: keep mask (one entry per point)".into(),
                expected: self.points.len(),
                got: keep.len(),
            });
        }
        let indices: Vec<usize> = keep
            .iter()
            .enumerate()
            .filter_map(|(i, &k)| k.then_some(i))
            .collect();
        self.gather(&indices)
    }

    /// The data of the points at `indices` (strictly ascending, as the
    /// [`crate::filter`] functions return them), everything kept aligned as in
    /// [`CloudData::select`].
    ///
    /// # Errors
    /// [`crate::Error::InvalidInput`] if an index is out of range or the
    /// indices are not strictly ascending; [`crate::Error::Shape`] as
    /// [`CloudData::select`].
    pub fn select_indices(&self, indices: &[u32]) -> crate::Result<Self> {
        let n = self.points.len();
        let mut out = Vec::with_capacity(indices.len());
        for (pos, &i) in indices.iter().enumerate() {
            let i = i as usize;
            if i >= n {
                return Err(crate::Error::invalid(format!(
                    "CloudData::select_indices: index {i} (at {pos}) is out of range for {n} points"
                )));
            }
            if out.last().is_some_and(|&last| last >= i) {
                return Err(crate::Error::invalid(format!(
                    "CloudData::select_indices: indices must be strictly ascending; index {i} \
                     (at {pos}) follows {}",
                    out[out.len() - 1]
                )));
            }
            out.push(i);
        }
        self.gather(&out)
    }

    /// Checks that everything per point has one entry per point, including the
    /// grid's pixels (`what` names the caller in the error).
    pub(crate) fn check_aligned(&self, what: &str) -> crate::Result<()> {
        let n = self.points.len();
        for (field, len) in [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("covariances", self.covariances.as_ref().map(Vec::len)),
            ("grid pixels", self.grid.as_ref().map(|g| g.pixels.len())),
        ] {
            if let Some(len) = len.filter(|&len| len != n) {
                return Err(crate::Error::Shape {
                    what: format!("{what}: {field} (one per point)"),
                    expected: n,
                    got: len,
                });
            }
        }
        Ok(())
    }

    /// The points at `indices` (valid, ascending) with everything aligned.
    fn gather(&self, indices: &[usize]) -> crate::Result<Self> {
        fn pick<T: Copy>(all: &[T], indices: &[usize]) -> Vec<T> {
            indices.iter().map(|&i| all[i]).collect()
        }
        self.check_aligned("CloudData::select")?;
        Ok(Self {
            points: pick(&self.points, indices),
            covariances: self.covariances.as_deref().map(|c| pick(c, indices)),
            normals: self.normals.as_deref().map(|c| pick(c, indices)),
            sensor: self.sensor,
            sensor_is_default: self.sensor_is_default,
            grid: self.grid.as_ref().map(|g| Grid {
                width: g.width,
                height: g.height,
                pixels: pick(&g.pixels, indices),
            }),
            fields: self.fields.clone(),
            skipped: self.skipped,
            at_origin: self.at_origin,
        })
    }

    /// Data holding just these points (no covariances, normals, sensor or grid).
    pub fn from_points(points: Vec<Point3>) -> Self {
        Self {
            points,
            fields: vec!["x".into(), "y".into(), "z".into()],
            ..Self::default()
        }
    }
}

/// Collects points while a reader walks a file: skips (and counts) points with a
/// non-finite coordinate, and records pixels for organized clouds.
#[derive(Debug, Default)]
pub struct CloudDataBuilder {
    data: CloudData,
    pixels: Vec<u32>,
    organized: Option<(usize, usize)>,
    no_return_origin: Option<Point3>,
    with_normals: bool,
    with_covariances: bool,
}

impl CloudDataBuilder {
    /// A builder for a cloud with these field names; `organized` is `(width,
    /// height)` of an organized cloud. `normals`/`covariances` say whether
    /// [`CloudDataBuilder::push`] will be given them.
    pub fn new(
        fields: Vec<String>,
        organized: Option<(usize, usize)>,
        normals: bool,
        covariances: bool,
        capacity: usize,
    ) -> Self {
        let data = CloudData {
            points: Vec::with_capacity(capacity),
            normals: normals.then(|| Vec::with_capacity(capacity)),
            covariances: covariances.then(|| Vec::with_capacity(capacity)),
            fields,
            ..CloudData::default()
        };
        Self {
            data,
            pixels: Vec::new(),
            organized,
            no_return_origin: None,
            with_normals: normals,
            with_covariances: covariances,
        }
    }

    /// Sets where the sensor sat in the cloud's frame, for an organized
    /// cloud: the points at exactly that position are no-returns, counted in
    /// [`CloudData::at_origin`] and not kept. Ignored for an unorganized cloud.
    pub fn set_no_return_origin(&mut self, origin: Option<Point3>) {
        self.no_return_origin = origin.filter(|_| self.organized.is_some());
    }

    /// Adds the point read at position `index` of the file (its pixel, for an
    /// organized cloud). A point with a non-finite coordinate is counted in
    /// `skipped` and not kept; in an organized cloud, a point at exactly the
    /// no-return origin ([`CloudDataBuilder::set_no_return_origin`]) is
    /// counted in `at_origin` and not kept. Normals and covariances must be
    /// given iff the builder was made for them.
    #[inline]
    pub fn push(
        &mut self,
        index: usize,
        point: Point3,
        normal: Option<Vector3>,
        covariance: Option<Matrix3>,
    ) {
        if !point.coords.iter().all(|c| c.is_finite()) {
            self.data.skipped += 1;
            return;
        }
        if self.no_return_origin == Some(point) {
            self.data.at_origin += 1;
            return;
        }
        self.data.points.push(point);
        if self.with_normals {
            if let Some(n) = self.data.normals.as_mut() {
                n.push(normal.unwrap_or_else(Vector3::zeros));
            }
        }
        if self.with_covariances {
            if let Some(c) = self.data.covariances.as_mut() {
                c.push(covariance.unwrap_or_else(Matrix3::zeros));
            }
        }
        if self.organized.is_some() {
            self.pixels.push(index as u32);
        }
    }

    /// Sets whether the sensor pose is the format's default viewpoint.
    pub fn set_sensor_is_default(&mut self, default: bool) {
        self.data.sensor_is_default = default;
    }

    /// Sets the sensor pose (PCD `VIEWPOINT`).
    pub fn set_sensor(&mut self, sensor: Option<Pose>) {
        self.data.sensor = sensor;
    }

    /// The finished data.
    pub fn finish(mut self) -> CloudData {
        if let Some((width, height)) = self.organized {
            self.data.grid = Some(Grid {
                width,
                height,
                pixels: self.pixels,
            });
        }
        self.data
    }
}

/// A triangle mesh as read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshData {
    /// The mesh (polygons fan-triangulated, STL vertices welded).
    pub mesh: Mesh,
    /// Faces dropped because they repeat a vertex (zero area by construction),
    /// after triangulation. Never dropped silently: reported here.
    pub dropped_faces: usize,
}
