//! The CiA 311 XDD/XDC front-end and writer of odc.
//!
//! [`parse`] decodes the bytes and reads them with the span-keeping XML reader of `odc-esi`
//! (same limits: no DTD, no entity expansion, nesting depth 256, 2,000,000 elements, 64 MiB;
//! its codes become this crate's `F3xx`), then lowers the ISO 15745 profile container into an
//! [`odc_model::Device`]: the device profile (`DeviceIdentity`, `ApplicationProcess` with its
//! `dataTypeList` and `parameterList`) and the communication network profile
//! (`CANopenObjectList`, `dummyUsage`, `TransportLayers`, `NetworkManagement`,
//! `deviceCommissioning`). [`write()`] writes a model back as XDD or XDC.
//!
//! # Policies
//!
//! - **The model of an EDS.** An object lowers to what the EDS front-end makes of the same
//!   object: a VAR has one sub-object 0 named as the object; values are read by the EDS value
//!   reader ([`odc_eds::read_value`]), since CiA 311 files write them in CiA 306 syntax
//!   (`0x1A`, `$NODEID+0x180`, hex bytes).
//! - **Attributes over parameters.** An object's `dataType`, `accessType`, `defaultValue`,
//!   `lowLimit`, `highLimit`, `actualValue` and `denotation` attributes win; what they leave
//!   out comes from the parameter its `uniqueIDRef` names (IEC type element, `access`,
//!   `defaultValue`, `allowedValues/range`, `actualValue`, `label` for a missing name).
//!   `dataType="0000"` (written by old CANopenEditor versions) is absent; a sub-object of an
//!   ARRAY without a type takes the object's.
//! - **Empty attributes are absent** (`lowLimit=""`): CANopenEditor writes them on every
//!   object; an empty default of a string type is the empty string, as in an EDS.
//! - **PDOmapping** `no` is not mappable, `default`/`optional` mappable (direction by access,
//!   as in an EDS), `TPDO`/`RPDO` mappable in that direction only, said as an EDS says it
//!   where it can: `readWrite` with `TPDO` is `rwr`, with `RPDO` `rww`; `read`/`const` with
//!   `TPDO` and `write` with `RPDO` are plainly mappable. A direction the access forbids
//!   (`readWriteInput` with `RPDO`, as some CANopenEditor files say) is kept as written.
//! - **Kept**: unknown attributes and parameter `property` elements go to the object's
//!   `extra` (a VAR's to the object); a parameter's `description` too (key `Description`,
//!   line ends as `\n`); unknown elements of the profiles are kept whole in
//!   [`odc_model::Device::xml_extra`].
//! - **XDC or XDD**: a file named `.xdc`, or one with an `actualValue` or `denotation`, is an
//!   XDC ([`odc_model::Format::Xdc`]); `deviceCommissioning` is read in either.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod lower;
mod rules;
mod write;

use std::borrow::Cow;

use odc_model::{Device, Diagnostic, FileId, Sources};

pub use rules::{RULES, codes};
pub use write::{Written, write};

/// Largest file read (bytes); larger ones get error `F305` and no device.
pub const MAX_FILE_SIZE: usize = odc_esi::MAX_FILE_SIZE;

/// What [`parse`] produced for one file.
#[derive(Debug)]
pub struct Parsed {
    /// The device; `None` when the file is not an ISO 15745 container (its diagnostics say why).
    pub device: Option<Device>,
    /// Every problem found, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
    /// The file's id in the [`Sources`] it was added to.
    pub file: FileId,
}

/// Whether `bytes` look like an XDD/XDC: XML whose first element is
/// `ISO15745ProfileContainer` (any namespace prefix), within the first 4 KiB.
pub fn is_xdd(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    let mut at = 0;
    while let Some(i) = memchr::memchr(b'<', head.get(at..).unwrap_or_default()) {
        let rest = head.get(at + i + 1..).unwrap_or_default();
        match rest.first() {
            Some(b'?' | b'!') => at += i + 1,
            Some(_) => {
                let end = rest
                    .iter()
                    .position(|b| b.is_ascii_whitespace() || *b == b'>' || *b == b'/')
                    .unwrap_or(rest.len());
                let name = rest.get(..end).unwrap_or_default();
                let local = name.rsplit(|b| *b == b':').next().unwrap_or(name);
                return local == b"ISO15745ProfileContainer";
            }
            None => return false,
        }
    }
    false
}

/// Decodes `bytes`, adds the text to `sources` under `name`, reads and lowers it. Never
/// panics; every problem is a diagnostic.
pub fn parse(sources: &mut Sources, name: &str, bytes: &[u8]) -> Parsed {
    parse_input(sources, name, Cow::Borrowed(bytes))
}

/// [`parse`] for bytes the caller no longer needs (no copy of a UTF-8 file).
pub fn parse_vec(sources: &mut Sources, name: &str, bytes: Vec<u8>) -> Parsed {
    parse_input(sources, name, Cow::Owned(bytes))
}

fn parse_input(sources: &mut Sources, name: &str, bytes: Cow<'_, [u8]>) -> Parsed {
    let xml = match odc_esi::read_xml_file(sources, name, bytes, "XDD files") {
        Ok(x) => x,
        Err((file, mut d)) => {
            d.code = rules::from_esi(d.code);
            return Parsed { device: None, diagnostics: vec![d], file };
        }
    };
    let mut capped = odc_model::Capped::new();
    capped.extend(xml.diagnostics.finish().into_iter().map(|mut d| {
        d.code = rules::from_esi(d.code);
        d
    }));
    let xdc_name =
        std::path::Path::new(name).extension().is_some_and(|e| e.eq_ignore_ascii_case("xdc"));
    let device = lower::lower(&xml.doc, xml.file, xdc_name, &mut capped);
    let mut diagnostics = capped.finish();
    odc_model::diag::sort(&mut diagnostics);
    Parsed { device, diagnostics, file: xml.file }
}

#[cfg(test)]
mod tests;
