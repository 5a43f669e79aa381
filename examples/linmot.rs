//! A LinMot E1200 on a simulated CAN bus: `cargo run --example linmot`.
//!
//! The E1200 has no CiA 402: it runs LinMot's own control word and motion command interface
//! (manual 7.1). Both ends run code generated from `eds/linmot-e1200.eds`:
//! - the master configures TxPDO 4 by UPID (manual 9.1.3) through the generated descriptors,
//!   reads the UPIDs' RAM values through the generated UPID scheme (`upid::U1CA4_RAM`, …),
//!   starts the node, and runs the manual's control word sequence: homing (083Fh), operational
//!   (003Fh), then the motion command "VAI 16Bit Go To Pos" (0901h) to 50 mm, sending SYNCs
//!   until the actual position is there;
//! - the drive is a simulation around the generated slave dictionary: SDO through odc's
//!   server, TxPDO 4 mapped from the UPIDs the master wrote (its mapping entries in 1A03h,
//!   its data read from the UPID objects 2000h + UPID of the dictionary).
//!
//! The manual gives the layout of RxPDO 1/2 and TxPDO 1 (Control Word, MC Header, MC
//! parameter bytes; Status Word, State Var, Actual Position) but no objects for these built-in
//! items, so the device file cannot map them; the overlay beside it declares them
//! (`[[process-data]]`) and the generated module `process` has their structs. The manual does
//! not give the bits of Status Word and State Var (they are in LinMot's motion control software
//! manual): the simulated drive echoes the control word it runs in Status Word, leaves State
//! Var 0, and reports Actual Position in the motion command's unit (0.1 mm).

use std::thread;
use std::time::Duration;

use odc::can::CanFrame;
use odc::master::Master;
use odc::nmt::{NmtCommand, NmtState};
use odc::sdo::Server;
use odc::{MappingEntry, ObjectAddr};
use odc_examples::Error;
use odc_examples::bus::{self, Closed, Port};
use odc_examples::step;

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod linmot_e1200 {
    odc::include_od!("linmot_e1200");
}
use linmot_e1200::process::{RxPdo1, RxPdo2, TxPdo1};
use linmot_e1200::{od, slave, upid};

/// The node id parameter's default (manual 4.3: 63).
const NODE: odc::cob::NodeId = odc::node_id!(63);

/// The motion command "VAI 16Bit Go To Pos" (090xh; x is the count nibble).
const VAI_GO_TO_POS: u16 = 0x0900;

/// TxPDO 4 as the PLC maps it after 9.1.3: the placeholders 4F08h sub 7, 8 (2 bytes) and 9
/// (4 bytes), typed as the UPIDs behind them.
#[derive(Clone, Copy, Debug, PartialEq, odc::Pdo)]
struct TxPdo4 {
    #[pdo(index = 0x4F08, sub = 7)]
    analog_voltage: u16,
    #[pdo(index = 0x4F08, sub = 8)]
    diff_analog_voltage: i16,
    #[pdo(index = 0x4F08, sub = 9)]
    difference_velocity: i32,
}

/// The simulated E1200.
struct LinMot {
    od: slave::Dictionary,
    server: Server<64>,
    nmt: NmtState,
    rx1: RxPdo1,
    rx2: RxPdo2,
    control_word: u16,
    count: u16,
    position: i32,
    target: i32,
    speed: i32,
}

impl LinMot {
    fn new() -> Self {
        let mut od = slave::Dictionary::new(NODE);
        // What the drive measures (the dictionary has every UPID entry: these cannot fail).
        let _ = od.set(upid::U1CA4_RAM, 4500);
        let _ = od.set(upid::U1CA6_RAM, -120);
        let _ = od.set(upid::U1B91_RAM, 0);
        LinMot {
            od,
            server: Server::new(NODE),
            nmt: NmtState::PreOperational,
            rx1: RxPdo1::default(),
            rx2: RxPdo2::default(),
            control_word: 0,
            count: 0,
            position: 0,
            target: 0,
            speed: 0,
        }
    }

    fn run(mut self, port: &Port) -> Result<(), Closed> {
        port.send(CanFrame::from_slice(NODE.error_control().raw(), &[0]).ok_or(Closed)?)?;
        loop {
            match port.recv_timeout(Duration::from_secs(1)) {
                Ok(Some(frame)) => {
                    for out in self.handle(&frame) {
                        port.send(out)?;
                    }
                }
                Ok(None) => {}
                Err(Closed) => return Ok(()),
            }
        }
    }

