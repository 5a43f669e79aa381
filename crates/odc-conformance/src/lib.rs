//! Tests a live CANopen device against its device file and CiA 301/402, in the spirit of
//! CiA 310 (the CANopen conformance test plan), as far as it applies to what the file
//! declares: identity, every entry, the SDO protocol, NMT and error control, PDOs, EMCY, LSS
//! and a CiA 402 drive's state machine and modes.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let loaded = odc_pipeline::load("eds/lxm23a.eds".as_ref(), &odc_pipeline::Options::new())?;
//! let bus = odc::transport::tcp::TcpCan::connect("127.0.0.1:7000")?;
//! let node = odc::cob::NodeId::new(5).ok_or("node-ID")?;
//! let report = odc_conformance::run(loaded.device()?, node, bus, &odc_conformance::Options::default());
//! print!("{}", report.summary());
//! # Ok(())
//! # }
//! ```
//!
//! Each check names its clause and ends as pass, fail (with the frames of the check) or not
//! applicable (with why). A check restores what it writes; it resets the node (NMT) where the
//! clause is about resets, which brings back the values the device has stored, not the
//! file's. The one check that changes stored parameters (0x1011 "load") runs only with
//! [`Options::restore_defaults`].
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod cia402;
mod emcy;
mod entries;
mod identity;
mod lss;
mod nmt;
mod pdo;
mod report;
mod sdo;
mod session;

use std::fmt::Display;

use odc::cob::NodeId;
use odc::transport::Bus;
use odc_model::Device;
use serde::Serialize;

pub use report::Report;
use session::Session;

/// How the checks run.
#[derive(Clone, Debug)]
pub struct Options {
    /// How long to wait for an answer (SDO response, boot-up), in ms.
    pub timeout_ms: u64,
    /// How far the tester's receive time of a frame may be from its transmission, in ms: a
    /// heartbeat gap may differ from the period set, and a PDO gap fall short of the inhibit
    /// time, by this much. A tester on a shared host receives frames late, one at a time, so a
    /// single gap can look that much too long or too short.
    pub timing_tolerance_ms: u64,
    /// Run the 0x1011 "load" check: it restores the device's factory defaults, so the
    /// parameters it has stored are lost.
    pub restore_defaults: bool,
    /// How long the device may take to abort a transfer the client left (the SDO timeout
    /// check), in ms.
    pub sdo_timeout_ms: u64,
    /// Only the groups named (all when empty).
    pub groups: Vec<Group>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            timeout_ms: 1000,
            timing_tolerance_ms: 20,
            restore_defaults: false,
            sdo_timeout_ms: 2000,
            groups: Vec::new(),
        }
    }
}

/// The groups of checks, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Group {
    /// 0x1000, 0x1018 and `[DeviceInfo]`.
    Identity,
    /// Every entry of the file: exists, size, access, limits, defaults.
    Entries,
    /// The SDO protocol.
    Sdo,
    /// NMT and error control (boot-up, states, heartbeat, guarding).
    Nmt,
    /// PDO mapping and transmission.
    Pdo,
    /// Emergency messages and 0x1003.
    Emcy,
    /// Layer setting services (CiA 305).
    Lss,
    /// A CiA 402 drive.
    Cia402,
}

impl Group {
    /// Every group.
    pub const ALL: [Group; 8] = [
        Group::Identity,
        Group::Entries,
        Group::Sdo,
        Group::Nmt,
        Group::Pdo,
        Group::Emcy,
        Group::Lss,
        Group::Cia402,
    ];

    /// Its name (`identity`, `entries`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Group::Identity => "identity",
            Group::Entries => "entries",
            Group::Sdo => "sdo",
            Group::Nmt => "nmt",
            Group::Pdo => "pdo",
            Group::Emcy => "emcy",
            Group::Lss => "lss",
            Group::Cia402 => "cia402",
        }
    }

    /// The group of a name.
    pub fn from_name(name: &str) -> Option<Group> {
        Group::ALL.into_iter().find(|g| g.name().eq_ignore_ascii_case(name))
    }
}

/// How a check ended.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "result", rename_all = "snake_case")]
pub enum Outcome {
    /// The device did what the clause says.
    Pass {
        /// What was seen.
        detail: String,
    },
    /// It did not.
    Fail {
        /// What was wrong.
        reason: String,
        /// The frames of the check (`ms dir id [bytes]`), the first and last ones when many.
        frames: Vec<String>,
    },
    /// The clause does not apply to this device.
    NotApplicable {
        /// Why.
        why: String,
    },
}

impl Outcome {
    pub(crate) fn pass(detail: impl Into<String>) -> Self {
        Outcome::Pass { detail: detail.into() }
    }

    pub(crate) fn fail(reason: impl Into<String>) -> Self {
        Outcome::Fail { reason: reason.into(), frames: Vec::new() }
    }

    pub(crate) fn na(why: impl Into<String>) -> Self {
        Outcome::NotApplicable { why: why.into() }
    }

    /// A pass when `problems` is empty, else a fail listing them (the first 12).
    pub(crate) fn from_problems(problems: &[String], checked: usize, what: &str) -> Self {
        if checked == 0 {
            return Outcome::na(format!("the file has no {what}"));
        }
        if problems.is_empty() {
            return Outcome::pass(format!("{checked} {what} checked"));
        }
        let mut reason = format!("{} of {checked} {what}: ", problems.len());
        reason += &problems.iter().take(12).cloned().collect::<Vec<_>>().join("; ");
        if problems.len() > 12 {
            reason += &format!("; and {} more", problems.len() - 12);
        }
        Outcome::fail(reason)
    }
}

/// One check and how it ended.
#[derive(Clone, Debug, Serialize)]
pub struct CheckResult {
    /// Its identifier, `group.name`.
    pub id: &'static str,
    /// Its group.
    pub group: Group,
    /// The clause it tests (CiA 301, 305, 402).
    pub clause: &'static str,
    /// What it tests.
    pub title: &'static str,
    /// How it ended.
    #[serde(flatten)]
    pub outcome: Outcome,
}

/// Runs every check of `options.groups` (all when empty) on `node`, the device `device`
/// describes, over `bus`. Bus failures end as failed checks, never as a panic.
pub fn run<B>(device: &Device, node: NodeId, bus: B, options: &Options) -> Report
where
    B: Bus,
    B::Error: Display,
{
    let mut s = Session::new(device, node, bus, options);
    s.settle();
    // A node that does not answer at all would make every check wait out its timeouts (one
    // per entry): one result says so instead.
    if s.read(0x1000, 0) == Err(session::SdoFail::Timeout) {
        s.check("node.answers", Group::Identity, "CiA 301 7.2.4", "the node answers SDO", |_| {
            Outcome::fail(format!(
                "no answer to an SDO upload of 0x1000 at node {node}: is it on the bus, at \
                 this node-ID and bit rate, and not stopped?"
            ))
        });
        return s.finish();
    }
    for group in Group::ALL {
        if !options.groups.is_empty() && !options.groups.contains(&group) {
            continue;
        }
        match group {
            Group::Identity => identity::run(&mut s),
            Group::Entries => entries::run(&mut s),
            Group::Sdo => sdo::run(&mut s),
            Group::Nmt => nmt::run(&mut s),
            Group::Pdo => pdo::run(&mut s),
            Group::Emcy => emcy::run(&mut s),
            Group::Lss => lss::run(&mut s),
            Group::Cia402 => cia402::run(&mut s),
        }
    }
    s.finish()
}
