//! The ESI front-end on arbitrary bytes: it must not panic, and every diagnostic it returns must
//! point into the decoded text.
#![no_main]

use libfuzzer_sys::fuzz_target;
use odc_model::Sources;

fuzz_target!(|data: &[u8]| {
    let mut sources = Sources::new();
    let parsed = odc_esi::parse(&mut sources, "fuzz.xml", data);
    let len = sources.text(parsed.file).map_or(0, str::len);
    for d in &parsed.diagnostics {
        for l in &d.labels {
            assert!(l.span.start <= l.span.end && l.span.end as usize <= len, "{d:?}");
        }
    }
    let _ = odc_model::diag::render_short(&sources, &parsed.diagnostics);
});
