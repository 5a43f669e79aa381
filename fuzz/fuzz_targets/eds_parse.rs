//! The EDS/DCF front-end on arbitrary bytes: it must not panic, and every diagnostic it returns
//! must point into the text it was given (a span past the end would break the renderers).
#![no_main]

use libfuzzer_sys::fuzz_target;
use odc_model::Sources;

fuzz_target!(|data: &[u8]| {
    let mut sources = Sources::new();
    let parsed = odc_eds::parse(&mut sources, "fuzz.eds", data);
    let len = sources.text(parsed.file).map_or(0, str::len);
    for d in &parsed.diagnostics {
        for l in &d.labels {
            assert!(l.span.start <= l.span.end && l.span.end as usize <= len, "{d:?}");
        }
    }
    // Rendering resolves every span to a line and column.
    let _ = odc_model::diag::render_short(&sources, &parsed.diagnostics);
});
