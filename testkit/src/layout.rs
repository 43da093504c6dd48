//! Guard rails on the workspace's layout, the restructuring's acceptance
//! kept true: no library source file over 1,500 lines, the command line's
//! crate under 2,500 lines of code (plumbing only), and no two public
//! types of the library crates sharing a name (a name says what a thing
//! is; `use a::Shadows` and `use b::Shadows` would say two things).
//! Read from the sources as they are in the repository.

use std::path::{Path, PathBuf};

/// The crates whose public types are an API (test support and the
/// Python module's private classes are not).
const LIBRARIES: &[&str] = &[
    "bsp-core",
    "bsp-csg",
    "svbsp",
    "shadow-scene",
    "shadow-raster",
    "shadow-cli",
    "tiling",
    "shadows",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace holds testkit")
        .to_path_buf()
}

/// Every `.rs` file under `dir`, sorted.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("a source folder") {
            let p = e.expect("a folder entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The lines of a source file before its test module (`#[cfg(test)]`
/// followed by `mod`), which the workspace keeps at a file's end; a file
/// that is a test module itself has none.
fn non_test_lines(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).expect("a readable source");
    if path.file_name().is_some_and(|n| n == "tests.rs") {
        return Vec::new();
    }
    let lines: Vec<String> = text.lines().map(str::to_string).collect();
    let end = (0..lines.len())
        .find(|&i| {
            lines[i].trim() == "#[cfg(test)]"
                && lines
                    .get(i + 1)
                    .is_some_and(|l| l.trim_start().starts_with("mod ") && l.ends_with('{'))
        })
        .unwrap_or(lines.len());
    lines[..end].to_vec()
}

/// A public type's name declared on `line`, if any.
fn public_type(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix("pub ")?;
    let rest = ["struct ", "enum ", "trait ", "type ", "union "]
        .iter()
        .find_map(|k| rest.strip_prefix(k))?;
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    Some(&rest[..end])
}

#[test]
fn no_library_file_is_over_1500_lines() {
    let long: Vec<String> = LIBRARIES
        .iter()
        .flat_map(|c| sources(&root().join(c).join("src")))
        .filter_map(|p| {
            let n = std::fs::read_to_string(&p).ok()?.lines().count();
            (n > 1500).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "split these: {long:?}");
}

#[test]
fn the_command_line_stays_plumbing() {
    let code: usize = sources(&root().join("shadow-cli/src"))
        .iter()
        .flat_map(|p| non_test_lines(p))
        .filter(|l| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with("//")
        })
        .count();
    assert!(
        code < 2500,
        "shadow-cli has {code} lines of code: move the work into a library"
    );
}

#[test]
fn no_two_public_types_share_a_name() {
    let mut seen: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for c in LIBRARIES {
        for p in sources(&root().join(c).join("src")) {
            let lines = non_test_lines(&p);
            for (i, line) in lines.iter().enumerate() {
                let Some(name) = public_type(line) else {
                    continue;
                };
                // a README compiled as a doctest is no type of the API
                let doctest = lines[i.saturating_sub(3)..i]
                    .iter()
                    .any(|l| l.contains("cfg(doctest)"));
                if !doctest {
                    let at = format!("{}:{}", p.strip_prefix(root()).unwrap().display(), i + 1);
                    seen.entry(name.to_string()).or_default().push(at);
                }
            }
        }
    }
    let shared: Vec<_> = seen.iter().filter(|(_, at)| at.len() > 1).collect();
    assert!(
        seen.len() > 100,
        "the scan found too few types: {}",
        seen.len()
    );
    assert!(shared.is_empty(), "public types sharing a name: {shared:?}");
}

#[test]
fn the_scan_sees_what_it_looks_for() {
    assert_eq!(public_type("pub struct Shadows {"), Some("Shadows"));
    assert_eq!(public_type("    pub enum Side {"), Some("Side"));
    assert_eq!(
        public_type("pub type GridPoint = [i32; 3];"),
        Some("GridPoint")
    );
    assert_eq!(public_type("pub(crate) struct Hidden;"), None);
    assert_eq!(public_type("pub fn shadows() {}"), None);
}
