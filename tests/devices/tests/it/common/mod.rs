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

/// A frame as the manual prints it: its CAN-ID, its bytes, and the positions the manual
/// prints as placeholders (`xxh`, `-`, `CurveID`: written `..` in the transcription).
#[derive(Clone, Debug)]
pub struct Printed {
    /// The CAN-ID as printed.
    pub id: u32,
    /// Whether the manual prints a remote frame (node guarding's request).
    pub remote: bool,
    /// The data bytes as printed; `None` where the manual prints a placeholder.
    pub bytes: Vec<Option<u8>>,
    /// The manual's text, for messages and the records.
    pub text: &'static str,
    /// Why the frame on the wire does not count as reproduced (a test built or chose some of
    /// its bytes, or it differs from the print); `None`: compared exactly and counted.
    pub not_reproduced: Option<&'static str>,
}

/// Parses the manual's notation `"601 / 23 01 14 01 01 03 00 04"` (CAN-ID, then data bytes,
/// all hexadecimal; `..` where the manual prints a placeholder), or `"702 RTR"` for a remote
/// frame. OCR mistakes are fixed in the transcription, never here.
pub fn printed(text: &'static str) -> Printed {
    // `"702 RTR"`: a remote frame (node guarding's request), which carries no data.
    if let Some(id) = text.strip_suffix(" RTR") {
        let id = u32::from_str_radix(id.trim(), 16).expect("hex CAN-ID");
        return Printed { id, remote: true, bytes: Vec::new(), text, not_reproduced: None };
    }
    let (id, data) = text.split_once('/').expect("`ID / bytes`");
    let id = u32::from_str_radix(id.trim(), 16).expect("hex CAN-ID");
    let bytes: Vec<Option<u8>> = data
        .split_whitespace()
        .map(|b| (b != "..").then(|| u8::from_str_radix(b, 16).expect("hex byte")))
        .collect();
    assert!(bytes.len() <= 8, "{text}: more than 8 bytes");
    Printed { id, remote: false, bytes, text, not_reproduced: None }
}

impl Printed {
    /// The frame on the wire is not counted as reproduced, for `why` (recorded).
    pub fn not_reproduced(mut self, why: &'static str) -> Self {
        self.not_reproduced = Some(why);
        self
    }

    /// Whether `frame` is this frame exactly: the CAN-ID, remote or data, the length, and
    /// every byte the manual prints as a value.
    pub fn matches(&self, frame: &CanFrame) -> bool {
        frame.id() == self.id
            && frame.is_remote() == self.remote
            && frame.bytes().len() == self.bytes.len()
            && frame.bytes().iter().zip(&self.bytes).all(|(b, p)| p.is_none_or(|p| p == *b))
    }
}

/// Shows a frame as the transcriptions write it.
pub fn show(f: &CanFrame) -> String {
    if f.is_remote() {
        return format!("{:X} RTR", f.id());
    }
    let bytes: Vec<String> = f.bytes().iter().map(|b| format!("{b:02X}")).collect();
    format!("{:X} / {}", f.id(), bytes.join(" "))
}

/// The comparisons of one test with the manual's printed frames, kept as records: the
/// counts of `tests/devices/README.md` are made from them (`tests/table.rs`).
///
/// Each record is one printed frame: the test, where the manual prints it, whether it is
/// reproduced (`R`, compared exactly) or not (`N`, with the reason), the printed text and the
/// bytes on the wire. On drop (a test that passed), the records are compared with the test's
/// block in `records/<test file>.tsv`; with `ODC_RECORDS=write` that block is rewritten.
pub struct Records {
    /// The stem of the test file (`lenze`): its records file. Taken from the caller, since the
    /// files are modules of one test binary.
    file: &'static str,
    test: &'static str,
    lines: Vec<String>,
}

impl Records {
    /// The records of test function `test` of the calling test file.
    #[track_caller]
    pub fn new(test: &'static str) -> Self {
        let caller = std::panic::Location::caller().file();
        let file = std::path::Path::new(caller).file_stem().and_then(|s| s.to_str());
        Records { file: file.unwrap_or(caller), test, lines: Vec::new() }
    }

    /// Compares the frames library code put on the wire with the manual's, one by one, at
    /// `at` (the README row's key: section, figure or table): each reproduced one exactly.
    pub fn compare(&mut self, at: &'static str, wire: &[CanFrame], manual: &[Printed]) {
        for (i, (ours, theirs)) in wire.iter().zip(manual).enumerate() {
            if theirs.not_reproduced.is_none() {
                assert!(
                    theirs.matches(ours),
                    "{at}, frame {}: built {}, the manual prints {}",
                    i + 1,
                    show(ours),
                    theirs.text
                );
            }
        }
        assert_eq!(
            wire.len(),
            manual.len(),
            "{at}: frames built: {:#?}",
            wire.iter().map(show).collect::<Vec<_>>()
        );
        for (ours, theirs) in wire.iter().zip(manual) {
            self.push(at, theirs.text, &show(ours), theirs.not_reproduced);
        }
    }

