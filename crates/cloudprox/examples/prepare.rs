//! What a new cloud costs before its first query, stage by stage: the
//! covariances, the hierarchy, the discretization estimate, the spacing, the
//! surface elements and their hulls (the Rust side of `benches/prepare.py`).
//!
//! `cargo run --release --example prepare -- POINTS COVARIANCES [repeat]`:
//! `POINTS` holds `n x 3` and `COVARIANCES` `n x 9` little-endian `f64`
//! (numpy's `tofile`). Without files, a noisy box of about 120 000 points.
//! Prints the median wall time of `repeat` runs (default 5) of each stage
//! and its mean CPU time over all threads, in milliseconds.

use std::time::Instant;

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, box_surface};

/// Little-endian `f64`s of a file.
fn read_f64(path: &str) -> Result<Vec<f64>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(std::path::Path::new(path), &e))?;
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect())
}

/// The cloud's points and sensor covariances.
fn input(args: &[String]) -> Result<(Vec<Point3>, Vec<Matrix3>)> {
    if args.len() >= 2 {
        let p = read_f64(&args[0])?;
        let c = read_f64(&args[1])?;
        let points: Vec<Point3> = p
            .chunks_exact(3)
            .map(|x| Point3::new(x[0], x[1], x[2]))
            .collect();
        let cov = c.chunks_exact(9).map(Matrix3::from_row_slice).collect();
        return Ok((points, cov));
    }
    let sigma = 0.002;
    let pts = box_surface(&Point3::origin(), &Vector3::new(2.0, 1.5, 1.0), 0.006);
    let pts = add_noise(&pts, sigma, 1);
    let cov = vec![Matrix3::identity() * (sigma * sigma); pts.len()];
    Ok((pts, cov))
}

/// Prints a digest of everything the stages build (the covariances, the
/// spacings, the elements with their points and samples, the hierarchy), to
/// compare two builds bit for bit (`Debug` prints every float exactly).
fn digest(points: &[Point3], cov: &[Matrix3]) -> Result<()> {
    use std::hash::{Hash, Hasher};
    let cloud = PointCloud::from_covariances(points.to_vec(), cov.to_vec())?
        .with_discretization(&DiscretizationSettings::default())?;
    let e = cloud.elements();
    let parts: [(&str, String); 7] = [
        ("covariances", format!("{:?}", cloud.covariances())),
        ("spacing", format!("{:?}", cloud.spacing())),
        ("node spacing", format!("{:?}", cloud.node_spacing())),
        ("hierarchy", format!("{:?}", cloud.bvh().nodes())),
        ("elements", format!("{:?}", e.elements())),
        ("element points", format!("{:?}", e.indices())),
        ("samples", format!("{:?}", e.samples().covariances())),
    ];
    for (name, text) in parts {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        text.hash(&mut h);
        println!("digest {name:16} {:016x}", h.finish());
    }
    Ok(())
}

/// The process's CPU time so far (user and system, all threads), in
/// milliseconds, from `/proc/self/stat` (clock ticks of 10 ms); 0 where it
/// cannot be read.
fn cpu_ms() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // The fields after the command name, which is in parentheses.
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
            Some(ticks * 10.0)
        })
        .unwrap_or(0.0)
}

/// The median of `v`.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (points, cov) = input(&args)?;
    let repeat: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let stages = [
        "covariances",
        "hierarchy",
        "discretization",
        "spacing",
        "elements",
        "hulls",
    ];
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); stages.len()];
    let mut cpu: Vec<f64> = vec![0.0; stages.len()];
    let far = [Pose::translation(1e3, 0.0, 0.0)];
    let request = CollisionRequest {
        model: QueryModel::Elements,
        ..CollisionRequest::default()
    };
    let mut count = 0;
    for _ in 0..repeat {
        let (mut t, mut c) = (Instant::now(), cpu_ms());
        let mut lap = |k: usize, times: &mut Vec<Vec<f64>>| {
            times[k].push(t.elapsed().as_secs_f64() * 1e3);
            let now = cpu_ms();
            cpu[k] += now - c;
            (t, c) = (Instant::now(), now);
        };
        let cloud = PointCloud::from_covariances(points.clone(), cov.clone())?;
        lap(0, &mut times);
        let _ = cloud.bvh();
        lap(1, &mut times);
        let cloud = cloud.with_discretization(&DiscretizationSettings::default())?;
        lap(2, &mut times);
        let _ = cloud.spacing();
        lap(3, &mut times);
        count = cloud.elements().elements().len();
        lap(4, &mut times);
        let _ = collide_many(&far, &cloud, &Pose::identity(), &cloud, &request)?;
        lap(5, &mut times);
    }
    println!("{} points, {count} elements", points.len());
    if std::env::var_os("PREPARE_DIGEST").is_some() {
        digest(&points, &cov)?;
    }
    let (mut total, mut total_cpu) = (0.0, 0.0);
    println!("{:16} {:>8} {:>12}", "stage", "wall ms", "mean cpu ms");
    for ((name, t), c) in stages.iter().zip(times).zip(cpu) {
        let (m, c) = (median(t), c / repeat as f64);
        (total, total_cpu) = (total + m, total_cpu + c);
        println!("{name:16} {m:8.1} {c:12.0}");
    }
    println!("{:16} {total:8.1} {total_cpu:12.0}", "total");
    Ok(())
}
