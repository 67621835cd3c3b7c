//! Link collision geometry: URDF primitives as meshes, mesh files, the
//! signed distance or the cloud that stands for a link in a query, and the
//! exact shape for self-collision.

use std::sync::{Arc, OnceLock};

use crate::bvh::Aabb;
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Point3;
use crate::query::exact::ExactShape;
use crate::shape::{DistanceField, Mesh, MeshDistance};
use crate::Real;

/// Segments around the axis of URDF cylinders, spheres and capsules (the
/// polygon's chord error is `r (1 - cos(pi / 32))`, 0.5% of the radius).
pub const CIRCLE_SEGMENTS: usize = 32;
/// Rings from pole to equator of URDF spheres and capsule caps.
const CAP_RINGS: usize = 8;

/// A closed, outward-oriented surface of revolution about z from a profile of
/// `(radius, z)` points running from the bottom pole to the top pole (both
/// poles with radius 0, the points between with radius > 0).
fn lathe(profile: &[(Real, Real)], segments: usize) -> Result<Mesh> {
    let rings = &profile[1..profile.len() - 1];
    let n = segments as u32;
    let mut vertices = Vec::with_capacity(rings.len() * segments + 2);
    for &(r, z) in rings {
        for k in 0..segments {
            let t = 2.0 * std::f64::consts::PI * k as Real / segments as Real;
            vertices.push(Point3::new(r * t.cos(), r * t.sin(), z));
        }
    }
    let bottom = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, profile[0].1));
    let top = bottom + 1;
    vertices.push(Point3::new(0.0, 0.0, profile[profile.len() - 1].1));
    let mut faces = Vec::new();
    let last = (rings.len() - 1) as u32;
    for k in 0..n {
        let k1 = (k + 1) % n;
        faces.push([bottom, k1, k]);
        faces.push([top, last * n + k, last * n + k1]);
        for ring in 0..last {
            let (a, b) = (ring * n, (ring + 1) * n);
            faces.push([a + k, a + k1, b + k1]);
            faces.push([a + k, b + k1, b + k]);
        }
    }
    Mesh::new(vertices, faces)
}

fn positive(what: &str, v: Real) -> Result<Real> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(format!(
            "{what} must be finite and > 0, got {v}"
        )))
    }
}

/// A sphere of `radius` centred at the origin: a closed convex mesh with
/// [`CIRCLE_SEGMENTS`] segments and its vertices on the sphere.
///
/// # Errors
/// [`Error::InvalidInput`] if `radius` is not finite and positive.
pub fn sphere_mesh(radius: Real) -> Result<Mesh> {
    capsule_mesh(radius, 0.0)
}

/// A capsule along z centred at the origin: a cylinder of `radius` and
/// `length` (0 for a sphere) between two hemispheres, as a closed convex mesh.
///
/// # Errors
/// [`Error::InvalidInput`] if `radius` is not finite and positive or `length`
/// not finite and non-negative.
pub fn capsule_mesh(radius: Real, length: Real) -> Result<Mesh> {
    let r = positive("radius", radius)?;
    if !(length.is_finite() && length >= 0.0) {
        return Err(Error::invalid(format!(
            "capsule length must be finite and >= 0, got {length}"
        )));
    }
    let h = 0.5 * length;
    let mut profile = Vec::with_capacity(2 * CAP_RINGS + 2);
    let half_pi = std::f64::consts::FRAC_PI_2;
    // Bottom cap, pole to equator.
    for i in 0..=CAP_RINGS {
        let phi = -half_pi + half_pi * i as Real / CAP_RINGS as Real;
        profile.push((r * phi.cos(), -h + r * phi.sin()));
    }
    // Top cap, equator to pole (the equator repeated only when the cylinder has length).
    let start = usize::from(h == 0.0);
    for i in start..=CAP_RINGS {
        let phi = half_pi * i as Real / CAP_RINGS as Real;
        profile.push((r * phi.cos(), h + r * phi.sin()));
    }
    profile[0].0 = 0.0;
    let n = profile.len();
    profile[n - 1].0 = 0.0;
    lathe(&profile, CIRCLE_SEGMENTS)
}

/// A link's collision geometry in the link frame.
#[derive(Debug, Clone)]
pub struct LinkGeometry {
    /// One mesh per `<collision>` element, in the link frame (origin and scale applied).
    pub parts: Vec<Mesh>,
    /// The parts merged into one mesh (sampled for queries; the self-filter's mesh).
    pub mesh: Mesh,
    /// The parts prepared for exact queries (self-collision).
    pub exact: ExactShape,
    /// The signed distance of the merged mesh: the link's surface in a query
    /// with an exact mesh side (built once, when the robot is loaded; shared by
    /// the clones).
    pub distance: Arc<MeshDistance>,
    /// Bounding box of the parts in the link frame.
    pub aabb: Aabb,
    /// Largest distance of a vertex from the link frame's origin.
    pub radius: Real,
    /// The distance field of `distance`, built on the first query that
    /// reads it ([`LinkGeometry::field`]; shared by the clones).
    field: Arc<OnceLock<Option<DistanceField>>>,
}

/// The cells of a link's distance field across its bounding box's diagonal.
const FIELD_CELLS: Real = 48.0;
/// The finest and coarsest cell of a link's distance field (metres).
const FIELD_CELL_RANGE: (Real, Real) = (0.002, 0.01);
/// A link's distance field is exact within this many cells of its surface.
const FIELD_BAND_CELLS: Real = 6.0;

