//! The EDS writer's round-trip property, shared by the `eds_roundtrip` fuzz target
//! (fuzz/fuzz_targets/eds_roundtrip.rs includes this file) and the regression tests of what it
//! found (tests/fuzz_regressions.rs): parse → write → parse gives the same model, and the
//! writer is stable.
//!
//! "The same" ignores spans (`Span`'s equality ignores positions), the order of
//! `extra_sections` (INI sections are unordered, and the writer puts the sections it knows
//! first and the kept unknown ones after them, so a file with an unknown section before a known
//! one reads back with the sections in another order), and the two normalisations the odc-eds
//! docs promise for modular devices: the writer writes `[SupportedModules] NrOfEntries` as the
//! number of modules and an `[MxModuleInfo]` for every module. Everything else must be equal.
//! The text written is re-read under the name a user would give it (`.dcf` for a DCF): a DCF
//! whose only DCF feature was, say, an empty `[1000Value]` section is a DCF by its name.
//! Stability: writing the re-read model gives the same text.

use odc_model::{Device, Format, Sources};

fn canonical(d: &Device) -> Device {
    let mut d = d.clone();
    // Section names compare case-insensitively: a kept section merged with a known one on
    // re-reading takes the known one's spelling.
    for s in &mut d.extra_sections {
        s.name.make_ascii_lowercase();
    }
    d.extra_sections.sort_by(|a, b| a.name.cmp(&b.name));
    d.modules.nr_of_entries = None;
    for m in &mut d.modules.supported {
        m.has_info = true;
    }
    d
}

/// Checks the property on `input` (panics where it fails); returns the text first written.
pub fn round_trip(input: &[u8]) -> String {
    let mut sources = Sources::new();
    let first = odc_eds::parse(&mut sources, "fuzz.eds", input);
    let format = first.device.format.unwrap_or(Format::Eds);
    let text = odc_eds::write(&first.device, format);
    let name = if format == Format::Dcf { "fuzz.dcf" } else { "fuzz.eds" };
    let second = odc_eds::parse(&mut sources, name, text.as_bytes());
    assert_eq!(canonical(&first.device), canonical(&second.device), "written:\n{text}");
    let again = odc_eds::write(&second.device, format);
    let third = odc_eds::parse(&mut sources, name, again.as_bytes());
    assert_eq!(odc_eds::write(&third.device, format), again, "writer not stable");
    text
}
