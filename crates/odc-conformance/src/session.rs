//! The checks' view of the device: odc's master on the bus, a log of every frame (a failed
//! check shows its own), and the file's model.

use std::fmt::{self, Display};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

use odc::can::CanFrame;
use odc::cob::NodeId;
use odc::master::{Dir, Error, Master};
use odc::nmt::NmtCommand;
use odc::sdo::SdoError;
use odc::transport::Bus;
use odc_model::{Device, SubObject, Value};

use crate::{CheckResult, Group, Options, Outcome, Report};

/// A frame of the log: when (ms since the session began), which way, the frame.
pub(crate) type Logged = (u64, Dir, CanFrame);

/// Why an SDO transfer did not succeed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum SdoFail {
    /// The device aborted with this code.
    Abort(u32),
    /// No answer in time (the client aborted).
    Timeout,
    /// Anything else: the client's abort for a protocol error, the bus.
    Other(String),
}

impl Display for SdoFail {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SdoFail::Abort(c) => write!(f, "abort 0x{c:08X}"),
            SdoFail::Timeout => f.write_str("no answer"),
            SdoFail::Other(s) => f.write_str(s),
        }
    }
}

fn sdo_fail<E: Display>(e: Error<E>) -> SdoFail {
    match e {
        Error::Sdo { error: SdoError::Remote(a), .. } => SdoFail::Abort(a.to_u32()),
        // The master reports a missing SDO response as a timeout of its own (saying whether
        // the node was heard at all); a client-side abort 0x05040000 is the same.
        Error::Timeout { .. } => SdoFail::Timeout,
        Error::Sdo { error: SdoError::Local(odc::SdoAbort::Timeout), .. } => SdoFail::Timeout,
        other => SdoFail::Other(other.to_string()),
    }
}

pub(crate) struct Session<'d, B: Bus> {
    pub dev: &'d Device,
    pub node: NodeId,
    pub master: Master<B>,
    pub opt: &'d Options,
    log: Arc<Mutex<Vec<Logged>>>,
    results: Vec<CheckResult>,
}