    /// Printed frames no library code builds here, with the reason.
    pub fn printed_only(&mut self, at: &'static str, manual: &[&'static str], why: &'static str) {
        for text in manual {
            self.push(at, text, "-", Some(why));
        }
    }

    fn push(&mut self, at: &str, printed: &str, made: &str, why: Option<&str>) {
        let (kind, why) = match why {
            Some(why) => ("N", why),
            None => ("R", ""),
        };
        let line = format!("{}\t{at}\t{kind}\t{printed}\t{made}\t{why}", self.test);
        assert!(!line[self.test.len()..].contains('\n'), "one line per record");
        self.lines.push(line);
    }
}

/// Serialises the rewrites of the records files by the tests of the binary.
static RECORDS_FILE: std::sync::Mutex<()> = std::sync::Mutex::new(());

impl Drop for Records {
    fn drop(&mut self) {
        if std::thread::panicking() {
            return;
        }
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("records")
            .join(format!("{}.tsv", self.file));
        let _guard = RECORDS_FILE.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let prefix = format!("{}\t", self.test);
        let committed: Vec<&str> = text.lines().filter(|l| l.starts_with(&prefix)).collect();
        if std::env::var_os("ODC_RECORDS").is_some_and(|v| v == "write") {
            let mut all: Vec<String> =
                text.lines().filter(|l| !l.starts_with(&prefix)).map(str::to_owned).collect();
            all.extend(self.lines.iter().cloned());
            // Stable: by test, each test's records in the order it compared them.
            all.sort_by(|a, b| a.split('\t').next().cmp(&b.split('\t').next()));
            std::fs::create_dir_all(path.parent().expect("records/")).expect("records/");
            std::fs::write(&path, all.join("\n") + "\n").expect("records written");
        } else {
            assert_eq!(
                committed,
                self.lines,
                "{}: the test's comparisons and {} differ (rerun with ODC_RECORDS=write, then \
                 `ODC_RECORDS=write cargo test -p odc-tests-devices --test it table::`)",
                self.test,
                path.display()
            );
        }
    }
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
        let id = odc::cob::Function::Nmt.base().expect("NMT has a CAN-ID");
        self.wire.log.push(CanFrame::from_slice(id.into(), &cmd.frame(None)).expect("2 bytes"));
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

/// The bits a manual's table row prints, most significant first, for bit `numbers` ("0" and
/// "1" defined, anything else irrelevant: "X", and the "4" OCR slips of ServoOne's Table
/// 10.1): the mask of the defined bits and their value.
pub fn bit_row(bits: &str, numbers: &[u32]) -> (u16, u16) {
    let cells: Vec<&str> = bits.split_whitespace().collect();
    assert_eq!(cells.len(), numbers.len(), "{bits}");
    cells.iter().zip(numbers).fold((0, 0), |(mask, value), (cell, &n)| match *cell {
        "0" => (mask | 1 << n, value),
        "1" => (mask | 1 << n, value | 1 << n),
        _ => (mask, value),
    })
}

/// A manual's statusword table (state, the row's bits of 6041h for bit `numbers`) against
/// odc's CiA 402 state decode: odc's statusword of the state has the printed bits, and a
/// statusword with them decodes to the state whatever the irrelevant ones among `numbers`
/// are. A bit table, not frames: not counted.
pub fn statusword_table(table: &[(State, &str)], numbers: &[u32]) {
    let listed = numbers.iter().fold(0u16, |m, &n| m | 1 << n);
    for &(state, bits) in table {
        let (mask, value) = bit_row(bits, numbers);
        assert_eq!(state.statusword().bits() & mask, value, "{state:?}");
        assert_eq!(Statusword(value).state(), Some(state), "{bits}");
        assert_eq!(Statusword(value | (!mask & listed)).state(), Some(state), "{bits}");
    }
}

/// A manual's controlword command table (name, the row's bits 7, 3, 2, 1, 0 of 6040h, the
/// transitions CiA 402 gives the command) against odc's CiA 402 state machine: the command,
/// its irrelevant bits all clear and then all set, takes every one of those transitions.
/// The commands named in `clear_only` are compared with their irrelevant bits clear only.
/// A bit table, not frames: not counted.
pub fn controlword_table(table: &[(&str, &str, &[u8])], clear_only: &[&str]) {
    use odc::cia402::{Controlword, transition};
    let states = [
        State::NotReadyToSwitchOn,
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::FaultReactionActive,
        State::Fault,
    ];
    for &(name, bits, transitions) in table {
        let (mask, value) = bit_row(bits, &[7, 3, 2, 1, 0]);
        let forms: &[u16] = if clear_only.contains(&name) { &[0] } else { &[0, 0x8F] };
        for x in forms {
            let cw = Controlword(value | (x & !mask));
            for &n in transitions {
                let pairs: Vec<(State, State)> = states
                    .iter()
                    .flat_map(|&a| states.iter().map(move |&b| (a, b)))
                    .filter(|&(a, b)| transition(a, b) == Some(n))
                    .collect();
                assert!(!pairs.is_empty(), "transition {n}");
                for (from, to) in pairs {
                    assert_eq!(from.after(cw, true), to, "{name} ({cw:?}): transition {n}");
                }
            }
        }
    }
}