impl LinkGeometry {
    /// Prepares the parts of one link (`link` names it in errors).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the link if parry rejects a part or
    /// every face of the parts is degenerate.
    pub fn new(link: &str, parts: Vec<Mesh>) -> Result<Self> {
        Self::labelled(&format!("link '{link}'"), parts)
    }

    /// [`LinkGeometry::new`] of a body that `label` names in errors (a link,
    /// or an attached object).
    pub(crate) fn labelled(label: &str, parts: Vec<Mesh>) -> Result<Self> {
        let named = |e: Error| Error::invalid(format!("{label}: {e}"));
        let mesh = Mesh::merged(&parts)?;
        let exact = ExactShape::new(&parts).map_err(named)?;
        let distance = Arc::new(MeshDistance::new(&mesh).map_err(named)?);
        let aabb = mesh.aabb();
        let radius = mesh
            .vertices()
            .iter()
            .map(|v| v.coords.norm())
            .fold(0.0, Real::max);
        Ok(Self {
            parts,
            mesh,
            exact,
            distance,
            aabb,
            radius,
            field: Arc::new(OnceLock::new()),
        })
    }

    /// Whether [`LinkGeometry::field`] has been asked for (built, or found
    /// impossible to build).
    pub(crate) fn has_field(&self) -> bool {
        self.field.get().is_some()
    }

    /// The link's distance field, built on first use: cells of a 48th of
    /// the bounding box's diagonal (from 2 mm to 1 cm), exact within six
    /// cells of the surface. Its bounds let the exact-side query pass over elements and
    /// points that the noise cannot bring to the surface, or that lie deep
    /// inside, without a closest-point search. `None` where it cannot be
    /// built (a grid too large): the queries search as without one.
    pub fn field(&self) -> Option<&DistanceField> {
        self.field
            .get_or_init(|| {
                let diagonal = (self.aabb.maxs - self.aabb.mins).norm();
                let (fine, coarse) = FIELD_CELL_RANGE;
                let cell = (diagonal / FIELD_CELLS).clamp(fine, coarse);
                DistanceField::new(Arc::clone(&self.distance), cell, FIELD_BAND_CELLS * cell).ok()
            })
            .as_ref()
    }
}

/// Seed of every link's sampling: the seed [`crate::query::collide_mesh_cloud`]
/// and the Python `collide` use for a mesh, so a link's query equals theirs.
pub const LINK_SAMPLING_SEED: u64 = 0;

/// The clouds that stand for the links in a query, sampled at one spacing.
#[derive(Debug)]
pub(crate) struct LinkSamples {
    /// Per link (in link order): its cloud in the link frame, `None` without geometry.
    pub clouds: Vec<Option<PointCloud>>,
    /// Per link: the largest sampling spacing of its cloud (for the broad phase).
    pub spacing_max: Vec<Real>,
    /// Per attached object (in [`super::Robot::attached_objects`] order): the
    /// sample of a mesh object in its own frame, and its largest spacing;
    /// `None` for a cloud object (its own cloud stands for it).
    pub attached: Vec<Option<(PointCloud, Real)>>,
}

/// The cloud sampled from `g`'s merged mesh at `spacing` (`what` names it in
/// errors), its hierarchy built, and its largest sampling spacing.
fn sample_geometry(g: &LinkGeometry, spacing: Real, what: &str) -> Result<(PointCloud, Real)> {
    sample_padded(g, spacing, 0.0, what)
}

/// [`sample_geometry`] with the samples moved `padding` metres along their
/// faces' outward normals (see [`PointCloud::from_mesh_offset`]).
pub(crate) fn sample_padded(
    g: &LinkGeometry,
    spacing: Real,
    padding: Real,
    what: &str,
) -> Result<(PointCloud, Real)> {
    let cloud = PointCloud::from_mesh_offset(&g.mesh, spacing, LINK_SAMPLING_SEED, padding)
        .map_err(|e| Error::invalid(format!("{what}: {e}")))?;
    let _ = cloud.bvh();
    let spacing_max = cloud.spacing().iter().copied().fold(0.0, Real::max);
    Ok((cloud, spacing_max))
}

impl LinkSamples {
    pub(crate) fn new(robot: &super::Robot, spacing: Real) -> Result<Self> {
        let links = &robot.links;
        let mut clouds = Vec::with_capacity(links.len());
        let mut spacing_max = Vec::with_capacity(links.len());
        for link in links {
            if let Some(g) = &link.geometry {
                let (cloud, h) = sample_geometry(g, spacing, &format!("link '{}'", link.name))?;
                spacing_max.push(h);
                clouds.push(Some(cloud));
            } else {
                clouds.push(None);
                spacing_max.push(0.0);
            }
        }
        let attached = robot
            .attached
            .iter()
            .map(|o| match o.cloud {
                Some(_) => Ok(None),
                None => sample_geometry(
                    &o.geometry,
                    spacing,
                    &format!("attached object '{}'", o.name),
                )
                .map(Some),
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            clouds,
            spacing_max,
            attached,
        })
    }
}

/// Cached samples of every link (and attached mesh object) at `spacing`,
/// sampled on first use.
pub(crate) fn samples_at(robot: &super::Robot, spacing: Real) -> Result<Arc<LinkSamples>> {
    robot
        .samples
        .get_or_build(spacing, || LinkSamples::new(robot, spacing))
}
