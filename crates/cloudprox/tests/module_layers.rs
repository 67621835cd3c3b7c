//! The crate's layering: a point cloud is the type the filters, the readers
//! and the scan pipeline build on, so `cloud` names none of them (the scan
//! pipeline once lived in `cloud/` and made it depend on `filter`).

use std::fs;
use std::path::Path;

/// The modules named by `crate::m` paths in the code of the `.rs` files
/// under `dir` (comment lines left out: a doc link is no dependency).
fn modules_used(dir: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "rs") {
            let text = fs::read_to_string(&path).unwrap();
            for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
                for (at, _) in line.match_indices("crate::") {
                    let name: String = line[at + 7..]
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    let file = path.file_name().unwrap().to_string_lossy().into_owned();
                    out.push((file, name));
                }
            }
        }
    }
    out
}

#[test]
fn the_cloud_module_uses_no_filter_reader_or_scan_pipeline() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let used = modules_used(&src.join("cloud"));
    // The search sees the module's own imports.
    assert!(used.iter().any(|(_, m)| m == "bvh"), "{used:?}");
    for (file, m) in &used {
        assert!(
            !["filter", "io", "scan"].contains(&m.as_str()),
            "cloud/{file} uses crate::{m}"
        );
    }
    // And the scan pipeline does use the filters (the search would see it).
    assert!(modules_used(&src)
        .iter()
        .any(|(f, m)| f == "scan.rs" && m == "filter"));
}
