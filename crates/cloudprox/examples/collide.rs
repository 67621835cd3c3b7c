//! The collide query in a dozen lines: a noisy ball resting on a noisy plate.
//!
//! `cargo run --release --example collide`

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, box_surface, sphere};

fn main() -> Result<()> {
    let sigma = 0.002; // 2 mm of sensor noise
    let plate = box_surface(&Point3::origin(), &Vector3::new(0.2, 0.2, 0.01), 0.008);
    let ball = sphere(&Point3::origin(), 0.05, 1500);
    let a = PointCloud::from_sigma(add_noise(&plate, sigma, 1), sigma)?;
    let b = PointCloud::from_sigma(add_noise(&ball, sigma, 2), sigma)?;
    let request = CollisionRequest::default();
    for gap_mm in [-5.0, 0.0, 5.0, 10.0, 20.0, 40.0] {
        // The ball's lowest point `gap_mm` above the plate's top face (z = 0.01).
        let pose_b = Pose::translation(0.0, 0.0, 0.01 + 0.05 + gap_mm * 1e-3);
        let r = collide(&Pose::identity(), &a, &pose_b, &b, &request)?;
        println!(
            "gap {gap_mm:>5.1} mm: P = {:.4} ({}), {} region(s), {:.2} ms",
            r.probability,
            r.state.name(),
            r.patches.len(),
            r.stats.time_seconds * 1e3
        );
        // The patch where the surfaces come closest (or interpenetrate deepest).
        let deepest = r
            .patches
            .iter()
            .min_by(|x, y| x.separation.total_cmp(&y.separation));
        if let Some(region) = deepest {
            println!(
                "    normal {:.3?}, estimated separation {:+.1} mm",
                region.normal.as_slice(),
                region.separation * 1e3
            );
        }
    }
    Ok(())
}
