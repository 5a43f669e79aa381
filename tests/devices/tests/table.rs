//! The table of `tests/devices/README.md` against the tests it names: every row's test exists,
//! its counts add up (reproduced ≤ printed, a reason wherever fewer are reproduced), and each
//! test file's `Count:` line is the sum of the rows that name it. The counts in the test files
//! are thereby derived from the table, and neither can drift from the other unnoticed.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// One row: where printed, frames printed, frames reproduced, the tests (`file.rs::fn`), why not.
#[derive(Debug)]
struct Row {
    line: usize,
    printed: u32,
    reproduced: u32,
    tests: Vec<(String, String)>,
    why_not: String,
}

/// The rows of every table in the README (pipe rows whose 2nd and 3rd cells are numbers).
fn rows(readme: &str) -> Vec<Row> {
    let mut out = Vec::new();
    for (k, line) in readme.lines().enumerate() {
        let Some(inner) = line.trim().strip_prefix('|').and_then(|l| l.strip_suffix('|')) else {
            continue;
        };
        let cells: Vec<&str> = inner.split('|').map(str::trim).collect();
        let [_, printed, reproduced, tests, why_not] = cells[..] else { continue };
        let (Ok(printed), Ok(reproduced)) = (printed.parse(), reproduced.parse()) else {
            continue;
        };
        let tests = tests
            .split(',')
            .map(|t| t.trim().trim_matches('`'))
            .filter(|t| !t.is_empty() && *t != "—" && *t != "-")
            .map(|t| {
                let (file, function) = t
                    .split_once("::")
                    .unwrap_or_else(|| panic!("README line {}: `{t}` is not file.rs::fn", k + 1));
                (file.to_owned(), function.to_owned())
            })
            .collect();
        out.push(Row { line: k + 1, printed, reproduced, tests, why_not: why_not.to_owned() });
    }
    out
}

/// `//! Count: N printed, R reproduced (tests/devices/README.md).` of a test file.
fn count_line(source: &str) -> Option<(u32, u32)> {
    let line = source.lines().find_map(|l| l.strip_prefix("//! Count: "))?;
    let (printed, rest) = line.split_once(" printed, ")?;
    let (reproduced, _) = rest.split_once(" reproduced")?;
    Some((printed.parse().ok()?, reproduced.parse().ok()?))
}

#[test]
fn the_table_and_the_test_files_agree() {
    let readme = std::fs::read_to_string(dir().join("README.md")).unwrap();
    let rows = rows(&readme);
    assert!(rows.len() >= 20, "the table has {} rows", rows.len());
    let mut sums: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for row in &rows {
        let at = format!("README.md line {}", row.line);
        assert!(row.reproduced <= row.printed, "{at}: more reproduced than printed");
        if row.reproduced < row.printed {
            assert!(row.why_not.len() > 10, "{at}: not all reproduced, and no reason");
        }
        if row.tests.is_empty() {
            assert_eq!(row.reproduced, 0, "{at}: reproduced without a test");
            continue;
        }
        let files: Vec<&str> = row.tests.iter().map(|(f, _)| f.as_str()).collect();
        assert!(files.iter().all(|f| *f == files[0]), "{at}: the tests of a row are in one file");
        for (file, function) in &row.tests {
            let source = std::fs::read_to_string(dir().join("tests").join(file))
                .unwrap_or_else(|e| panic!("{at}: tests/{file}: {e}"));
            assert!(
                source.contains(&format!("fn {function}(")),
                "{at}: no fn {function} in {file}"
            );
        }
        let sum = sums.entry(files[0].to_owned()).or_default();
        sum.0 += row.printed;
        sum.1 += row.reproduced;
    }
    // Every test file with a Count line is in the table, with the table's sums.
    let mut with_count = Vec::new();
    for entry in std::fs::read_dir(dir().join("tests")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.extension().is_some_and(|e| e == "rs") && name != "table.rs" {
            let source = std::fs::read_to_string(&path).unwrap();
            if let Some(count) = count_line(&source) {
                assert_eq!(sums.get(&name), Some(&count), "{name}: Count line against the table");
                with_count.push(name);
            }
        }
    }
    with_count.sort();
    let named: Vec<&String> = sums.keys().collect();
    assert_eq!(with_count.iter().collect::<Vec<_>>(), named, "files named by the table");
}
