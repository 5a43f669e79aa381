//! The test bench of the worked-example tests: a master (odc's SDO client, generated
//! descriptors and PDO structs) wired to a device (odc's SDO server on a generated slave
//! dictionary), every frame on the wire logged, and the manual's frames to compare with.
#![allow(clippy::unwrap_used, clippy::expect_used, dead_code)] // test helpers; not every test uses all

use std::collections::VecDeque;

use odc::can::CanFrame;
use odc::cia402::{State, Statusword};
use odc::nmt::NmtCommand;
use odc::sdo::frame::{Init, Request, Response};
use odc::sdo::{Bus, Client, Server};
use odc::slave::ObjectDictionary;
use odc::{Entry, ObjValue, Pdo};

/// The SDO buffer size of the bench: the longest value of the examples (ServoOne's 100-byte
/// string) fits.
pub const N: usize = 128;

/// A frame as the manual prints it, and how much of it the manual defines.
#[derive(Clone, Debug)]
pub struct Printed {
    /// The frame.
    pub frame: CanFrame,
    /// Bytes to compare: all printed ones unless the manual says the rest is undefined.
    pub defined: usize,
    /// The manual's text, for messages.
    pub text: &'static str,
}

/// Parses the manual's notation `"601 / 23 01 14 01 01 03 00 04"` (CAN-ID, then data bytes,
/// all hexadecimal), or `"702 RTR"` for a remote frame. OCR mistakes are fixed in the transcription, never here.
pub fn printed(text: &'static str) -> Printed {
    // `"702 RTR"`: a remote frame (node guarding's request), which carries no data.
    if let Some(id) = text.strip_suffix(" RTR") {
        let id = u32::from_str_radix(id.trim(), 16).expect("hex CAN-ID");
        return Printed { frame: CanFrame::remote(id, 1).unwrap(), defined: 0, text };
    }
    let (id, data) = text.split_once('/').expect("`ID / bytes`");
    let id = u32::from_str_radix(id.trim(), 16).expect("hex CAN-ID");
    let bytes: Vec<u8> =
        data.split_whitespace().map(|b| u8::from_str_radix(b, 16).expect("hex byte")).collect();
    let frame = CanFrame::from_slice(id, &bytes).expect("at most 8 bytes");
    Printed { frame, defined: bytes.len(), text }
}

impl Printed {
    /// Only the first `n` bytes are defined (the manual's own table says the rest is not, or
    /// the print lost them).
    pub fn defined(mut self, n: usize) -> Self {
        self.defined = n;
        self
    }

    /// Whether `frame` is this frame in every defined byte (and has the printed CAN-ID).
    pub fn matches(&self, frame: &CanFrame) -> bool {
        let n = self.defined;
        frame.id() == self.frame.id()
            && frame.is_remote() == self.frame.is_remote()
            && frame.bytes().len() >= n
            && frame.bytes().get(..n) == self.frame.bytes().get(..n)
    }
}

/// Compares the frames on the wire with the manual's, one by one, and says which differ.
pub fn assert_same(wire: &[CanFrame], manual: &[Printed]) {
    let show = |f: &CanFrame| {
        let bytes: Vec<String> = f.bytes().iter().map(|b| format!("{b:02X}")).collect();
        format!("{:X} / {}", f.id(), bytes.join(" "))
    };
    for (i, (ours, theirs)) in wire.iter().zip(manual).enumerate() {
        assert!(
            theirs.matches(ours),
            "frame {}: built {}, the manual prints {} (compared bytes: {})",
            i + 1,
            show(ours),
            theirs.text,
            theirs.defined
        );
    }
    assert_eq!(
        wire.len(),
        manual.len(),
        "frames built: {:#?}",
        wire.iter().map(show).collect::<Vec<_>>()
    );
}

/// What the device side does besides answering SDOs: the wire loops every request through
/// the server on `od`.
pub struct Wire<D> {
    /// The device's object dictionary.
    pub od: D,
    /// The device's SDO server.
    pub server: Server<N>,
    /// Every frame, in order, both directions.
    pub log: Vec<CanFrame>,
    inbox: VecDeque<CanFrame>,
    now: u64,
}