    fn handle(&mut self, frame: &CanFrame) -> Vec<CanFrame> {
        match frame.id() {
            0x000 => {
                if let [cs, n] = *frame.bytes()
                    && (n == 0 || n == NODE.get())
                    && cs == NmtCommand::Start as u8
                {
                    self.nmt = NmtState::Operational;
                }
                Vec::new()
            }
            0x080 if self.nmt == NmtState::Operational => self.sync(),
            id if id == self.server.request_id().raw() => {
                let answer =
                    self.server.handle(&mut self.od, frame, odc::time::Instant::from_millis(0));
                self.map_upids();
                answer.into_iter().collect()
            }
            // RPDOs of the default mapping (transmission type 1): taken at the next SYNC.
            id if id == RxPdo1::cob_id(NODE) => {
                self.rx1 = RxPdo1::unpack(frame.bytes()).unwrap_or(self.rx1);
                Vec::new()
            }
            id if id == RxPdo2::cob_id(NODE) => {
                self.rx2 = RxPdo2::unpack(frame.bytes()).unwrap_or(self.rx2);
                Vec::new()
            }
            _ => Vec::new(),
        }
    }

    /// TPDO 4's CAN-ID (1803h sub 1) while it is valid, and its mapping (1A03h), as the PLC
    /// left them.
    fn tpdo4(&self) -> Option<(u32, Vec<MappingEntry>)> {
        let read = |index, sub| {
            let mut le = [0u8; 4];
            let n = self.od.read(index, sub, &mut le).ok()?;
            (n <= 4).then(|| u32::from_le_bytes(le))
        };
        let cob = odc::cob::CobId(read(0x1803, 1)?);
        if !cob.is_valid() || cob.is_extended() {
            return None;
        }
        let count = u8::try_from(read(0x1A03, 0)?).ok()?;
        let entries = (1..=count).map(|sub| read(0x1A03, sub).map(MappingEntry::from_u32));
        Some((cob.can_id() & 0x7FF, entries.collect::<Option<_>>()?))
    }

    /// The UPIDs of TPDO 4 (4F08h sub 1..4), as the PLC set them.
    fn upids(&self) -> [u16; 4] {
        use od::tpdo4_upid_mapping::{TPDO4_UPIDS_1, TPDO4_UPIDS_2, TPDO4_UPIDS_3, TPDO4_UPIDS_4};
        [TPDO4_UPIDS_1, TPDO4_UPIDS_2, TPDO4_UPIDS_3, TPDO4_UPIDS_4]
            .map(|entry| self.od.get(entry).unwrap_or_default())
    }

    /// "The controller automatically maps those parameters to the PDOs" (9.1.1): 1A03h gets one
    /// entry per UPID of 4F08h sub 1..4, pointing at that sub-index with the UPID's bit length,
    /// which the UPID's object (2000h + UPID) gives.
    fn map_upids(&mut self) {
        let mut n = 0u8;
        for (sub, id) in (1..).zip(self.upids()) {
            let Some(ram) = upid::param(id, upid::Op::Ram) else { continue };
            let Some(bits) = upid::lookup(ram).and_then(|e| e.data_type.bits()) else { continue };
            n += 1;
            let entry = MappingEntry::new(0x4F08, sub, u8::try_from(bits).unwrap_or(32));
            let _ = self.od.write(0x1A03, n, &entry.to_u32().to_le_bytes());
        }
        let _ = self.od.write(0x1A03, 0, &[n]);
    }

    /// One SYNC: take the RPDOs, run the control word and a new motion command, move, and
    /// send the TPDOs.
    fn sync(&mut self) -> Vec<CanFrame> {
        let control_word = self.rx1.control_word;
        if control_word != self.control_word && control_word & 0x0800 != 0 {
            // Homing (7.1: Control Word 083Fh): this simulation's axis is homed at once.
            self.position = 0;
            self.target = 0;
        }
        self.control_word = control_word;
        let header = self.rx1.mc_header;
        // A command runs when its count nibble changes (5.1). VAI 16Bit Go To Pos: parameter
        // bytes 0..1 the position (0.1 mm), 2..3 the maximal velocity (mm/s), 4..7
        // acceleration and deceleration (not simulated).
        if header & 0xF != self.count && header & 0xFFF0 == VAI_GO_TO_POS {
            self.count = header & 0xF;
            let [p0, p1, v0, v1] = self.rx1.mc_par_bytes_0_3.to_le_bytes();
            self.target = i32::from(i16::from_le_bytes([p0, p1]));
            // Per 10 ms SYNC period, in 0.1 mm.
            self.speed = i32::from(u16::from_le_bytes([v0, v1])) / 10;
        }
        let step = (self.target - self.position).clamp(-self.speed.max(1), self.speed.max(1));
        self.position += step;
        let mut out = Vec::new();
        let tx1 =
            TxPdo1 { status_word: self.control_word, state_var: 0, actual_position: self.position };
        out.extend(CanFrame::from_slice(TxPdo1::cob_id(NODE), &tx1.pack()));
        if let Some((id, entries)) = self.tpdo4() {
            // The UPIDs' values, in the mapped order.
            let mut data = Vec::new();
            for e in entries.iter().filter(|e| e.index == 0x4F08) {
                let id =
                    self.upids().get(usize::from(e.sub).saturating_sub(1)).copied().unwrap_or(0);
                let Some(ObjectAddr { index, sub }) = upid::param(id, upid::Op::Ram) else {
                    continue;
                };
                let mut buf = [0u8; 4];
                let n = usize::from(e.bits / 8).min(4);
                if self.od.read(index, sub, &mut buf[..n]).is_ok() {
                    data.extend_from_slice(&buf[..n]);
                }
            }
            if !data.is_empty() {
                out.extend(CanFrame::from_slice(id, &data));
            }
        }
        out
    }
}

