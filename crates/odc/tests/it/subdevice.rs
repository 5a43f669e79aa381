//! `odc::ethercat::subdevice` on the generated slave dictionary of esi/servoone.xml, over an
//! ESC emulated here as far as the device side needs it (registers, mailbox sync managers,
//! AL event request), driven as a master would: state requests, CoE mailboxes, process data.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::ethercat::subdevice::{
    Application, Config, Describe, EntryDescription, Esc, ObjectDescription, SmSpec, SubDevice, al,
    foe,
};

mod servoone {
    odc_macros::include_device!("../../esi/servoone.xml", role = "slave");
}

/// An ESC: 4 KiB of registers and 4 KiB of process RAM, with the PDI's side effects on the
/// mailboxes (reading the last byte of SM0 empties it, writing the last byte of SM1 fills it)
/// and the AL event request.
struct TestEsc {
    mem: Vec<u8>,
}

const SM0: (u16, u16) = (0x1000, 128);
const SM1: (u16, u16) = (0x1080, 128);

impl TestEsc {
    fn new() -> Self {
        let mut mem = vec![0; 0x2000];
        mem[0x0006] = 4; // 4 KiB of process RAM
        mem[0x0130] = 1; // INIT
        Self { mem }
    }
    /// The last byte of sync manager `n`'s area.
    fn last(&self, n: u16) -> u16 {
        self.u16(0x800 + 8 * n) + self.u16(0x802 + 8 * n) - 1
    }
    fn u16(&self, a: u16) -> u16 {
        u16::from_le_bytes([self.mem[a as usize], self.mem[a as usize + 1]])
    }
    fn set(&mut self, a: u16, b: &[u8]) {
        self.mem[a as usize..a as usize + b.len()].copy_from_slice(b);
    }
    fn event(&mut self, bit: u32) {
        let ev = u32::from_le_bytes(self.mem[0x220..0x224].try_into().unwrap()) | 1 << bit;
        self.set(0x220, &ev.to_le_bytes());
    }
    fn clear(&mut self, bit: u32) {
        let ev = u32::from_le_bytes(self.mem[0x220..0x224].try_into().unwrap()) & !(1 << bit);
        self.set(0x220, &ev.to_le_bytes());
    }
    fn sm(&mut self, n: u16, start: u16, len: u16, control: u8, enable: bool) {
        let mut r = [0u8; 8];
        r[..2].copy_from_slice(&start.to_le_bytes());
        r[2..4].copy_from_slice(&len.to_le_bytes());
        r[4] = control;
        r[6] = u8::from(enable);
        self.set(0x800 + 8 * n, &r);
    }
    fn mailboxes(&mut self) {
        self.sm(0, SM0.0, SM0.1, 0x26, true);
        self.sm(1, SM1.0, SM1.1, 0x22, true);
    }
    /// The master requests `state`.
    fn request(&mut self, state: u8) {
        self.set(0x120, &[state, 0]);
        self.event(0);
    }
    /// The master writes a mailbox: header, `data`, zeros to the end.
    fn send(&mut self, kind: u8, data: &[u8]) {
        let mut m = vec![0u8; SM0.1 as usize];
        m[..2].copy_from_slice(&(data.len() as u16).to_le_bytes());
        m[5] = kind;
        m[6..6 + data.len()].copy_from_slice(data);
        self.set(SM0.0, &m);
        self.mem[0x805] |= 0x08;
        self.event(8);
    }
    /// The master reads the read mailbox, if full: (type, data).
    fn receive(&mut self) -> Option<(u8, Vec<u8>)> {
        if self.mem[0x80D] & 0x08 == 0 {
            return None;
        }
        let at = SM1.0 as usize;
        let len = self.u16(SM1.0) as usize;
        let out = (self.mem[at + 5] & 0x0F, self.mem[at + 6..at + 6 + len].to_vec());
        self.mem[0x80D] &= !0x08;
        self.event(9);
        Some(out)
    }
}

