//! The controller side: NMT, SYNC and PDOs on the bus, odc's SDO client for the rest, and the
//! two CiA 402 procedures every example runs. Every frame sent or received is printed.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use odc::can::CanFrame;
use odc::cia402::{Controlword, State, Statusword};
use odc::nmt::NmtCommand;
use odc::plan::SdoWrite;
use odc::sdo::{Bus, Client};
use odc::{Entry, ObjValue, Pdo};

use crate::Error;
use crate::bus::{Closed, Port, describe};

/// How long the master waits for an answer before it gives up.
pub const TIMEOUT: Duration = Duration::from_secs(10);

/// The master's end of the bus, as odc's SDO client sees it: frames that are not SDO
/// responses are kept for the PDO side.
pub struct Link {
    port: Port,
    start: Instant,
    sdo_response: u32,
    pending: VecDeque<CanFrame>,
    frames: u32,
}

impl Link {
    fn now(&self) -> u64 {
        u64::try_from(self.start.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    /// Prints a frame with its number on the bus and its direction.
    fn print(&mut self, arrow: &str, frame: &CanFrame) {
        self.frames += 1;
        println!("{:>5}  {arrow} {}", self.frames, describe(frame));
    }

    fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        self.print("master -> ", frame);
        self.port.send(*frame)
    }

    fn receive(&mut self, timeout: Duration) -> Result<Option<CanFrame>, Closed> {
        let frame = self.port.recv_timeout(timeout)?;
        if let Some(f) = &frame {
            self.print("  drive -> ", f);
        }
        Ok(frame)
    }
}

impl Bus for Link {
    type Error = Closed;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        Link::send(self, frame)
    }

    fn recv(&mut self, deadline_ms: u64) -> Result<Option<CanFrame>, Closed> {
        loop {
            let left = deadline_ms.saturating_sub(self.now());
            let Some(frame) = self.receive(Duration::from_millis(left))? else { return Ok(None) };
            if frame.id == self.sdo_response {
                return Ok(Some(frame));
            }
            self.pending.push_back(frame);
        }
    }

    fn now_ms(&mut self) -> u64 {
        self.now()
    }
}

/// The controller of one node.
pub struct Master {
    link: Link,
    client: Client<64>,
    node: u8,
}

impl Master {
    /// The master of node `node` on `port`.
    pub fn new(port: Port, node: u8) -> Self {
        let client =
            Client::new(node).with_timeout(u64::try_from(TIMEOUT.as_millis()).unwrap_or(u64::MAX));
        let sdo_response = client.response_id();
        Master {
            link: Link {
                port,
                start: Instant::now(),
                sdo_response,
                pending: VecDeque::new(),
                frames: 0,
            },
            client,
            node,
        }
    }

    /// Prints a step of the example.
    pub fn step(&self, text: &str) {
        println!("-- {text}");
    }