/// The program: the drive in a thread, the master in this one.
pub fn main() -> Result<(), Error> {
    let (master_port, drive_port) = bus::pair();
    let drive = thread::spawn(move || LinMot::new().run(&drive_port));
    let mut m = odc_examples::master(master_port);
    let node = u32::from(NODE.get());

    step("boot-up");
    m.wait_boot_up(NODE)?;
    step("TxPDO 4 by UPID (manual 9.1.3): 1CA4h, 1CA6h, 1B91h into 4F08h sub 1..3");
    m.write(NODE, &od::tpdo4_upid_mapping::TPDO4_UPIDS_1, 0x1CA4)?;
    m.write(NODE, &od::tpdo4_upid_mapping::TPDO4_UPIDS_2, 0x1CA6)?;
    m.write(NODE, &od::tpdo4_upid_mapping::TPDO4_UPIDS_3, 0x1B91)?;
    let mapping = od::transmit_pdo_mapping_parameter_3_tx_pdo_4::PDO_MAPPING_ENTRY_1;
    let first = m.read(NODE, &mapping)?;
    println!("-- the drive mapped 1A03h sub 1 = {first:08X}h");
    if first != 0x4F08_0110 {
        return Err("TxPDO 4 is not mapped as the manual says".into());
    }
    step("the UPIDs' RAM values through the generated UPID scheme");
    let voltage = m.read(NODE, &upid::U1CA4_RAM)?;
    let diff = m.read(NODE, &upid::U1CA6_RAM)?;
    println!("-- X4.4 analog voltage {voltage}, diff analog voltage {diff}");

    step("NMT start; the control word sequence of manual 7.1");
    m.nmt(NmtCommand::Start, NODE)?;
    let tx1 = |f: CanFrame| TxPdo1::unpack(f.bytes()).ok_or("TxPDO 1 has 8 bytes");
    for (control_word, what) in [(0x083F, "homing"), (0x003F, "enter operational state")] {
        step(&format!("{what}: Control Word {control_word:04X}h"));
        send(&mut m, RxPdo1::cob_id(NODE), &RxPdo1 { control_word, ..RxPdo1::default() }.pack())?;
        m.sync()?;
        let s = tx1(m.recv_frame(odc::cob::CobId(TxPdo1::cob_id(NODE)))?)?;
        let _ = m.recv_pdo::<TxPdo4>(odc::cob::CobId(0x480 + node))?;
        println!("   status word {:04X}h, actual position {}", s.status_word, s.actual_position);
    }
    step("VAI 16Bit Go To Pos (0901h): 50 mm at 1 m/s, 10 m/s² up and down");
    let (position, velocity, acceleration, deceleration) = (500u16, 1000u16, 100u16, 100u16);
    let command = RxPdo1 {
        control_word: 0x003F,
        mc_header: VAI_GO_TO_POS | 1,
        mc_par_bytes_0_3: u32::from(position) | u32::from(velocity) << 16,
    };
    let ramps = RxPdo2 {
        mc_par_bytes_4_7: u32::from(acceleration) | u32::from(deceleration) << 16,
        mc_par_bytes_8_11: 0,
    };
    send(&mut m, RxPdo1::cob_id(NODE), &command.pack())?;
    send(&mut m, RxPdo2::cob_id(NODE), &ramps.pack())?;
    let mut syncs = 0;
    loop {
        m.sync()?;
        syncs += 1;
        let s = tx1(m.recv_frame(odc::cob::CobId(TxPdo1::cob_id(NODE)))?)?;
        let t4 = m.recv_pdo::<TxPdo4>(odc::cob::CobId(0x480 + node))?;
        println!(
            "   actual position {} (0.1 mm), analog voltage {}, diff {}",
            s.actual_position, t4.analog_voltage, t4.diff_analog_voltage
        );
        if s.actual_position == i32::from(position) {
            break;
        }
        if syncs == 100 {
            return Err("the drive did not reach 50 mm".into());
        }
    }
    println!("-- at 50 mm after {syncs} SYNCs");
    drop(m);
    drive.join().map_err(|_| "the drive thread panicked")??;
    Ok(())
}

/// Any frame from the master.
fn send(m: &mut Master<Port>, id: u32, data: &[u8]) -> Result<(), Error> {
    Ok(m.send(&CanFrame::from_slice(id, data).ok_or("at most 8 bytes")?)?)
}
