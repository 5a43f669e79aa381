//! CiA 402 (drive profile) detection, its axes, and the modes of operation a drive supports.
//!
//! # The one rule
//!
//! A device is a CiA 402 drive when object 0x1000 (device type) says device profile 402 in
//! bits 0–15. 0x1000 decides whenever it has a value: CiA 301 (7.5.2.1) makes it mandatory and
//! the device's own statement of what it is, the one a master reads from the bus, and ETG.6010
//! keeps it for CiA 402 over EtherCAT. An ESI `<Profile>` that says 402 while 0x1000 says
//! another profile (Beckhoff's AX5805 safety card and Synapticon's multi-device file say 5001;
//! modular devices whose axes come with their modules) describes something else than the
//! device itself. Only when 0x1000 has no value does the ESI decide: a `<Profile>` with
//! `<ProfileNo>402`, for the whole device or for a channel (`ChannelCount`, `ChannelInfo`).
//!
//! The code generator (typed controlword and statusword, the `cia402` module), the checker
//! (D501–D507), the data sheet and the simulator all ask [`is_cia402`].

use odc_model::{Device, Value};

/// The profile area repeats at most 8 times (0x6000–0x9FFF), one per axis.
pub const MAX_AXES: u16 = 8;

/// Distance between the profile areas of two axes (axis n at 0x6000 + n·0x800).
pub const AXIS_OFFSET: u16 = 0x800;

/// Whether the device is a CiA 402 drive, by the rule of the module documentation.
pub fn is_cia402(device: &Device) -> bool {
    !axes(device).is_empty()
}

/// What 0x1000 says: `Some(true)` when bits 0–15 are 402, `Some(false)` for another profile,
/// `None` when the object or its value is absent (or `$NODEID`-relative, or no integer).
fn device_type_402(device: &Device) -> Option<bool> {
    let v = device.sub(0x1000, 0)?.initial_value()?;
    let n = match v.value {
        Value::Unsigned(u) => u,
        Value::Signed(i) => u64::try_from(i).ok()?,
        _ => return None,
    };
    Some(n & 0xFFFF == 402)
}

/// The axes (0-based) an ESI `Profile` list declares as CiA 402: channels are counted over
/// the profiles in order; a profile covers `ChannelCount` channels (one when not given), or one
/// per `ChannelInfo`, each with its own `ProfileNo`.
fn esi_402_axes(device: &Device) -> Vec<u16> {
    let Some(ec) = device.ethercat.as_deref() else { return Vec::new() };
    let mut out = Vec::new();
    let mut channel: u32 = 0;
    for p in &ec.profiles {
        if p.channel_profiles.is_empty() {
            let n = p.channel_count.unwrap_or(1).max(1);
            if p.profile_no == Some(402) {
                out.extend(
                    (channel..channel.saturating_add(n)).filter_map(|c| u16::try_from(c).ok()),
                );
            }
            channel = channel.saturating_add(n);
        } else {
            for cp in &p.channel_profiles {
                if *cp == Some(402)
                    && let Ok(c) = u16::try_from(channel)
                {
                    out.push(c);
                }
                channel = channel.saturating_add(1);
            }
        }
    }
    out.retain(|&a| a < MAX_AXES);
    out
}