    /// The next frame with CAN-ID `id` (frames received earlier first).
    ///
    /// # Errors
    ///
    /// When none comes within [`TIMEOUT`] or the bus closes.
    pub fn expect(&mut self, id: u32) -> Result<CanFrame, Error> {
        if let Some(pos) = self.link.pending.iter().position(|f| f.id == id)
            && let Some(f) = self.link.pending.remove(pos)
        {
            return Ok(f);
        }
        let deadline = Instant::now() + TIMEOUT;
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match self.link.receive(left)? {
                Some(f) if f.id == id => return Ok(f),
                Some(f) => self.link.pending.push_back(f),
                None => break,
            }
        }
        Err(format!("no frame with CAN-ID {id:03X} within {TIMEOUT:?}").into())
    }

    /// Forgets frames received but not yet asked for, after reading what has arrived.
    ///
    /// # Errors
    ///
    /// When the bus closes.
    pub fn settle(&mut self) -> Result<(), Error> {
        while let Some(f) = self.link.port.try_recv()? {
            self.link.print("  drive -> ", &f);
        }
        self.link.pending.clear();
        Ok(())
    }

    /// The boot-up message of the node (0x700 + node, one byte 0).
    ///
    /// # Errors
    ///
    /// When it does not come.
    pub fn boot_up(&mut self) -> Result<(), Error> {
        let f = self.expect(0x700 + u32::from(self.node))?;
        if f.bytes() != [0] {
            return Err(format!("not a boot-up message: {}", describe(&f)).into());
        }
        Ok(())
    }

    /// An NMT command to this node.
    ///
    /// # Errors
    ///
    /// When the bus closes.
    pub fn nmt(&mut self, command: NmtCommand) -> Result<(), Error> {
        let frame = CanFrame::from_slice(0, &command.frame(self.node)).ok_or("NMT frame")?;
        Ok(self.link.send(&frame)?)
    }

    /// Any frame, as it is (the process data of a device the generated code has no struct
    /// for).
    ///
    /// # Errors
    ///
    /// When the bus closes.
    pub fn frame(&mut self, frame: &CanFrame) -> Result<(), Error> {
        Ok(self.link.send(frame)?)
    }

    /// A SYNC.
    ///
    /// # Errors
    ///
    /// When the bus closes.
    pub fn sync(&mut self) -> Result<(), Error> {
        let frame = CanFrame::from_slice(u32::from(odc::cob::SYNC), &[]).ok_or("SYNC frame")?;
        Ok(self.link.send(&frame)?)
    }

    /// An RPDO: the struct's bytes on the PDO's CAN-ID (bit 31 and the other flags of
    /// `cob_id` dropped).
    ///
    /// # Errors
    ///
    /// A value that does not fit its field, or a closed bus.
    pub fn rpdo<P: Pdo>(&mut self, cob_id: u32, pdo: &P) -> Result<(), Error> {
        let bytes = pdo.pack().map_err(|e| format!("{e:?}"))?;
        let frame =
            CanFrame::from_slice(cob_id & 0x7FF, bytes.as_ref()).ok_or("PDO over 8 bytes")?;
        Ok(self.link.send(&frame)?)
    }

    /// The next TPDO on `cob_id`, unpacked.
    ///
    /// # Errors
    ///
    /// When none comes or it does not unpack.
    pub fn tpdo<P: Pdo>(&mut self, cob_id: u32) -> Result<P, Error> {
        let frame = self.expect(cob_id & 0x7FF)?;
        P::unpack(frame.bytes()).map_err(|e| format!("{e:?}").into())
    }

    /// An SDO write of a generated descriptor's entry.
    ///
    /// # Errors
    ///
    /// The abort, or a closed bus.
    pub fn write<T: ObjValue>(&mut self, entry: &Entry<T>, value: T) -> Result<(), Error> {
        Ok(self.client.write(&mut self.link, entry, value)?)
    }

    /// An SDO read of a generated descriptor's entry.
    ///
    /// # Errors
    ///
    /// The abort, or a closed bus.
    pub fn read<T: ObjValue>(&mut self, entry: &Entry<T>) -> Result<T, Error> {
        Ok(self.client.read(&mut self.link, entry)?)
    }

    /// Executes a configuration plan (a generated `master::plan`), write by write.
    ///
    /// # Errors
    ///
    /// Which write failed, and why.
    pub fn execute(&mut self, plan: &[SdoWrite]) -> Result<(), Error> {
        self.client
            .execute(&mut self.link, plan)
            .map_err(|(i, e)| format!("write {i} of the plan: {e}"))?;
        Ok(())
    }
}

/// The PDOs of a profile-position move: an RPDO with the controlword and the target position,
/// a TPDO with the statusword and the actual position, whatever structs a device's
/// generated code (or the example) has for them.
pub struct PositionPdos<R, T> {
    /// COB-ID of the RPDO.
    pub rx: u32,
    /// COB-ID of the TPDO.
    pub tx: u32,
    /// The RPDO for a controlword and a target.
    pub command: fn(Controlword, i32) -> R,
    /// Statusword and actual position of the TPDO.
    pub status: fn(&T) -> (Statusword, i32),
}