impl<'d, B> Session<'d, B>
where
    B: Bus,
    B::Error: Display,
{
    pub fn new(dev: &'d Device, node: NodeId, bus: B, opt: &'d Options) -> Self {
        let mut master =
            Master::new(bus).with_timeout(odc::time::Duration::from_millis(opt.timeout_ms));
        let log = Arc::new(Mutex::new(Vec::new()));
        let start = Instant::now();
        let sink = Arc::clone(&log);
        master.observe(move |dir, frame| {
            let ms = u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX);
            sink.lock().unwrap_or_else(PoisonError::into_inner).push((ms, dir, *frame));
        });
        Session { dev, node, master, opt, log, results: Vec::new() }
    }

    pub fn finish(self) -> Report {
        Report::new(self.dev.name(), self.node.get(), self.results)
    }

    fn log_len(&self) -> usize {
        self.log.lock().unwrap_or_else(PoisonError::into_inner).len()
    }

    /// The frames logged since position `from`.
    pub fn frames_since(&self, from: usize) -> Vec<Logged> {
        let log = self.log.lock().unwrap_or_else(PoisonError::into_inner);
        log.get(from..).map(<[Logged]>::to_vec).unwrap_or_default()
    }

    /// Runs one check; a failure carries the frames the check sent and received.
    pub fn check(
        &mut self,
        id: &'static str,
        group: Group,
        clause: &'static str,
        title: &'static str,
        f: impl FnOnce(&mut Self) -> Outcome,
    ) {
        self.settle();
        let from = self.log_len();
        let mut outcome = f(self);
        if let Outcome::Fail { frames, .. } = &mut outcome {
            let all: Vec<String> = self.frames_since(from).iter().map(frame_text).collect();
            *frames = if all.len() > 40 {
                let mut v = all.get(..20).map(<[String]>::to_vec).unwrap_or_default();
                v.push(format!("... {} frames ...", all.len() - 40));
                v.extend(all.get(all.len() - 20..).map(<[String]>::to_vec).unwrap_or_default());
                v
            } else {
                all
            };
        }
        self.results.push(CheckResult { id, group, clause, title, outcome });
    }

    /// Hands out what the master queued (heartbeats and the like), so that a check starts
    /// from a quiet queue.
    pub fn settle(&mut self) {
        let now = self.master.now();
        while let Ok(Some(_)) = self.master.poll(now) {}
    }

    /// Receives for `ms` (the master's own services, SYNC and guarding, run meanwhile) and
    /// returns the frames received in that time.
    pub fn listen(&mut self, ms: u64) -> Vec<(u64, CanFrame)> {
        let from = self.log_len();
        let deadline = self.master.now().saturating_add(odc::time::Duration::from_millis(ms));
        while let Ok(Some(_)) = self.master.poll(deadline) {}
        self.frames_since(from)
            .into_iter()
            .filter(|(_, d, _)| *d == Dir::Received)
            .map(|(t, _, f)| (t, f))
            .collect()
    }

    // ---- SDO ----------------------------------------------------------------------------

    pub fn read(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, SdoFail> {
        self.master.upload(self.node, index, sub).map_err(sdo_fail)
    }

    pub fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoFail> {
        self.master.download(self.node, index, sub, data).map_err(sdo_fail)
    }

    pub fn read_u32(&mut self, index: u16, sub: u8) -> Result<u32, SdoFail> {
        let b = self.read(index, sub)?;
        let mut w = [0u8; 4];
        for (d, s) in w.iter_mut().zip(&b) {
            *d = *s;
        }
        Ok(u32::from_le_bytes(w))
    }

    /// The CAN-ID the device sends EMCY on: its 0x1014 (bits 0-10), else 0x80 + node-ID.
    pub fn emcy_id(&mut self) -> u32 {
        let own = self.node.emcy().raw();
        if self.dev.sub(0x1014, 0).is_none() {
            return own;
        }
        self.read_u32(0x1014, 0).map_or(own, |v| v & 0x7FF)
    }

    /// One request frame of the client's choice, and the server's answer.
    pub fn raw_sdo(&mut self, request: [u8; 8]) -> Result<Option<[u8; 8]>, String> {
        self.send(self.node.sdo_request().raw(), &request)?;
        self.raw_answer()
    }

    /// The next frame on the SDO response CAN-ID, within the timeout.
    pub fn raw_answer(&mut self) -> Result<Option<[u8; 8]>, String> {
        match self.master.recv_frame(odc::cob::CobId(self.node.sdo_response().raw())) {
            Ok(f) => Ok(Some(f.data())),
            Err(Error::Timeout { .. }) => Ok(None),
            Err(e) => Err(e.to_string()),
        }
    }

    pub fn send(&mut self, id: u32, data: &[u8]) -> Result<(), String> {
        let frame = CanFrame::from_slice(id, data).ok_or("a frame of more than 8 bytes")?;
        self.master.send(&frame).map_err(|e| e.to_string())
    }

    // ---- NMT ----------------------------------------------------------------------------

    pub fn nmt(&mut self, command: NmtCommand) -> Result<(), String> {
        self.master.nmt(command, self.node).map_err(|e| e.to_string())
    }

    /// A reset (node or communication), waited for until the boot-up.
    pub fn reset(&mut self, command: NmtCommand) -> Result<(), String> {
        self.nmt(command)?;
        self.master.wait_boot_up(self.node).map_err(|e| format!("after {command:?}: {e}"))
    }
}

impl<'d, B: Bus> Session<'d, B> {
    // ---- The file -----------------------------------------------------------------------

    pub fn sub(&self, index: u16, sub: u8) -> Option<&'d SubObject> {
        self.dev.sub(index, sub)
    }

    /// The bytes of the value the file gives an entry (DCF parameter value, else default),
    /// with `$NODEID` resolved.
    pub fn default_bytes(&self, s: &SubObject) -> Option<Vec<u8>> {
        let v = &s.initial_value()?.value;
        resolve_bytes(v, s, self.node)
    }
}

/// The bytes of `v` as the type of `s`, `$NODEID` resolved for `node`.
pub(crate) fn resolve_bytes(v: &Value, s: &SubObject, node: NodeId) -> Option<Vec<u8>> {
    let v = match v {
        Value::NodeIdPlus(n) => Value::Signed(n.checked_add(i64::from(node.get()))?),
        other => other.clone(),
    };
    odc_model::wire::encode(&v, s.data_type)
}

/// A frame as the report shows it: `ms dir id [bytes]`.
pub(crate) fn frame_text((ms, dir, f): &Logged) -> String {
    let dir = match dir {
        Dir::Sent => "->",
        Dir::Received => "<-",
    };
    if f.is_remote() {
        return format!("{ms:>6} ms {dir} {:03X} RTR len {}", f.id(), f.len());
    }
    let bytes: Vec<String> = f.bytes().iter().map(|b| format!("{b:02X}")).collect();
    format!("{ms:>6} ms {dir} {:03X} [{}]", f.id(), bytes.join(" "))
}

/// A little-endian number of at most 8 bytes.
pub(crate) fn le(bytes: &[u8]) -> u64 {
    bytes.iter().rev().fold(0, |acc, b| acc << 8 | u64::from(*b))
}
