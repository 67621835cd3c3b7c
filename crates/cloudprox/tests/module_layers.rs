//! The crate's layering: `cloud` sits below the readers (`io`), the filters
//! (`filter`) and the scan pipeline (`scan`), which alone combines them into
//! a cloud, so `cloud` names none of the three (the scan pipeline once lived
//! in `cloud/` and made it depend on `filter`). Test code inside `cloud/`
//! counts too.

use std::fs;
use std::path::{Path, PathBuf};

/// `text` without its comments (`//` to the end of the line, `/* ... */`);
/// string literals are not told apart (none in the files read names a
/// module).
fn without_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find('/') {
        out.push_str(&rest[..at]);
        let tail = &rest[at..];
        if tail.starts_with("//") {
            rest = tail.find('\n').map_or("", |nl| &tail[nl..]);
        } else if tail.starts_with("/*") {
            rest = tail.find("*/").map_or("", |end| &tail[end + 2..]);
        } else {
            out.push('/');
            rest = &tail[1..];
        }
    }
    out.push_str(rest);
    out
}

fn identifier(s: &str) -> &str {
    let s = s.trim_start();
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The first-level module names after a path prefix that ends at the crate
/// root: `filter` in `crate::filter::x`, `filter` and `io` in
/// `crate::{filter::x, io}`.
fn names_after_root(after: &str, out: &mut Vec<String>) {
    let after = after.trim_start();
    let Some(group) = after.strip_prefix('{') else {
        out.push(identifier(after).to_string());
        return;
    };
    let mut depth = 1;
    let mut start = true;
    for (k, c) in group.char_indices() {
        if start && depth == 1 && !c.is_whitespace() {
            out.push(identifier(&group[k..]).to_string());
            start = false;
        }
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return;
                }
            }
            ',' if depth == 1 => start = true,
            _ => {}
        }
    }
}

/// The crate-root modules named in `code` (comments removed), a file whose
/// module lies `depth` levels below the root: by `crate::` paths and by
/// `super::` chains that climb to the root.
fn root_modules(code: &str, depth: usize) -> Vec<String> {
    let code = without_comments(code);
    let mut out = Vec::new();
    for (at, _) in code.match_indices("crate::") {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$') {
            continue; // `$crate::` or a longer name ending in `crate`
        }
        names_after_root(&code[at + "crate::".len()..], &mut out);
    }
    if depth > 0 {
        let climb = "super::".repeat(depth);
        for (at, _) in code.match_indices(&climb) {
            if code[..at].ends_with("super::") {
                continue; // part of a longer chain, counted from its start
            }
            names_after_root(&code[at + climb.len()..], &mut out);
        }
    }
    out.retain(|m| !m.is_empty() && m != "super");
    out
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `(file, module)` for each crate-root module named in the files of the
/// module directory `dir` of `src`.
fn modules_used(src: &Path, dir: &str) -> Vec<(String, String)> {
    let mut files = Vec::new();
    rust_files(&src.join(dir), &mut files);
    let mut used = Vec::new();
    for path in files {
        let rel = path.strip_prefix(src).unwrap();
        // `cloud/mod.rs` is the module `cloud` (one level down), `cloud/x.rs`
        // the module `cloud::x` (two).
        let mut depth = rel.components().count();
        if rel.file_name().is_some_and(|f| f == "mod.rs") {
            depth -= 1;
        }
        let text = fs::read_to_string(&path).unwrap();
        for m in root_modules(&text, depth) {
            used.push((rel.display().to_string(), m));
        }
    }
    used
}

#[test]
fn the_cloud_module_uses_no_filter_reader_or_scan_pipeline() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let used = modules_used(&src, "cloud");
    // The search sees the module's own imports.
    assert!(used.iter().any(|(_, m)| m == "bvh"), "{used:?}");
    for (file, m) in &used {
        assert!(
            !["filter", "io", "scan"].contains(&m.as_str()),
            "{file} uses crate::{m}"
        );
    }
}

#[test]
fn the_search_reads_paths_groups_climbs_and_skips_comments() {
    let names = |code: &str, depth: usize| {
        let mut v = root_modules(code, depth);
        v.sort();
        v
    };
    assert_eq!(names("use crate::filter::voxel;", 1), ["filter"]);
    assert_eq!(
        names("use crate::{\n    filter::{a, b},\n    io,\n};", 1),
        ["filter", "io"]
    );
    assert_eq!(names("let x = crate::io::read(p);", 2), ["io"]);
    // `super` climbs one level: from `cloud::x`, two reach the root.
    assert_eq!(names("use super::super::scan::Scan;", 2), ["scan"]);
    assert_eq!(names("use super::pose;", 2), Vec::<String>::new());
    assert_eq!(names("use super::{filter, io};", 1), ["filter", "io"]);
    // Comments and longer names are not paths.
    assert_eq!(
        names(
            "// crate::io\nlet a = 1; // crate::filter\n/* crate::scan */ $crate::io::x();",
            1
        ),
        Vec::<String>::new()
    );
    // The scan pipeline itself does combine the three.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let scan = fs::read_to_string(src.join("scan.rs")).unwrap();
    let used = names(&scan, 1);
    for m in ["filter", "io", "cloud", "uncertainty"] {
        assert!(used.iter().any(|u| u == m), "{m}: {used:?}");
    }
}