impl Esc for TestEsc {
    type Error = core::convert::Infallible;
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        let r = addr as usize..addr as usize + buf.len();
        buf.copy_from_slice(&self.mem[r.clone()]);
        if r.contains(&0x120) {
            self.clear(0);
        }
        if r.contains(&(self.last(0) as usize)) {
            self.mem[0x805] &= !0x08;
            self.clear(8);
        }
        if r.contains(&0x80D) {
            self.clear(9);
        }
        Ok(())
    }
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        self.set(addr, data);
        let r = addr as usize..addr as usize + data.len();
        if r.contains(&(self.last(1) as usize)) {
            self.mem[0x80D] |= 0x08;
        }
        Ok(())
    }
}

const SMS: [SmSpec; 4] = [
    SmSpec { number: 0, kind: al::MBOX_OUT, min: 34, max: 256, control: 0x26 },
    SmSpec { number: 1, kind: al::MBOX_IN, min: 34, max: 256, control: 0x22 },
    SmSpec { number: 2, kind: al::OUTPUTS, min: 0, max: 32, control: 0x64 },
    SmSpec { number: 3, kind: al::INPUTS, min: 0, max: 32, control: 0x20 },
];

/// Two objects to describe: enough for the lists and their fragments.
struct Two;
impl Describe for Two {
    fn object_at(&self, pos: usize) -> Option<ObjectDescription<'_>> {
        let index = *[0x1000u16, 0x6040].get(pos)?;
        self.object(index)
    }
    fn object(&self, index: u16) -> Option<ObjectDescription<'_>> {
        let (name, lists) = match index {
            0x1000 => ("Device type", 0),
            0x6040 => ("Controlword", 1 << 2),
            _ => return None,
        };
        Some(ObjectDescription { index, data_type: 7, max_sub: 0, code: 7, name, lists })
    }
    fn entry(&self, index: u16, sub: u8) -> Option<EntryDescription<'_>> {
        (index == 0x6040 && sub == 0).then_some(EntryDescription {
            data_type: 6,
            bits: 16,
            access: 0x3F | 1 << 6,
            name: "Controlword",
        })
    }
}

/// An application with one file, "fw", to write and read over FoE.
#[derive(Default)]
struct Files {
    file: Vec<u8>,
    closed: Vec<bool>,
}

impl Application<servoone::slave::Dictionary> for Files {
    fn foe_open_write(&mut self, name: &[u8], password: u32) -> Result<(), u32> {
        match (name, password) {
            (b"fw", 0x1234) => {
                self.file.clear();
                Ok(())
            }
            (b"fw", _) => Err(foe::error::ACCESS_DENIED),
            _ => Err(foe::error::NOT_FOUND),
        }
    }
    fn foe_write(&mut self, offset: u32, data: &[u8]) -> Result<(), u32> {
        assert_eq!(offset as usize, self.file.len());
        self.file.extend_from_slice(data);
        Ok(())
    }
    fn foe_open_read(&mut self, name: &[u8], _: u32) -> Result<(), u32> {
        if name == b"fw" { Ok(()) } else { Err(foe::error::NOT_FOUND) }
    }
    fn foe_read(&mut self, offset: u32, buf: &mut [u8]) -> Result<usize, u32> {
        let rest = self.file.get(offset as usize..).unwrap_or(&[]);
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        Ok(n)
    }
    fn foe_close(&mut self, write: bool) -> Result<(), u32> {
        self.closed.push(write);
        Ok(())
    }
}

struct Device {
    esc: TestEsc,
    stack: SubDevice<128, 256, 16>,
    od: servoone::slave::Dictionary,
    app: Files,
}

