//! The real-world corpus: no panic, round trip, and at least 95% of files without errors.

use odc_tests_corpus::{files, path};

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus() {
    let files: Vec<_> = files(&["eds", "dcf"]).iter().map(|f| path(f)).collect();
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