/// Walks the drive's state machine to "operation enabled": from the state its TPDO reports,
/// the controlword of the next transition ([`State::next_command_towards_enabled`]), until
/// the TPDO says "operation enabled". Expects the TPDO that NMT start triggered first.
///
/// # Errors
///
/// A statusword without a CiA 402 state, a drive stuck in a state, a silent drive.
pub fn enable<R: Pdo, T: Pdo>(m: &mut Master, pdos: &PositionPdos<R, T>) -> Result<i32, Error> {
    let (mut sw, mut position) = (pdos.status)(&m.tpdo::<T>(pdos.tx)?);
    for _ in 0..8 {
        let state = sw.state().ok_or("a statusword without a CiA 402 state")?;
        println!("   state: {state}");
        if state == State::OperationEnabled {
            return Ok(position);
        }
        let cw = state.next_command_towards_enabled().ok_or("the drive changes state by itself")?;
        m.rpdo(pdos.rx, &(pdos.command)(cw, position))?;
        (sw, position) = (pdos.status)(&m.tpdo::<T>(pdos.tx)?);
    }
    Err("the drive does not reach operation enabled".into())
}

/// One profile-position move to `target` (absolute): set-point with controlword bit 4, wait
/// for the acknowledge (statusword bit 12), clear bit 4, then send SYNCs and read the TPDO
/// until the drive reports "target reached" (bit 10) at the target. Returns the SYNCs it took.
///
/// # Errors
///
/// A drive that does not acknowledge, stops short, or never arrives.
pub fn move_to<R: Pdo, T: Pdo>(
    m: &mut Master,
    pdos: &PositionPdos<R, T>,
    target: i32,
) -> Result<u32, Error> {
    let run = Controlword::ENABLE_OPERATION;
    m.rpdo(pdos.rx, &(pdos.command)(run.with_new_setpoint(true), target))?;
    let (sw, _) = (pdos.status)(&m.tpdo::<T>(pdos.tx)?);
    if !sw.setpoint_ack() {
        return Err("the drive did not acknowledge the set-point".into());
    }
    m.rpdo(pdos.rx, &(pdos.command)(run, target))?;
    let (mut sw, mut position) = (pdos.status)(&m.tpdo::<T>(pdos.tx)?);
    let mut syncs = 0;
    while !(sw.target_reached() && position == target) {
        if syncs == 1000 {
            return Err(format!("not at {target} after 1000 SYNCs (at {position})").into());
        }
        m.sync()?;
        syncs += 1;
        (sw, position) = (pdos.status)(&m.tpdo::<T>(pdos.tx)?);
        println!("   position {position}, statusword 0x{:04X}", sw.bits());
    }
    Ok(syncs)
}

/// The CiA 301 writes that give a PDO a mapping of the application's choice (for a device
/// whose file has no default mapping): invalidate the COB-ID, clear the mapping, write
/// `P::MAPPING`, set the count and the transmission type, validate the COB-ID.
pub fn mapping_plan<P: Pdo>(
    comm_index: u16,
    mapping_index: u16,
    cob_id: u32,
    transmission_type: u8,
) -> Vec<SdoWrite> {
    let cob = odc::cob::CobId(cob_id);
    let mut plan = vec![
        SdoWrite::u32(comm_index, 1, cob.with_valid(false).0),
        SdoWrite::u8(mapping_index, 0, 0),
    ];
    for (i, e) in P::MAPPING.iter().enumerate() {
        plan.push(SdoWrite::u32(mapping_index, u8::try_from(i + 1).unwrap_or(u8::MAX), e.to_u32()));
    }
    plan.push(SdoWrite::u8(mapping_index, 0, u8::try_from(P::MAPPING.len()).unwrap_or(u8::MAX)));
    plan.push(SdoWrite::u8(comm_index, 2, transmission_type));
    plan.push(SdoWrite::u32(comm_index, 1, cob.with_valid(true).0));
    plan
}
