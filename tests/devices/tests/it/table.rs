//! The counts of `tests/devices/README.md` against the records the tests write
//! (`records/*.tsv`, one line per printed frame a test compared or listed, `common::Records`).
//!
//! Each counted row's `printed` and `reproduced` are the numbers of records with its key (the
//! `where` cell up to its first colon) from the test file it names, and its tests are the
//! ones that recorded them; every record has its row; each manual's `Counted:` line is the sum
//! of its rows. `ODC_RECORDS=write cargo test -p odc-tests-devices --test it table::` writes the
//! numbers from the records; without it, any difference fails. The records themselves are
//! checked by the tests that make them (each test's block must equal what it compared).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The manual (README heading prefix) of each test file that records.
const MANUALS: [(&str, &str); 6] = [
    ("lxm23a", "## Schneider LXM23A"),
    ("lexium_mdrive", "## Schneider Lexium MDrive"),
    ("lexium_mdrive_lss", "## Schneider Lexium MDrive"),
    ("servoone", "## LTI ServoOne"),
    ("lenze", "## Lenze E94AYCCA"),
    ("linmot", "## LinMot E1200"),
];

/// (printed, reproduced, tests) per (test file stem, key).
type Tally = BTreeMap<(String, String), (u32, u32, BTreeSet<String>)>;

fn records() -> Tally {
    let mut tally = Tally::new();
    for entry in std::fs::read_dir(dir().join("records")).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        assert!(MANUALS.iter().any(|(f, _)| *f == stem), "records/{stem}.tsv: no manual");
        let source = std::fs::read_to_string(dir().join("tests/it").join(format!("{stem}.rs")))
            .unwrap_or_else(|e| panic!("records/{stem}.tsv without tests/it/{stem}.rs: {e}"));
        for (k, line) in std::fs::read_to_string(&path).unwrap().lines().enumerate() {
            let at = format!("records/{stem}.tsv line {}", k + 1);
            let cells: Vec<&str> = line.split('\t').collect();
            let [test, key, kind, _printed, _made, why] = cells[..] else {
                panic!("{at}: not 6 cells")
            };
            assert!(source.contains(&format!("#[test]\nfn {test}(")), "{at}: no test {test}");
            assert!(
                source.contains(&format!("Records::new(\"{test}\")")),
                "{at}: {test} records nothing (stale records)"
            );
            let t = tally.entry((stem.clone(), key.to_owned())).or_default();
            t.0 += 1;
            match kind {
                "R" => t.1 += 1,
                "N" => assert!(why.len() > 10, "{at}: not reproduced, and no reason"),
                _ => panic!("{at}: kind {kind}"),
            }
            t.2.insert(test.to_owned());
        }
    }
    tally
}

/// The README with every counted row's numbers and every `Counted:` line made from `tally`,
/// and the keys of the rows found.
fn recount(readme: &str, tally: &Tally) -> (String, BTreeSet<(String, String)>) {
    let mut out = Vec::new();
    let mut seen = BTreeSet::new();
    let mut manual = String::new();
    let mut sums: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for (k, line) in readme.lines().enumerate() {
        if line.starts_with("## ") {
            manual = line.to_owned();
        }
        let cells: Vec<&str> = line.trim().split('|').map(str::trim).collect();
        // `| where | printed | reproduced | test | why not |`: 7 pieces with the outer ones.
        let counted = cells.len() == 7 && cells[2].parse::<u32>().is_ok();
        if !counted {
            out.push(line.to_owned());
            continue;
        }
        let at = format!("README.md line {}", k + 1);
        let key = cells[1].split(':').next().unwrap().trim().to_owned();
        let tests: BTreeSet<(String, String)> = cells[4]
            .split(',')
            .map(|t| t.trim().trim_matches('`'))
            .filter(|t| !t.is_empty())
            .map(|t| {
                let (file, f) = t.split_once("::").unwrap_or_else(|| panic!("{at}: `{t}`"));
                (file.strip_suffix(".rs").expect("file.rs").to_owned(), f.to_owned())
            })
            .collect();
        let files: BTreeSet<&String> = tests.iter().map(|(f, _)| f).collect();
        assert_eq!(files.len(), 1, "{at}: a counted row names tests of one file");
        let file = files.into_iter().next().unwrap().clone();
        let (_, heading) = MANUALS.iter().find(|(f, _)| *f == file).expect("a known file");
        assert!(manual.starts_with(heading), "{at}: {file}.rs under {manual}");
        let (printed, reproduced, recorded) = tally
            .get(&(file.clone(), key.clone()))
            .unwrap_or_else(|| panic!("{at}: no record of `{key}` in records/{file}.tsv"));
        let named: BTreeSet<String> = tests.iter().map(|(_, f)| f.clone()).collect();
        assert_eq!(&named, recorded, "{at}: the tests named are the ones that recorded `{key}`");
        assert!(seen.insert((file, key.clone())), "{at}: `{key}` has two rows");
        let sum = sums.entry(manual.clone()).or_default();
        sum.0 += printed;
        sum.1 += reproduced;
        let mut cells = cells;
        let (p, r) = (printed.to_string(), reproduced.to_string());
        cells[2] = &p;
        cells[3] = &r;
        out.push(format!("| {} |", cells[1..6].join(" | ")));
    }
    // The `Counted:` line of each manual, after its heading.
    let mut manual = String::new();
    for line in &mut out {
        if line.starts_with("## ") {
            manual = line.clone();
        }
        if line.starts_with("Counted: ") {
            let (p, r) = sums.get(&manual).copied().unwrap_or_default();
            *line = format!("Counted: {p} printed frames, {r} reproduced.");
        }
    }
    (out.join("\n") + "\n", seen)
}

#[test]
fn the_counts_are_the_records() {
    let tally = records();
    let path = dir().join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let (made, seen) = recount(&readme, &tally);
    for key in tally.keys() {
        assert!(seen.contains(key), "records of `{}` in {}.rs without a README row", key.1, key.0);
    }
    let counted = readme.lines().filter(|l| l.starts_with("Counted: ")).count();
    assert_eq!(counted, 5, "one `Counted:` line per manual");
    if std::env::var_os("ODC_RECORDS").is_some_and(|v| v == "write") {
        std::fs::write(&path, made).unwrap();
    } else {
        let differ = made.lines().zip(readme.lines()).position(|(m, r)| m != r);
        assert!(
            made == readme,
            "README.md's counts are not the records' (ODC_RECORDS=write); line {:?} should read {:?}",
            differ.map(|k| k + 1),
            differ.and_then(|k| made.lines().nth(k))
        );
    }
}

/// The rows of the "checked, not frames" tables name tests that exist.
#[test]
fn the_checked_rows_name_tests() {
    let readme = std::fs::read_to_string(dir().join("README.md")).unwrap();
    for (k, line) in readme.lines().enumerate() {
        for t in line.split('`').skip(1).step_by(2) {
            let Some((file, f)) = t.split_once(".rs::") else { continue };
            let source = std::fs::read_to_string(dir().join("tests/it").join(format!("{file}.rs")))
                .unwrap_or_else(|e| panic!("README.md line {}: {file}.rs: {e}", k + 1));
            assert!(source.contains(&format!("fn {f}(")), "README.md line {}: no {t}", k + 1);
        }
    }
}
