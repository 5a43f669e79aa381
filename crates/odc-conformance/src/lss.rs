//! Layer setting services (CiA 305): a device whose file says `LSS_Supported=1` answers the
//! inquiries with its 0x1018 identity and node-ID; one that says 0 (or nothing) is silent.

use std::fmt::Display;

use odc::transport::Bus;

use crate::session::{Session, le};
use crate::{Group, Outcome};

const MASTER: u32 = 0x7E5;
const SLAVE: u32 = 0x7E4;

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    let supported = s.dev.device_info.lss_supported.as_ref().is_some_and(|v| v.value);
    s.check(
        "lss.inquire",
        Group::Lss,
        "CiA 305 4.4 (switch state global, inquire identity and node-ID); CiA 306 4.3",
        "with LSS_Supported=1 the device answers the inquiries with 0x1018 and its node-ID; \
         without, it is silent",
        |s| {
            if let Err(e) = s.send(MASTER, &[0x04, 0x01, 0, 0, 0, 0, 0, 0]) {
                return Outcome::fail(e);
            }
            s.listen(20);
            let mut answers = Vec::new();
            for (cs, sub) in
                [(0x5A, Some(1)), (0x5B, Some(2)), (0x5C, Some(3)), (0x5D, Some(4)), (0x5E, None)]
            {
                let _ = s.send(MASTER, &[cs, 0, 0, 0, 0, 0, 0, 0]);
                let got = s
                    .listen(100)
                    .into_iter()
                    .find(|(_, f)| f.is_data(SLAVE) && f.bytes().first() == Some(&cs))
                    .map(|(_, f)| f.bytes().to_vec());
                answers.push((cs, sub, got));
            }
            // Back to waiting, as before.
            let _ = s.send(MASTER, &[0x04, 0x00, 0, 0, 0, 0, 0, 0]);
            let heard = answers.iter().filter(|a| a.2.is_some()).count();
            if !supported {
                return if heard == 0 {
                    Outcome::pass("LSS_Supported is not 1: no answer to 5 inquiries")
                } else {
                    Outcome::fail(format!(
                        "the file says LSS_Supported={}, but {heard} of 5 inquiries were answered",
                        if s.dev.device_info.lss_supported.is_some() { "0" } else { "nothing" }
                    ))
                };
            }
            let mut problems = Vec::new();
            for (cs, sub, got) in answers {
                let Some(b) = got else {
                    problems.push(format!("no answer to 0x{cs:02X}"));
                    continue;
                };
                let value = if cs == 0x5E {
                    u64::from(b.get(1).copied().unwrap_or(0))
                } else {
                    le(b.get(1..5).unwrap_or(&[]))
                };
                let want = match sub {
                    Some(sub) => match s.read_u32(0x1018, sub) {
                        Ok(v) => u64::from(v),
                        Err(_) => continue,
                    },
                    None => u64::from(s.node.get()),
                };
                if value != want {
                    problems.push(format!("0x{cs:02X} answered 0x{value:08X}, want 0x{want:08X}"));
                }
            }
            if problems.is_empty() {
                Outcome::pass("identity and node-ID as 0x1018 and the node says")
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
}
