//! Proximity queries, one folder per query kind.
//!
//! Naming rule (as in parry): the generic entry of a query kind is a function of
//! the kind's name in `<kind>/<kind>.rs` (`collide`); specialisations for one pair
//! of object types are named `<kind>_<a>_<b>` in sibling files. World poses come
//! first, each before its object: `collide(pose_a, a, pose_b, b, request)`.

pub mod collide;
pub mod distance;
pub mod exact;
pub mod exact_side;

pub use distance::{
    distance, distance_cloud_exact, distance_exact_cloud, DistanceRequest, DistanceResult,
};

pub use collide::{
    collide, collide_along, collide_many, collide_mesh_cloud, facing_pairs, prepare,
    CollisionRequest, CollisionResult, ContactPatch, MeshSampling, MeshSide, PointAggregates,
    PointProbabilities, QueryCounters, QueryModel, QueryStats, ALONG_RUN,
};
