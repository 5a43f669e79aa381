//! The EDS writer: parse → write → parse gives the same model, and the writer is stable.
//!
//! "The same" ignores spans (`Span`'s equality ignores positions) and the order of
//! `extra_sections`: INI sections are unordered, and the writer puts the sections it knows
//! first and the kept unknown ones after them, so a file with an unknown section before a known
//! one reads back with the sections in another order. Everything else must be equal.
//! The text written is re-read under the name a user would give it (`.dcf` for a DCF): a DCF
//! whose only DCF feature was, say, an empty `[1000Value]` section is a DCF by its name.
//! Stability: writing the re-read model gives the same text.
#![no_main]

use libfuzzer_sys::fuzz_target;
use odc_model::{Device, Format, Sources};

fn canonical(d: &Device) -> Device {
    let mut d = d.clone();
    d.extra_sections.sort_by_key(|s| s.name.to_ascii_lowercase());
    d
}

fuzz_target!(|data: &[u8]| {
    let mut sources = Sources::new();
    let first = odc_eds::parse(&mut sources, "fuzz.eds", data);
    let format = first.device.format.unwrap_or(Format::Eds);
    let text = odc_eds::write(&first.device, format);
    let name = if format == Format::Dcf { "fuzz.dcf" } else { "fuzz.eds" };
    let second = odc_eds::parse(&mut sources, name, text.as_bytes());
    assert_eq!(canonical(&first.device), canonical(&second.device), "written:\n{text}");
    let again = odc_eds::write(&second.device, format);
    let third = odc_eds::parse(&mut sources, name, again.as_bytes());
    assert_eq!(odc_eds::write(&third.device, format), again, "writer not stable");
});