/// The index offsets of the device's CiA 402 axes, ascending: n·0x800 for each axis 0x1000 or
/// the ESI declares (by the rule of the module documentation), plus every further axis whose
/// controlword or statusword exists. Empty when the device is no CiA 402 drive.
pub fn axes(device: &Device) -> Vec<u16> {
    let mut out: Vec<u16> = match device_type_402(device) {
        Some(false) => return Vec::new(),
        Some(true) => vec![0],
        None => Vec::new(),
    };
    out.extend(esi_402_axes(device).into_iter().map(|a| a * AXIS_OFFSET));
    if out.is_empty() {
        return out;
    }
    for n in 1..MAX_AXES {
        let base = n * AXIS_OFFSET;
        if device.objects.contains_key(&(0x6040 + base))
            || device.objects.contains_key(&(0x6041 + base))
        {
            out.push(base);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// A standard mode of operation of CiA 402-2 (values of 0x6060 and 0x6061).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mode {
    /// Its bit in 0x6502 (supported drive modes).
    pub bit: u32,
    /// Its value in 0x6060/0x6061.
    pub value: i8,
    /// A Rust variant name.
    pub name: &'static str,
    /// What it is, with its abbreviation.
    pub text: &'static str,
}

const fn mode(bit: u32, value: i8, name: &'static str, text: &'static str) -> Mode {
    Mode { bit, value, name, text }
}

/// The standard modes, by 0x6502 bit.
pub const MODES: &[Mode] = &[
    mode(0, 1, "ProfilePosition", "Profile position mode (pp)."),
    mode(1, 2, "Velocity", "Velocity mode (vl)."),
    mode(2, 3, "ProfileVelocity", "Profile velocity mode (pv)."),
    mode(3, 4, "ProfileTorque", "Profile torque mode (tq)."),
    mode(5, 6, "Homing", "Homing mode (hm)."),
    mode(6, 7, "InterpolatedPosition", "Interpolated position mode (ip)."),
    mode(7, 8, "CyclicSyncPosition", "Cyclic synchronous position mode (csp)."),
    mode(8, 9, "CyclicSyncVelocity", "Cyclic synchronous velocity mode (csv)."),
    mode(9, 10, "CyclicSyncTorque", "Cyclic synchronous torque mode (cst)."),
    mode(
        10,
        11,
        "CyclicSyncTorqueWithCommutation",
        "Cyclic synchronous torque mode with commutation angle (cstca).",
    ),
];

/// The default of 0x6502 (supported drive modes), if it is a number that fits 32 bits.
pub fn supported_mode_bits(device: &Device) -> Option<u32> {
    device.sub(0x6502, 0).and_then(|s| s.initial_value()).and_then(|v| match v.value {
        Value::Unsigned(u) => u32::try_from(u).ok(),
        _ => None,
    })
}

/// The standard modes the device supports, from the default of 0x6502; every standard mode
/// when it has none (the generated `Mode` lists the same).
pub fn supported_modes(device: &Device) -> Vec<Mode> {
    let supported = supported_mode_bits(device);
    MODES.iter().filter(|m| supported.is_none_or(|s| s & (1 << m.bit) != 0)).copied().collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A device whose 0x1000 has `device_type` as its default (none when empty), with a
    /// controlword at `0x6040 + axis2` when given, and `modes` as the default of 0x6502.
    fn eds(device_type: &str, axis2: bool, modes: &str) -> Device {
        let mut text = String::from("[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n");
        text += &format!(
            "[1000]\nParameterName=Device type\nObjectType=7\nDataType=7\nAccessType=ro\n\
             DefaultValue={device_type}\n"
        );
        text += "[OptionalObjects]\nSupportedObjects=2\n1=0x6502\n2=0x6840\n";
        text += &format!(
            "[6502]\nParameterName=Supported drive modes\nObjectType=7\nDataType=7\n\
             AccessType=ro\nDefaultValue={modes}\n"
        );
        if axis2 {
            text +=
                "[6840]\nParameterName=Controlword 2\nObjectType=7\nDataType=6\nAccessType=rww\n";
        }
        odc_eds::parse(&mut odc_model::Sources::new(), "x.eds", text.as_bytes()).device
    }

    #[test]
    fn device_type_decides() {
        assert!(is_cia402(&eds("0x00020192", false, "")));
        assert_eq!(axes(&eds("0x00020192", true, "")), [0, 0x800]);
        // Another profile, or no value: no drive (an EDS has no ESI profile to ask).
        assert!(!is_cia402(&eds("0x00000191", true, "")));
        assert!(axes(&eds("", true, "")).is_empty());
    }

    #[test]
    fn modes_follow_0x6502() {
        // pp (bit 0) and csp (bit 7).
        let d = eds("0x00020192", false, "0x81");
        let modes: Vec<i8> = supported_modes(&d).iter().map(|m| m.value).collect();
        assert_eq!(modes, [1, 8]);
        // Without a default, every standard mode.
        assert_eq!(supported_modes(&eds("0x192", false, "")).len(), 10);
    }
}
