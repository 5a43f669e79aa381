//! The XDD/XDC front-end on arbitrary bytes: it must not panic, every diagnostic it returns must
//! point into the decoded text, and the device it reads must write as XDC and read back.
#![no_main]

use libfuzzer_sys::fuzz_target;
use odc_model::{Format, Sources};

fuzz_target!(|data: &[u8]| {
    let mut sources = Sources::new();
    let parsed = odc_xdd::parse(&mut sources, "fuzz.xdd", data);
    let len = sources.text(parsed.file).map_or(0, str::len);
    for d in &parsed.diagnostics {
        for l in &d.labels {
            assert!(l.span.start <= l.span.end && l.span.end as usize <= len, "{d:?}");
        }
    }
    let _ = odc_model::diag::render_short(&sources, &parsed.diagnostics);
    if let Some(device) = parsed.device {
        let written = odc_xdd::write(&device, Format::Xdc);
        let again = odc_xdd::parse(&mut sources, "again.xdc", written.text.as_bytes());
        assert!(again.device.is_some(), "the written XDC does not read");
    }
});
