//! The real-world corpus: no panic, round trip, and at least 95% of files without errors.

use std::path::PathBuf;

fn corpus_dir() -> PathBuf {
    std::env::var_os("ODC_CORPUS").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus"))
    })
}

/// The eds/dcf files listed in MANIFEST.tsv.
fn files(dir: &std::path::Path) -> Option<Vec<PathBuf>> {
    let manifest = std::fs::read_to_string(dir.join("MANIFEST.tsv")).ok()?;
    Some(
        manifest
            .lines()
            .skip(1)
            .filter_map(|l| {
                let mut cols = l.split('\t');
                let file = cols.next()?;
                let kind = cols.next()?;
                matches!(kind, "eds" | "dcf").then(|| dir.join(file))
            })
            .collect(),
    )
}

#[test]
fn corpus() {
    let dir = corpus_dir();
    let Some(files) = files(&dir) else {
        println!("corpus not found at {}; skipped", dir.display());
        return;
    };
    let mut clean = 0usize;
    let mut failing = Vec::new();
    let mut panicked = Vec::new();
    let mut not_round_trip = Vec::new();
    for path in &files {
        let Ok(bytes) = std::fs::read(path) else {
            panicked.push(format!("{}: unreadable", path.display()));
            continue;
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let result = std::panic::catch_unwind(|| {
            let mut sources = odc_model::Sources::new();
            let p = odc_eds::parse(&mut sources, &name, &bytes);
            let format = p.device.format.unwrap_or(odc_model::Format::Eds);
            let text = odc_eds::write(&p.device, format);
            let p2 = odc_eds::parse(&mut sources, &name, text.as_bytes());
            let text2 = odc_eds::write(&p2.device, format);
            let first_error = p
                .diagnostics
                .iter()
                .find(|d| d.is_error())
                .map(|d| odc_model::diag::render_short(&sources, std::slice::from_ref(d)));
            (p.device == p2.device && text == text2, first_error)
        });
        match result {
            Err(_) => panicked.push(name),
            Ok((rt, err)) => {
                if !rt {
                    not_round_trip.push(name.clone());
                }
                match err {
                    None => clean += 1,
                    Some(e) => failing.push(e.trim_end().to_owned()),
                }
            }
        }
    }
    let total = files.len();
    println!(
        "{clean}/{total} files ({:.1}%) parse with zero errors",
        100.0 * clean as f64 / total.max(1) as f64
    );
    for f in &failing {
        println!("  {f}");
    }
    assert!(panicked.is_empty(), "panicked: {panicked:?}");
    assert!(not_round_trip.is_empty(), "no round trip: {not_round_trip:?}");
    assert!(clean * 100 >= total * 95, "only {clean}/{total} without errors");
}
