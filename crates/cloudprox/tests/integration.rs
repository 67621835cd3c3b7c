//! The core crate's integration tests, one module per file of this folder,
//! compiled into one test binary: one link instead of thirty, and the crate's
//! generic code instantiated once (`cargo test --test integration`; a module's
//! tests alone: `cargo test --test integration collide_elements::`).
//!
//! Two tests stay binaries of their own (`Cargo.toml`'s `[[test]]` list):
//! `fuzz_smoke` and `io_las_quiet_panic`, which installs a process-wide panic
//! hook.

mod common;
mod robot_common;

mod api_bad_input;
mod classify_socp;
mod collide_cloud_cloud;
mod collide_elements;
mod collide_hierarchy_brute_force;
mod collide_mesh_cloud;
mod collide_segmentations;
mod determinism;
mod distance;
mod exact_side;
mod exact_time_of_impact;
mod filter_bad_input;
mod filter_crop_box;
mod filter_outlier;
mod filter_self;
mod filter_shadow;
mod filter_voxel;
mod fuzz_regressions;
mod io_las;
mod io_npy;
mod io_obj;
mod io_off;
mod io_pcd;
mod io_ply;
mod io_pointcloud2;
mod io_stl;
mod io_xyz;
mod module_layers;
mod robot_collide;
mod robot_exact;
mod robot_grasp;
mod robot_model;
mod robot_shadow;
mod scan_pipeline;
mod shape_exact;
mod shape_signed_distance;
mod surface_elements;
mod uncertainty_discretization;
mod uncertainty_sensor;
