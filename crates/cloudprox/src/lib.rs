//! # cloudprox
//!
//! Probabilistic proximity and collision queries between *noisy point clouds*,
//! after Pan, Chitta & Manocha, "Proximity Computations between Noisy Point Clouds
//! using Robust Classification".
//!
//! Two clouds A and B are collision-free iff a surface separates them. Every point
//! carries a 3x3 covariance (sensor noise plus discretization error). A robust
//! classifier (a second-order cone program, solved by a specialized primal-dual interior-point method
//! with Clarabel as reference and fallback) finds the separating
//! surface that tolerates that noise; every point then gets the probability of lying
//! on the wrong side of it (a Gaussian cdf), and the pair gets an aggregated
//! probability `P` and a state (free / contact / collision).
//!
//! The pipeline, one module per stage:
//!
//! | stage | module |
//! |---|---|
//! | points, covariances, poses | [`cloud`] |
//! | from a scan file's points to a cloud: sensor noise, filter steps, discretization ([`scan::ScanPipeline`]) | [`scan`] |
//! | noise models, discretization error, robustness radius | [`uncertainty`] |
//! | surface elements: the surfaces the points sample, at the resolution the data supports | [`element`] |
//! | bounding volume hierarchy with noise-inflated pruning | [`bvh`] |
//! | robust separating surface (SOCP) | [`classify`] |
//! | per-point and pair probability, thresholds, state | [`probability`] |
//! | queries (`collide`, `collide_many`, `collide_along`; exact mesh-vs-mesh ground truth) | [`query`] |
//! | triangle meshes, primitives, surface sampling | [`shape`] |
//! | sensor filters: self, shadow, crop box, voxel, outliers | [`filter`] |
//! | files: PLY, PCD, XYZ/CSV, NPY, LAS/LAZ, STL, OBJ, OFF, PointCloud2 | [`io`] |
//! | URDF robots: kinematics, link geometry, robot-vs-cloud queries, motions | [`robot`] |
//!
//! [`sample`] makes synthetic shapes and seeded noise for tests, benchmarks and demos.
//!
//! # Example
//!
//! ```
//! use cloudprox::prelude::*;
//!
//! // Two small square patches 5 cm apart, with 2 mm of isotropic noise.
//! let grid = |z: f64| -> Vec<Point3> {
//!     (0..10).flat_map(|i| (0..10).map(move |j| Point3::new(i as f64 * 0.01, j as f64 * 0.01, z)))
//!         .collect()
//! };
//! let a = PointCloud::from_sigma(grid(0.0), 0.002).unwrap();
//! let b = PointCloud::from_sigma(grid(0.05), 0.002).unwrap();
//! let request = CollisionRequest::default();
//! let result = collide(&Pose::identity(), &a, &Pose::identity(), &b, &request).unwrap();
//! assert_eq!(result.state, CollisionState::Free);
//! assert!(result.probability < 0.01);
//! ```
#![deny(missing_docs)]
#![deny(unused_qualifications)]
#![deny(clippy::unwrap_used, clippy::expect_used)]

pub mod bvh;
pub mod classify;
pub mod cloud;
pub mod element;
pub mod error;
pub mod filter;
pub mod io;
pub mod math;
mod names;
pub mod probability;
pub mod query;
pub mod robot;
pub mod sample;
pub mod scan;
pub mod shape;
pub mod uncertainty;

pub use error::{Error, Result};

pub use math::Real;

/// The names most programs need, in one import.
pub mod prelude {
    pub use crate::classify::{ClassifySettings, Surface};
    pub use crate::cloud::PointCloud;
    pub use crate::error::{Error, Result};
    pub use crate::math::{Matrix3, Point3, Pose, Vector3};
    pub use crate::probability::{Aggregation, CollisionState, Thresholds};
    pub use crate::query::exact::{exact_proximity, ExactProximity, ExactShape};
    pub use crate::query::{
        collide, collide_along, collide_many, collide_mesh_cloud, CollisionRequest,
        CollisionResult, ContactPatch, MeshSampling, PointProbabilities, QueryModel, QueryStats,
    };
    pub use crate::shape::Mesh;
    pub use crate::uncertainty::{
        DepthCamera, DiscretizationSettings, Lidar, NoiseModel, RobustModel, SensorModel,
        StereoCamera, Viewpoint,
    };
}
