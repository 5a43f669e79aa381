//! The identity object against the ESI's `<Type>` (T625).

use super::*;

rule!(
    T625,
    "T625",
    "esi-identity-revision",
    "etg",
    Note,
    Warn,
    identity_revision,
    "0x1018's revision default differs from the device's Type@RevisionNo",
    "The revision number is stated twice in an ESI: Type@RevisionNo (which the SII image \
     carries, and by which a master matches the device to its description) and the default \
     of 0x1018:03 in the dictionary (what a device that starts from its dictionary answers \
     over CoE). Masters that check the identity over CoE as well as from the EEPROM, and tools \
     that compare the ESI with a device's answers, see two revisions. C207 compares vendor and \
     product for an ESI, not the revision, because vendor files reuse one dictionary for many \
     revisions: this rule reports it as a note. Fix: set 0x1018:03's DefaultData to the \
     revision (little-endian), or allow the rule for a shared dictionary."
);

pub(super) fn identity_revision(dev: &Device, ctx: &mut Ctx) {
    if ec(dev).is_none() {
        return;
    }
    let Some(declared) = &dev.device_info.revision_number else { return };
    let Some(o) = crate::util::object(dev, 0x1018) else { return };
    let Some(s) = o.sub(3) else { return };
    let Some(v) = s.default.as_ref() else { return };
    let Some(value) = v.value.as_u64() else { return };
    if value == u64::from(declared.value) {
        return;
    }
    let d = ctx.report(
        0x1018,
        Some(3),
        crate::util::value_span(o, s, Some(v)),
        format!(
            "0x1018:03 defaults to 0x{value:08X} but Type@RevisionNo is 0x{:08X}",
            declared.value
        ),
    );
    d.labels.push(Label {
        span: declared.span,
        message: "RevisionNo given here".into(),
        primary: false,
    });
    if value == u64::from(declared.value.swap_bytes()) {
        d.notes.push(
            "the bytes are reversed: ESI DefaultData is little-endian (least significant byte \
             first)"
                .into(),
        );
    }
}
