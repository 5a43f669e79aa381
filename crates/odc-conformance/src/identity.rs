//! Identity (CiA 301 7.5.2.1, 7.5.2.21; CiA 306 4.3): 0x1000 and 0x1018 as the file says,
//! and `[DeviceInfo]` agreeing with the device.

use std::fmt::Display;

use odc::transport::Bus;

use crate::session::{Session, le};
use crate::{Group, Outcome};

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    s.check(
        "identity.device-type",
        Group::Identity,
        "CiA 301 7.5.2.1",
        "0x1000 device type is the file's",
        |s| {
            let Some(sub) = s.sub(0x1000, 0) else {
                return Outcome::fail("the file has no 0x1000 (mandatory)");
            };
            let got = match s.read(0x1000, 0) {
                Ok(b) => b,
                Err(e) => return Outcome::fail(format!("0x1000: {e}")),
            };
            match s.default_bytes(sub) {
                Some(want) if want == got => Outcome::pass(format!("0x{:08X}", le(&got))),
                Some(want) => Outcome::fail(format!(
                    "0x1000 is 0x{:08X}, the file says 0x{:08X}",
                    le(&got),
                    le(&want)
                )),
                None if got.len() == 4 => {
                    Outcome::pass(format!("0x{:08X} (the file gives no value)", le(&got)))
                }
                None => Outcome::fail(format!("0x1000 has {} bytes, not 4", got.len())),
            }
        },
    );
    s.check(
        "identity.identity-object",
        Group::Identity,
        "CiA 301 7.5.2.21, CiA 306 4.3",
        "0x1018 vendor-ID, product code and revision are the file's ([DeviceInfo] and defaults)",
        |s| {
            if s.sub(0x1018, 1).is_none() {
                return Outcome::fail("the file has no 0x1018:01 (mandatory)");
            }
            let info = &s.dev.device_info;
            let rows = [
                (1, "vendor-ID", info.vendor_number.as_ref().map(|v| v.value)),
                (2, "product code", info.product_number.as_ref().map(|v| v.value)),
                (3, "revision number", info.revision_number.as_ref().map(|v| v.value)),
            ];
            let mut problems = Vec::new();
            let mut seen = Vec::new();
            for (sub, what, info_value) in rows {
                let Some(entry) = s.sub(0x1018, sub) else { continue };
                let got = match s.read(0x1018, sub) {
                    Ok(b) => le(&b),
                    Err(e) => {
                        problems.push(format!("0x1018:{sub:02X} {what}: {e}"));
                        continue;
                    }
                };
                seen.push(format!("{what} 0x{got:08X}"));
                if let Some(want) = s.default_bytes(entry).map(|b| le(&b))
                    && want != got
                {
                    problems.push(format!(
                        "0x1018:{sub:02X} {what} is 0x{got:08X}, its default 0x{want:08X}"
                    ));
                }
                if let Some(want) = info_value
                    && u64::from(want) != got
                {
                    problems.push(format!(
                        "0x1018:{sub:02X} {what} is 0x{got:08X}, [DeviceInfo] says 0x{want:08X}"
                    ));
                }
            }
            if problems.is_empty() {
                Outcome::pass(seen.join(", "))
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
}