impl<D: ObjectDictionary> Bus for Wire<D> {
    type Error = std::convert::Infallible;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
        self.log.push(*frame);
        if let Some(response) =
            self.server.handle(&mut self.od, frame, odc::time::Instant::from_millis(self.now))
        {
            self.log.push(response);
            self.inbox.push_back(response);
        }
        Ok(())
    }

    fn recv(&mut self, _deadline: odc::time::Instant) -> Result<Option<CanFrame>, Self::Error> {
        Ok(self.inbox.pop_front())
    }

    fn now(&mut self) -> odc::time::Instant {
        self.now += 1;
        odc::time::Instant::from_millis(self.now)
    }
}

/// Master and device on one wire.
pub struct Bench<D> {
    /// The master's SDO client.
    pub client: Client<N>,
    /// The wire with the device on it.
    pub wire: Wire<D>,
    /// The node id.
    pub node: odc::cob::NodeId,
}

impl<D: ObjectDictionary> Bench<D> {
    /// Node `node` with dictionary `od`.
    pub fn new(node: odc::cob::NodeId, od: D) -> Self {
        Bench {
            client: Client::new(node),
            wire: Wire {
                od,
                server: Server::new(node),
                log: Vec::new(),
                inbox: VecDeque::new(),
                now: 0,
            },
            node,
        }
    }

    /// An SDO write of a generated descriptor, by odc's client.
    pub fn write<T: ObjValue>(&mut self, entry: &Entry<T>, value: T) {
        self.client.write(&mut self.wire, entry, value).expect("the device accepts the write");
    }

    /// An SDO read of a generated descriptor.
    pub fn read<T: ObjValue>(&mut self, entry: &Entry<T>) -> T {
        self.client.read(&mut self.wire, entry).expect("the device answers the read")
    }

    /// An expedited SDO download without size indication (command byte 0x22), which odc's
    /// client never sends but some manuals do: built with odc's frame codec, the value
    /// zero-extended to 4 bytes, answered by the server (which takes the object's own size).
    pub fn write_unsized<T: ObjValue>(&mut self, entry: &Entry<T>, value: T) {
        let mut data = [0u8; 4];
        value.encode(&mut data).expect("a value of at most 4 bytes");
        let request =
            Request::InitiateDownload(entry.addr, Init::Expedited { data, len: 4, sized: false });
        self.wire
            .send(&CanFrame::standard(self.client.request_id(), request.encode()))
            .expect("sent");
        let response = self.wire.inbox.pop_front().expect("the server answers");
        assert_eq!(Response::decode(response.bytes()), Ok(Response::InitiateDownload(entry.addr)));
    }

    /// The frames the master sent to the device's SDO server (the examples that print
    /// requests only).
    pub fn requests(&self) -> Vec<CanFrame> {
        let id = self.client.request_id();
        self.wire.log.iter().filter(|f| f.id() == id.raw()).copied().collect()
    }

    /// The NMT command to every node (node 0), as the examples send it.
    pub fn nmt_all(&mut self, cmd: NmtCommand) {
        self.wire.log.push(CanFrame::from_slice(0, &cmd.frame(None)).expect("2 bytes"));
    }

    /// A PDO on the wire (either direction): its COB-ID for this node and its packed bytes.
    pub fn pdo<P: Pdo>(&mut self, cob_id: u32, pdo: &P) {
        let bytes = pdo.pack().expect("values fit their fields");
        let frame = CanFrame::from_slice(cob_id & 0x7FF, bytes.as_ref()).expect("at most 8 bytes");
        self.wire.log.push(frame);
    }

    /// Any other frame (EMCY, heartbeat).
    pub fn frame(&mut self, id: u32, bytes: &[u8]) {
        self.wire.log.push(CanFrame::from_slice(id, bytes).expect("at most 8 bytes"));
    }
}

/// A statusword: the state's bits from the profile, then the flags the manual's frame shows
/// (bit numbers, named where they are used).
pub fn status(state: State, flags: &[u32]) -> Statusword {
    flags.iter().fold(state.statusword(), |sw, &bit| sw.with_bit(bit, true))
}