impl Device {
    fn new() -> Self {
        let mut esc = TestEsc::new();
        esc.mailboxes();
        Self {
            esc,
            stack: SubDevice::new(),
            od: servoone::slave::Dictionary::new(None),
            app: Files::default(),
        }
    }
    fn poll(&mut self) {
        let cfg = Config {
            sync_managers: &SMS,
            fixed: &[],
            coe: true,
            complete_access: true,
            boot: false,
            foe: true,
            describe: Some(&Two),
        };
        let Ok(()) = self.stack.poll(&cfg, &mut self.esc, &mut self.od, &mut self.app);
    }
    fn cycle(&mut self) {
        let cfg = Config {
            sync_managers: &SMS,
            fixed: &[],
            coe: true,
            complete_access: true,
            boot: false,
            foe: false,
            describe: None,
        };
        let Ok(()) = self.stack.cycle(&cfg, &mut self.esc, &mut self.od, &mut self.app);
    }
    fn go(&mut self, state: u8) -> (u16, u16) {
        self.esc.request(state);
        self.poll();
        (self.esc.u16(0x130), self.esc.u16(0x134))
    }
    /// One CoE request and its reply's CoE data.
    fn coe(&mut self, data: &[u8]) -> Vec<u8> {
        self.esc.send(3, data);
        self.poll();
        let (kind, reply) = self.esc.receive().expect("a reply");
        assert_eq!(kind, 3);
        self.poll();
        reply
    }
    fn upload(&mut self, index: u16, sub: u8) -> Vec<u8> {
        let i = index.to_le_bytes();
        self.coe(&[0x00, 0x20, 0x40, i[0], i[1], sub, 0, 0, 0, 0])
    }
    fn download(&mut self, index: u16, sub: u8, v: &[u8]) -> Vec<u8> {
        let i = index.to_le_bytes();
        let n = 4 - v.len() as u8;
        let mut d = vec![0x00, 0x20, 0x23 | n << 2, i[0], i[1], sub, 0, 0, 0, 0];
        d[6..6 + v.len()].copy_from_slice(v);
        self.coe(&d)
    }
}

#[test]
fn al_states_and_their_codes() {
    let mut d = Device::new();
    // INIT → SAFE-OP skips PRE-OP: 0x0011, error flag (bit 4), stays in INIT.
    assert_eq!(d.go(4), (0x0011, 0x0011));
    // Error set: a request upwards without acknowledgement is not taken.
    assert_eq!(d.go(2), (0x0011, 0x0011));
    // Acknowledged (bit 4) PRE-OP.
    assert_eq!(d.go(0x12), (0x0002, 0));
    assert_eq!(d.stack.state(), 2);
    // Back to INIT; mailbox SM1 now outside the process RAM (4 KiB from 0x1000): 0x0016.
    assert_eq!(d.go(1), (0x0001, 0));
    d.esc.sm(1, 0x1FF0, 128, 0x22, true);
    assert_eq!(d.go(2), (0x0011, 0x0016));
    // BOOT on a device without bootstrap: 0x0013.
    assert_eq!(d.go(0x13), (0x0011, 0x0013));
}

