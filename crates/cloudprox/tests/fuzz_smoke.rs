//! A short, stable smoke run of every fuzz target (CI runs it through
//! `cargo test`; `scripts/fuzz.sh` runs the real fuzzer on nightly).
//!
//! The targets' bodies (`fuzz/src/lib.rs`) run on their seeds (inputs made
//! with cloudprox's writers, and the real files the Python tests fetch when
//! they are in the cache) and on reproducible mutations of them: flipped and
//! overwritten bytes, magic numbers, cuts, duplicated and deleted spans, huge
//! numbers in text headers. Any panic fails the test and names the input.

#[path = "../../../fuzz/src/lib.rs"]
mod bodies;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use bodies::{mutate, real_seed_extensions, synthetic_seeds, Rng, TARGETS};

/// Largest real file used as a seed (larger ones are slow to mutate).
const MAX_SEED_BYTES: u64 = 1 << 20;

/// The cache the Python tests fetch real files into, if it exists.
fn realfiles_dir() -> Option<PathBuf> {
    let cache = std::env::var_os("CLOUDPROX_CACHE")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache/cloudprox")))?;
    let dir = cache.join("realfiles");
    dir.is_dir().then_some(dir)
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// The real files (at most 1 MiB each) that seed `target`, sorted by path.
fn real_seeds(target: &str) -> Vec<(String, Vec<u8>)> {
    let exts = real_seed_extensions(target);
    let Some(dir) = realfiles_dir().filter(|_| !exts.is_empty()) else {
        return Vec::new();
    };
    let mut files = Vec::new();
    files_under(&dir, &mut files);
    files.sort();
    files
        .into_iter()
        .filter(|p| {
            let name = p.to_string_lossy().to_ascii_lowercase();
            exts.iter().any(|e| name.ends_with(e))
                && p.metadata().is_ok_and(|m| m.len() <= MAX_SEED_BYTES)
        })
        .filter_map(|p| Some((p.display().to_string(), std::fs::read(&p).ok()?)))
        .collect()
}

/// Every seed of `target`, named.
fn seeds(target: &str) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = synthetic_seeds(target)
        .into_iter()
        .enumerate()
        .map(|(i, s)| (format!("synthetic seed {i}"), s))
        .collect();
    out.extend(real_seeds(target));
    out.push(("empty input".into(), Vec::new()));
    out
}

/// Runs `target` on `data`; a panic becomes a message naming the input.
fn check(target: &str, what: &str, data: &[u8]) -> Result<(), String> {
    catch_unwind(AssertUnwindSafe(|| {
        assert!(bodies::run(target, data), "unknown target {target}");
    }))
    .map_err(|_| {
        let head: Vec<u8> = data.iter().take(256).copied().collect();
        format!(
            "target {target} panicked on {what} ({} bytes; first bytes {head:?})",
            data.len()
        )
    })
}

/// Seeds, then mutations until `runs` inputs or `budget` time.
fn smoke(target: &str, runs: usize, budget: Duration) -> usize {
    let seeds = seeds(target);
    let start = Instant::now();
    let mut done = 0;
    for (what, data) in &seeds {
        if let Err(e) = check(target, what, data) {
            panic!("{e}");
        }
        done += 1;
    }
    let mut rng = Rng::new(target.len() as u64 * 7919 + 1);
    while done < runs && start.elapsed() < budget {
        let (what, seed) = &seeds[rng.below(seeds.len())];
        let data = mutate(seed, &mut rng);
        if let Err(e) = check(target, &format!("mutation {done} of {what}"), &data) {
            panic!("{e}");
        }
        done += 1;
    }
    done
}

/// The readers: a few thousand inputs each, at most a few seconds.
#[test]
fn readers_survive_mutated_files() {
    for target in TARGETS {
        if matches!(target, "collide" | "exact") {
            continue;
        }
        let n = smoke(target, 3000, Duration::from_secs(4));
        assert!(n >= 50, "{target}: only {n} inputs ran");
    }
}

/// `collide` and the exact queries on structured inputs (slower per input).
#[test]
fn queries_survive_arbitrary_inputs() {
    for target in ["collide", "exact"] {
        let n = smoke(target, 1500, Duration::from_secs(8));
        assert!(n >= 50, "{target}: only {n} inputs ran");
    }
}

/// Mutation is reproducible and changes its input.
#[test]
fn mutation_is_seeded() {
    let seed = b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec();
    let run = |s| {
        let mut rng = Rng::new(s);
        (0..20).map(|_| mutate(&seed, &mut rng)).collect::<Vec<_>>()
    };
    assert_eq!(run(1), run(1));
    assert!(run(1).iter().any(|m| *m != seed));
    assert!(!bodies::run("no such target", b""));
}

