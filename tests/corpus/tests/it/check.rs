//! Runs every rule over the real-world corpus ($ODC_CORPUS/MANIFEST.tsv): no panics, and a
//! table of how many files trip each rule (run with `--nocapture` to see it).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::collections::{BTreeMap, BTreeSet};

use odc_check::{Config, Level, RULES, check};
use odc_model::{Device, Severity, Sources};

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus() {
    let dir = odc_tests_corpus::dir();
    let manifest = std::fs::read_to_string(dir.join("MANIFEST.tsv")).unwrap();
    let mut files = 0usize;
    let mut devices = 0usize;
    // rule code -> files that trip it; and the total number of diagnostics.
    let mut tripped: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    let mut total: BTreeMap<&str, usize> = BTreeMap::new();
    // ODC_CORPUS_SAMPLES=C112,C201 prints a few (ODC_CORPUS_SAMPLE_LIMIT, 25) diagnostics of
    // those rules.
    let samples = std::env::var("ODC_CORPUS_SAMPLES").unwrap_or_default();
    let limit: usize =
        std::env::var("ODC_CORPUS_SAMPLE_LIMIT").ok().and_then(|v| v.parse().ok()).unwrap_or(25);
    // ODC_CORPUS_KIND=esi (or eds, dcf) reads only the files of that kind.
    let only_kind = std::env::var("ODC_CORPUS_KIND").ok();
    let mut printed: BTreeMap<&str, usize> = BTreeMap::new();
    // Rules that are off by default are counted too (reported at warning level here).
    let mut config = Config::in_registry(odc_check::rules());
    for r in RULES.iter().filter(|r| r.level == Level::Allow) {
        config.set_level(r.info.code, Level::Warn).unwrap();
    }
    for line in manifest.lines().skip(1) {
        let mut cols = line.split('\t');
        let (Some(file), Some(kind)) = (cols.next(), cols.next()) else { continue };
        if only_kind.as_deref().is_some_and(|k| k != kind) {
            continue;
        }
        let Ok(bytes) = std::fs::read(dir.join(file)) else { continue };
        let mut sources = Sources::new();
        let devs: Vec<Device> = match kind {
            "eds" | "dcf" => vec![odc_eds::parse(&mut sources, file, &bytes).device],
            "esi" => odc_esi::parse(&mut sources, file, &bytes).devices,
            _ => continue,
        };
        files += 1;
        for dev in &devs {
            devices += 1;
            for d in check(dev, &config) {
                if samples.split(',').any(|c| c == d.code) {
                    let n = printed.entry(d.code).or_default();
                    if *n < limit {
                        *n += 1;
                        let lc = d.primary_span().and_then(|s| sources.line_col(s));
                        let line = lc.map_or(0, |l| l.line);
                        println!(
                            "{file}:{line}: {}[{}] {}",
                            d.severity.as_str(),
                            d.code,
                            d.message
                        );
                    }
                }
                tripped.entry(d.code).or_default().insert(file.to_string());
                *total.entry(d.code).or_default() += 1;
            }
        }
    }
    println!("corpus: {files} files, {devices} devices");
    println!(
        "{:<6} {:<34} {:>5} {:>5} {:>5} {:>7}  level",
        "code", "name", "files", "eds", "esi", "diags"
    );
    for r in RULES {
        let code = r.info.code;
        let set = tripped.get(code);
        let n = set.map_or(0, BTreeSet::len);
        let esi = set.map_or(0, |s| s.iter().filter(|f| f.starts_with("esi/")).count());
        let level = match (r.level, r.info.default) {
            (Level::Allow, _) => "allow",
            (_, Severity::Note) => "note",
            (level, _) => level.as_str(),
        };
        println!(
            "{code:<6} {:<34} {n:>5} {:>5} {esi:>5} {:>7}  {level}",
            r.info.name,
            n - esi,
            total.get(code).copied().unwrap_or(0)
        );
    }
}