#[test]
fn sdo_upload_download_and_aborts() {
    let mut d = Device::new();
    d.go(2);
    // 0x1000, expedited: command 0x43, the ESI's default 0x00000192.
    let r = d.upload(0x1000, 0);
    assert_eq!(r, [0x00, 0x30, 0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x00, 0x00]);
    // A write to it: abort 0x06010002 under service 2 (SDO request), command 0x80.
    let r = d.download(0x1000, 0, &[1, 2, 3, 4]);
    assert_eq!(r, [0x00, 0x20, 0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06]);
    // No such object: 0x06020000.
    let r = d.upload(0x5FFF, 0);
    assert_eq!(&r[6..], &[0x00, 0x00, 0x02, 0x06]);
    // Controlword, 2 bytes expedited (n = 2): stored.
    let r = d.download(0x6040, 0, &[0x0F, 0x00]);
    assert_eq!(r, [0x00, 0x30, 0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(d.od.get(servoone::od::CONTROLWORD).map(|c| c.0), Ok(0x000F));
    // A mailbox of another protocol (EoE, 2): mailbox error 0x0002.
    d.esc.send(2, &[0; 4]);
    d.poll();
    assert_eq!(d.esc.receive(), Some((0, vec![0x01, 0x00, 0x02, 0x00])));
}

#[test]
fn segmented_transfers_both_ways() {
    let mut d = Device::new();
    d.go(2);
    // A complete-access download of 0x1600 from sub-index 0 (count 2 as 16 bits, then two
    // mapping values): 10 bytes, the first 4 in the initiate, 6 in one last segment.
    let mut value = vec![2u8, 0];
    value.extend(0x6040_0010u32.to_le_bytes());
    value.extend(0x6060_0008u32.to_le_bytes());
    let mut init = vec![0x00, 0x20, 0x31, 0x00, 0x16, 0x00, 10, 0, 0, 0];
    init.extend(&value[..4]);
    let r = d.coe(&init);
    assert_eq!(r, [0x00, 0x30, 0x60, 0x00, 0x16, 0x00, 0, 0, 0, 0]);
    // Segment: toggle 0, 7 − 6 = 1 byte unused, last.
    let mut seg = vec![0x00, 0x20, 0x01 << 1 | 1];
    seg.extend(&value[4..]);
    seg.push(0);
    let r = d.coe(&seg);
    assert_eq!(&r[..3], &[0x00, 0x30, 0x20]);
    let mut b = [0u8; 4];
    assert_eq!(d.od.read(0x1600, 0, &mut b), Ok(1));
    assert_eq!(b[0], 2);
    assert_eq!(d.od.read(0x1600, 2, &mut b), Ok(4));
    assert_eq!(b, 0x6060_0008u32.to_le_bytes());
    // Fill all 8 entries, then upload the whole object (2 + 32 bytes) through a read mailbox
    // of 34 bytes (28 of CoE data): 18 bytes in the initiate, the rest in segments.
    d.download(0x1600, 0, &[0]);
    for sub in 3..=8u8 {
        d.download(0x1600, sub, &0x6040_0010u32.to_le_bytes());
    }
    d.download(0x1600, 0, &[8]);
    d.esc.sm(1, SM1.0, 34, 0x22, true);
    let r = d.coe(&[0x00, 0x20, 0x50, 0x00, 0x16, 0x00, 0, 0, 0, 0]);
    assert_eq!(r[2], 0x51, "normal upload with complete access");
    assert_eq!(u32::from_le_bytes(r[6..10].try_into().unwrap()), 34);
    let mut got = r[10..].to_vec();
    let mut toggle = 0u8;
    loop {
        let r = d.coe(&[0x00, 0x20, 0x60 | toggle << 4, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(r[2] >> 4 & 1, toggle);
        let unused = usize::from(r[2] >> 1 & 7);
        let data = &r[3..];
        // Short segments are padded to 7 bytes and say how many are unused.
        let n = if data.len() == 7 { 7 - unused } else { data.len() };
        got.extend_from_slice(&data[..n]);
        toggle ^= 1;
        if r[2] & 1 != 0 {
            break;
        }
    }
    let mut want = vec![8u8, 0];
    for sub in 1..=8u8 {
        d.od.read(0x1600, sub, &mut b).unwrap();
        want.extend_from_slice(&b);
    }
    assert_eq!(got, want);
    // A segment after the transfer ended: abort 0x05040001 (command not valid).
    let r = d.coe(&[0x00, 0x20, 0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!((r[2], &r[6..10]), (0x80, &0x0504_0001u32.to_le_bytes()[..]));
}

#[test]
fn a_mapping_made_in_pre_op_carries_process_data_in_op() {
    let mut d = Device::new();
    d.go(2);
    // RxPDO 0x1600: the controlword; TxPDO 0x1A00: the statusword; assigned to SM2, SM3.
    for (index, sub, v) in [
        (0x1600, 0, vec![0]),
        (0x1600, 1, 0x6040_0010u32.to_le_bytes().to_vec()),
        (0x1600, 0, vec![1]),
        (0x1A00, 0, vec![0]),
        (0x1A00, 1, 0x6041_0010u32.to_le_bytes().to_vec()),
        (0x1A00, 0, vec![1]),
        (0x1C12, 0, vec![0]),
        (0x1C12, 1, 0x1600u16.to_le_bytes().to_vec()),
        (0x1C12, 0, vec![1]),
        (0x1C13, 0, vec![0]),
        (0x1C13, 1, 0x1A00u16.to_le_bytes().to_vec()),
        (0x1C13, 0, vec![1]),
    ] {
        let r = d.download(index, sub, &v);
        assert_eq!(r[2], 0x60, "{index:04X}:{sub}: {r:02X?}");
    }
    // A mapping entry of an object the dictionary does not have: 0x06040041.
    d.download(0x1600, 0, &[0]);
    let r = d.download(0x1600, 2, &0x5FFF_0010u32.to_le_bytes());
    assert_eq!(&r[6..10], &0x0604_0041u32.to_le_bytes());
    d.download(0x1600, 0, &[1]);
    // SM2 of the wrong length: 0x001D.
    d.esc.sm(2, 0x1100, 4, 0x64, true);
    d.esc.sm(3, 0x1180, 2, 0x20, true);
    assert_eq!(d.go(4), (0x0012, 0x001D));
    d.esc.sm(2, 0x1100, 2, 0x64, true);
    assert_eq!(d.go(0x14), (0x0004, 0));
    // In SAFE-OP the mapping is fixed: a write to it is refused (0x08000022).
    let r = d.download(0x1C12, 0, &[0]);
    assert_eq!(&r[6..10], &0x0800_0022u32.to_le_bytes());
    assert_eq!(d.go(8), (0x0008, 0));
    // A cycle: the master's controlword into the dictionary, the statusword out.
    d.esc.set(0x1100, &0x000Fu16.to_le_bytes());
    d.od.set(servoone::od::STATUSWORD, odc::cia402::Statusword(0x0237)).unwrap();
    d.cycle();
    assert_eq!(d.od.get(servoone::od::CONTROLWORD).map(|c| c.0), Ok(0x000F));
    assert_eq!(d.esc.u16(0x1180), 0x0237);
    assert_eq!(d.stack.mapped().len(), 2);
}

/// A mapping that names an object the dictionary does not have (an ESI's mapping default can:
/// SDO writes cannot) is refused at SAFE-OP with the code ETG.1000.6 Table 11 gives it:
/// 0x0025 invalid output mapping, 0x0024 invalid input mapping; not 0x001D/0x001E, which say
/// the sync manager disagrees with a mapping the device could serve.
#[test]
fn a_mapping_of_a_missing_object_is_an_invalid_mapping() {
    use odc::slave::Storage;
    for (map, assign, sm, want) in [(0x1600u16, 0x1C12, 2u16, 0x0025), (0x1A00, 0x1C13, 3, 0x0024)]
    {
        let mut d = Device::new();
        d.go(2);
        for (index, sub, v) in [
            (map, 0, vec![0]),
            (assign, 0, vec![0]),
            (assign, 1, map.to_le_bytes().to_vec()),
            (assign, 0, vec![1]),
        ] {
            let r = d.download(index, sub, &v);
            assert_eq!(r[2], 0x60, "{index:04X}:{sub}: {r:02X?}");
        }
        // As a dictionary loaded with such a default holds it: 0x5FFF:00, 16 bits.
        d.od.raw_mut(map, 1).unwrap().copy_from_slice(&0x5FFF_0010u32.to_le_bytes());
        d.od.raw_mut(map, 0).unwrap()[0] = 1;
        let control = if sm == 2 { 0x64 } else { 0x20 };
        d.esc.sm(sm, 0x1100, 2, control, true);
        assert_eq!(d.go(4), (0x0012, want), "{map:04X}");
    }
}

#[test]
fn sdo_information_in_fragments_and_emergencies() {
    let mut d = Device::new();
    d.go(2);
    // Get OD List, all objects: 0x1000, 0x6040.
    let r = d.coe(&[0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00]);
    assert_eq!(r, [0x00, 0x80, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x10, 0x40, 0x60]);
    // Get OD of 0x6040 with a mailbox of 16 bytes (10 of CoE data): name in fragments.
    d.esc.sm(1, SM1.0, 16, 0x22, true);
    d.esc.send(3, &[0x00, 0x80, 0x03, 0x00, 0x00, 0x00, 0x40, 0x60]);
    d.poll();
    let mut payload = Vec::new();
    let mut left = Vec::new();
    while let Some((_, r)) = d.esc.receive() {
        assert_eq!(&r[..2], &[0x00, 0x80]);
        left.push(u16::from_le_bytes([r[4], r[5]]));
        payload.extend_from_slice(&r[6..]);
        d.poll();
    }
    // 6 bytes of description + "Controlword" (11) = 17 bytes, 4 per fragment: 5 fragments.
    assert_eq!(left, [4, 3, 2, 1, 0]);
    assert_eq!(&payload[..6], &[0x40, 0x60, 7, 0, 0, 7]);
    assert_eq!(&payload[6..17], b"Controlword");
    // An emergency goes out when the read mailbox is free: CoE service 1.
    d.esc.sm(1, SM1.0, SM1.1, 0x22, true);
    d.stack.emergency(0x8130, 0x11, [1, 2, 3, 4, 5]);
    d.poll();
    let (kind, r) = d.esc.receive().unwrap();
    assert_eq!(kind, 3);
    assert_eq!(r, [0x00, 0x10, 0x30, 0x81, 0x11, 1, 2, 3, 4, 5]);
}

/// One FoE mailbox and its reply: (opcode, u32, data).
fn foe_exchange(d: &mut Device, request: &[u8]) -> (u8, u32, Vec<u8>) {
    d.esc.send(4, request);
    d.poll();
    let (kind, r) = d.esc.receive().expect("an FoE reply");
    assert_eq!(kind, 4);
    d.poll();
    (r[0], u32::from_le_bytes(r[2..6].try_into().unwrap()), r[6..].to_vec())
}

#[test]
fn foe_writes_and_reads_a_file_in_packets() {
    let mut d = Device::new();
    d.go(2);
    // A write request with the wrong password: error 0x8002 (access denied).
    let mut wrq = vec![2, 0];
    wrq.extend(0x9999u32.to_le_bytes());
    wrq.extend(b"fw");
    let (op, code, _) = foe_exchange(&mut d, &wrq);
    assert_eq!((op, code), (5, 0x8002));
    // The right one: ack 0, then 250 bytes in packets of 116 (128-byte mailbox less the
    // mailbox and FoE headers): 116, 116, 18, each acknowledged with its number.
    wrq[2..6].copy_from_slice(&0x1234u32.to_le_bytes());
    let (op, n, _) = foe_exchange(&mut d, &wrq);
    assert_eq!((op, n), (4, 0));
    let file: Vec<u8> = (0..250u32).map(|i| (i * 7) as u8).collect();
    for (k, chunk) in file.chunks(116).enumerate() {
        let mut data = vec![3, 0];
        data.extend((k as u32 + 1).to_le_bytes());
        data.extend(chunk);
        let (op, n, _) = foe_exchange(&mut d, &data);
        assert_eq!((op, n), (4, k as u32 + 1));
    }
    assert_eq!(d.app.file, file);
    assert_eq!(d.app.closed, [true]);
    // Read it back: data packets 1, 2, 3 of 116, 116, 18 bytes, each after the ack of the
    // one before; the ack of the short last one ends the transfer (no reply).
    let mut rrq = vec![1, 0, 0, 0, 0, 0];
    rrq.extend(b"fw");
    let (mut op, mut n, mut data) = foe_exchange(&mut d, &rrq);
    let mut got = Vec::new();
    loop {
        assert_eq!(op, 3);
        got.extend_from_slice(&data);
        let mut ack = vec![4, 0];
        ack.extend(n.to_le_bytes());
        if data.len() < 116 {
            d.esc.send(4, &ack);
            d.poll();
            assert_eq!(d.esc.receive(), None);
            break;
        }
        (op, n, data) = foe_exchange(&mut d, &ack);
    }
    assert_eq!(got, file);
    assert_eq!(d.app.closed, [true, false]);
    // A file that is not there: 0x8001.
    let mut rrq = vec![1, 0, 0, 0, 0, 0];
    rrq.extend(b"boot.bin");
    let (op, code, _) = foe_exchange(&mut d, &rrq);
    assert_eq!((op, code), (5, 0x8001));
}