/// Writes each target's seeds to `$CLOUDPROX_FUZZ_SEEDS/<target>/` for
/// `scripts/fuzz.sh` (which runs this test by name).
#[test]
#[ignore = "writes the fuzz seed corpus; run by scripts/fuzz.sh"]
fn write_seed_corpus() {
    let dir =
        PathBuf::from(std::env::var_os("CLOUDPROX_FUZZ_SEEDS").expect("CLOUDPROX_FUZZ_SEEDS"));
    for target in TARGETS {
        let t = dir.join(target);
        std::fs::create_dir_all(&t).expect("create the corpus folder");
        for (i, (_, data)) in seeds(target).iter().enumerate() {
            std::fs::write(t.join(format!("seed-{i:03}")), data).expect("write a seed");
        }
    }
}

/// Prints the structured input a crash file of target `$CLOUDPROX_FUZZ_TARGET`
/// at `$CLOUDPROX_FUZZ_INPUT` stands for (clouds, poses, options).
#[test]
#[ignore = "prints a fuzz input; run by hand"]
fn describe_input() {
    let target = std::env::var("CLOUDPROX_FUZZ_TARGET").expect("CLOUDPROX_FUZZ_TARGET");
    let path = std::env::var_os("CLOUDPROX_FUZZ_INPUT").expect("CLOUDPROX_FUZZ_INPUT");
    let data = std::fs::read(path).expect("read the input");
    println!(
        "{}",
        bodies::describe(&target, &data).unwrap_or_else(|| format!("{data:?}"))
    );
}

/// The error says the data is shorter than the header promises.
fn short<T: std::fmt::Debug>(r: cloudprox::Result<T>) {
    match r {
        Err(cloudprox::Error::Format { problem, .. }) => assert!(
            problem.contains("truncated") || problem.contains("ends after"),
            "{problem}"
        ),
        other => panic!("expected a format error, got {other:?}"),
    }
}

/// Headers that claim 10^12 points (or the largest count the field holds)
/// over a few bytes of data are errors, and allocate nothing for them: this
/// test binary runs under the fuzz targets' allocator, which aborts on any
/// single allocation above 512 MiB.
#[test]
fn huge_header_counts_allocate_nothing() {
    use cloudprox::io::{las, npy, off, pcd, ply, pointcloud2, stl};
    let t = 1_000_000_000_000u64;
    let ply_text = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {t}\nproperty float x\n\
         property float y\nproperty float z\nend_header\n\0\0\0\0\0\0\0\0\0\0\0\0"
    );
    short(ply::read_ply(ply_text.as_bytes(), "huge.ply"));
    for data in ["ascii", "binary", "binary_compressed"] {
        let pcd_text = format!(
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {t}\n\
             HEIGHT 1\nPOINTS {t}\nDATA {data}\n0 0 0\n"
        );
        short(pcd::read_pcd(pcd_text.as_bytes(), "huge.pcd"));
    }
    let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({t}, 3), }}");
    let mut npy_bytes = b"\x93NUMPY\x01\x00".to_vec();
    let header = format!("{dict:<117}\n");
    npy_bytes.extend((header.len() as u16).to_le_bytes());
    npy_bytes.extend(header.as_bytes());
    npy_bytes.extend([0u8; 48]);
    short(npy::read_npy(&npy_bytes, "huge.npy"));
    let off_text = "OFF\n4000000000 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    short(off::read_off_mesh(off_text.as_bytes(), "huge.off"));
    let mut stl_bytes = vec![0u8; 80];
    stl_bytes.extend(u32::MAX.to_le_bytes());
    stl_bytes.extend([0u8; 50]);
    short(stl::read_stl_mesh(&stl_bytes, "huge.stl"));
    // LAS 1.4: legacy count 0, 64-bit count 10^12, records of 20 bytes.
    let mut las_bytes = vec![0u8; 375];
    las_bytes[..4].copy_from_slice(b"LASF");
    las_bytes[24] = 1;
    las_bytes[25] = 4;
    las_bytes[94..96].copy_from_slice(&375u16.to_le_bytes());
    las_bytes[96..100].copy_from_slice(&375u32.to_le_bytes());
    las_bytes[105..107].copy_from_slice(&20u16.to_le_bytes());
    for k in 0..3 {
        las_bytes[131 + 8 * k..139 + 8 * k].copy_from_slice(&0.01f64.to_le_bytes());
    }
    las_bytes[247..255].copy_from_slice(&t.to_le_bytes());
    las_bytes.extend([0u8; 40]);
    short(las::read_las(&las_bytes, "huge.las"));
    let layout = pointcloud2::PointCloud2Layout {
        height: u32::MAX,
        width: u32::MAX / 12,
        fields: ["x", "y", "z"]
            .iter()
            .zip(0u32..)
            .map(|(n, k)| pointcloud2::PointField {
                name: (*n).to_string(),
                offset: 4 * k,
                datatype: pointcloud2::FLOAT32,
                count: 1,
            })
            .collect(),
        is_bigendian: false,
        point_step: 12,
        row_step: u32::MAX,
    };
    short(pointcloud2::read_pointcloud2(&layout, &[0u8; 64]));
}
