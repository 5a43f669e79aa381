//! The device side of EtherCAT, `no_std` and without heap (feature `subdevice`): what the
//! firmware of an EtherCAT device runs beside its ESC, on the generated slave dictionary.
//!
//! - [`al`]: the AL state machine (INIT, PRE-OP, SAFE-OP, OP, BOOT) with the AL status codes
//!   of ETG.1000.6 and the checks of the sync managers against the live mapping;
//! - the mailbox on the ESI's mailbox sync managers with CoE: SDO expedited, normal and
//!   segmented both ways, complete access where the ESI allows it, aborts with the
//!   dictionary's codes, SDO Information ([`info`], from the application's [`Describe`]),
//!   CoE emergency ([`SubDevice::emergency`]);
//! - [`pdo`]: process data from the live 0x1C1n assignment and mapping objects into the
//!   process data sync managers' buffers, and the application's hook per cycle.
//!
//! It reaches the ESC only through the [`Esc`] trait: register and process RAM reads and
//! writes and the AL event request register, which an emulated ESC (odc-sim) or a PDI
//! adapter (SPI to an ET1100 or a LAN9252) implements. [`SubDevice::poll`] serves the events
//! (AL control, mailbox), [`SubDevice::cycle`] the process data; the caller runs them from
//! its interrupt or main loop, as SOES's `ecat_slv` is run.

pub mod al;
mod coe;
pub mod foe;
pub mod info;
pub mod pdo;

pub use info::{Describe, EntryDescription, ObjectDescription};

use al::{SM_FULL, SmRegs, code, state};
use coe::{Out, Transfer};
use pdo::Mapped;

use crate::slave::Storage;

/// ESC register addresses the device side uses (ETG.1000.4 §6, the ESC datasheets' register
/// maps).
pub mod register {
    /// Process RAM in KiB (1 byte).
    pub const RAM_SIZE: u16 = 0x0006;
    /// AL control (2 bytes).
    pub const AL_CONTROL: u16 = 0x0120;
    /// AL status (2 bytes).
    pub const AL_STATUS: u16 = 0x0130;
    /// AL status code (2 bytes).
    pub const AL_STATUS_CODE: u16 = 0x0134;
    /// AL event request (4 bytes): bit 0 AL control written, bit 8 + n sync manager n.
    pub const AL_EVENT: u16 = 0x0220;
    /// Sync manager 0 (8 bytes each).
    pub const SM: u16 = 0x0800;
    /// The first address of the process RAM.
    pub const PROCESS_RAM: u16 = 0x1000;
}

/// The ESC as the device's application sees it through its PDI.
///
/// Semantics a real ESC has and an implementation keeps: reading the last byte of a mailbox
/// the master writes empties it, writing the last byte of one the master reads fills it, and
/// reading AL control clears its event.
pub trait Esc {
    /// What an access may fail with (a SPI transfer's error).
    type Error;

    /// Reads `buf.len()` bytes from `addr` (registers or process RAM).
    ///
    /// # Errors
    ///
    /// The PDI's.
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error>;

    /// Writes `data` at `addr`.
    ///
    /// # Errors
    ///
    /// The PDI's.
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error>;

    /// The AL event request register (0x0220). An SPI adapter may return the bytes its
    /// address phase delivers instead of a read.
    ///
    /// # Errors
    ///
    /// The PDI's.
    fn al_event(&mut self) -> Result<u32, Self::Error> {
        let mut b = [0u8; 4];
        self.read(register::AL_EVENT, &mut b)?;
        Ok(u32::from_le_bytes(b))
    }
}

/// What the device's ESI says of one of its sync managers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SmSpec {
    /// Its number.
    pub number: u8,
    /// Usage, by the SII's codes: [`al::MBOX_OUT`], [`al::MBOX_IN`], [`al::OUTPUTS`],
    /// [`al::INPUTS`], 0 other.
    pub kind: u8,
    /// `@MinSize` (0 when not given).
    pub min: u16,
    /// `@MaxSize` (the process RAM when not given).
    pub max: u16,
    /// `@ControlByte`.
    pub control: u8,
}

/// What the device is, from its ESI: data, `const` in a firmware.
#[derive(Clone, Copy)]
pub struct Config<'a> {
    /// The sync managers.
    pub sync_managers: &'a [SmSpec],
    /// For sync managers without an assignment object (0x1C10 + n), and for every sync
    /// manager of a device without CoE: the mapping values of their fixed PDOs,
    /// `(sm, index << 16 | sub << 8 | bits)`, in order.
    pub fixed: &'a [(u8, u32)],
    /// The device serves CoE (`Mailbox/CoE`).
    pub coe: bool,
    /// CoE complete access (`CoE@CompleteAccess`).
    pub complete_access: bool,
    /// The device has a bootstrap state.
    pub boot: bool,
    /// The device serves FoE (`Mailbox/FoE`), through the application's `foe_*` methods.
    pub foe: bool,
    /// SDO Information (`CoE@SdoInfo`): the descriptions it serves.
    pub describe: Option<&'a dyn Describe>,
}

impl core::fmt::Debug for Config<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Config")
            .field("sync_managers", &self.sync_managers)
            .field("fixed", &self.fixed)
            .field("coe", &self.coe)
            .field("complete_access", &self.complete_access)
            .field("boot", &self.boot)
            .field("foe", &self.foe)
            .field("sdo_info", &self.describe.is_some())
            .finish()
    }
}

/// The application: what the device does with its dictionary beside the stack.
pub trait Application<D: ?Sized> {
    /// Once per cycle in SAFE-OP and OP, after the outputs are in the dictionary (OP) and
    /// before the inputs are taken from it.
    fn cycle(&mut self, od: &mut D, state: u8) {
        let _ = (od, state);
    }
    /// After a mailbox request was served (an SDO download may have changed values).
    fn mailbox_served(&mut self, od: &mut D) {
        let _ = od;
    }
    /// Before a requested state is entered, once the stack's checks passed; an error is the
    /// AL status code to refuse it with.
    ///
    /// # Errors
    ///
    /// The AL status code.
    fn entering(&mut self, od: &mut D, from: u8, to: u8) -> Result<(), u16> {
        let _ = (od, from, to);
        Ok(())
    }
    /// FoE: a master asks to write the file `name` (a firmware image in BOOT); an error is the
    /// FoE error code to refuse with ([`foe::error`]; by default "not defined").
    ///
    /// # Errors
    ///
    /// The FoE error code.
    fn foe_open_write(&mut self, name: &[u8], password: u32) -> Result<(), u32> {
        let _ = (name, password);
        Err(foe::error::NOT_DEFINED)
    }
    /// FoE: the next `data` of the file being written, at `offset`.
    ///
    /// # Errors
    ///
    /// The FoE error code.
    fn foe_write(&mut self, offset: u32, data: &[u8]) -> Result<(), u32> {
        let _ = (offset, data);
        Err(foe::error::NOT_DEFINED)
    }
    /// FoE: a master asks to read the file `name`.
    ///
    /// # Errors
    ///
    /// The FoE error code ([`foe::error::NOT_FOUND`] by default).
    fn foe_open_read(&mut self, name: &[u8], password: u32) -> Result<(), u32> {
        let _ = (name, password);
        Err(foe::error::NOT_FOUND)
    }
    /// FoE: the file being read from `offset` into `buf`; returns the bytes (fewer than
    /// `buf` holds at the end of the file).
    ///
    /// # Errors
    ///
    /// The FoE error code.
    fn foe_read(&mut self, offset: u32, buf: &mut [u8]) -> Result<usize, u32> {
        let _ = (offset, buf);
        Err(foe::error::NOT_DEFINED)
    }
    /// FoE: the transfer ended (`write`: a file was written, else one was read), or was
    /// aborted by the master.
    ///
    /// # Errors
    ///
    /// The FoE error code for the last packet of a write.
    fn foe_close(&mut self, write: bool) -> Result<(), u32> {
        let _ = write;
        Ok(())
    }
}

/// The application that does nothing.
impl<D: ?Sized> Application<D> for () {}

/// Mailbox types (ETG.1000.4 Table 29).
const TYPE_ERROR: u8 = 0x00;
const TYPE_COE: u8 = 0x03;
const TYPE_FOE: u8 = 0x04;
/// Bytes of the mailbox header.
const HEADER: usize = 6;

/// Mailbox error details (ETG.1000.4 Table 30).
pub mod mailbox_error {
    /// Syntax of the 6-byte header is wrong.
    pub const SYNTAX: u16 = 0x0001;
    /// The protocol is not supported.
    pub const UNSUPPORTED_PROTOCOL: u16 = 0x0002;
    /// Length of the data is shorter than the protocol's header.
    pub const SIZE_TOO_SHORT: u16 = 0x0006;
    /// Length of the data is inconsistent.
    pub const INVALID_SIZE: u16 = 0x0008;
}

/// The device side of one EtherCAT device: `MBX` bytes of mailbox (the largest mailbox sync
/// manager served whole), `BUF` bytes for an SDO value, `PD` mapped entries, `IMG` bytes for
/// the largest process data image.
pub struct SubDevice<
    const MBX: usize = 128,
    const BUF: usize = 256,
    const PD: usize = 64,
    const IMG: usize = 64,
> {
    state: u8,
    error: bool,
    counter: u8,
    transfer: Transfer,
    foe: foe::Transfer,
    buf: [u8; BUF],
    info: Option<info::Pending>,
    reply: [u8; MBX],
    reply_len: usize,
    mapped: [Mapped; PD],
    used: usize,
    emergency: Option<[u8; 8]>,
    /// One process data image on its way between the ESC and the dictionary.
    image: [u8; IMG],
}

impl<const MBX: usize, const BUF: usize, const PD: usize, const IMG: usize> Default
    for SubDevice<MBX, BUF, PD, IMG>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const MBX: usize, const BUF: usize, const PD: usize, const IMG: usize> core::fmt::Debug
    for SubDevice<MBX, BUF, PD, IMG>
{
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SubDevice")
            .field("state", &self.state)
            .field("error", &self.error)
            .field("mapped", &self.mapped.get(..self.used))
            .finish_non_exhaustive()
    }
}

/// The mailbox sync managers of `cfg` (out, in).
#[inline(never)]
fn mailboxes(cfg: &Config<'_>) -> (Option<u8>, Option<u8>) {
    let find = |kind: u8| cfg.sync_managers.iter().find(|s| s.kind == kind).map(|s| s.number);
    (find(al::MBOX_OUT), find(al::MBOX_IN))
}

fn is_process_data(s: &SmSpec) -> bool {
    matches!(s.kind, al::OUTPUTS | al::INPUTS)
}

/// Writes `value` into the PDI control register (bit 0: deactivated by the application) of
/// every process data sync manager: 1 outside SAFE-OP and OP, 0 on entering SAFE-OP.
fn pdi_control<E: Esc + ?Sized>(cfg: &Config<'_>, esc: &mut E, value: u8) -> Result<(), E::Error> {
    for spec in cfg.sync_managers.iter().filter(|s| is_process_data(s)) {
        esc.write(register::SM + 8 * u16::from(spec.number) + 7, &[value])?;
    }
    Ok(())
}

impl<const MBX: usize, const BUF: usize, const PD: usize, const IMG: usize>
    SubDevice<MBX, BUF, PD, IMG>
{
    /// A device at power-on: INIT.
    pub const fn new() -> Self {
        Self {
            state: state::INIT,
            error: false,
            counter: 0,
            transfer: Transfer::None,
            foe: foe::Transfer::None,
            buf: [0; BUF],
            info: None,
            reply: [0; MBX],
            reply_len: 0,
            mapped: [Mapped { sm: 0, index: 0, sub: 0, bits: 0, bit: 0 }; PD],
            used: 0,
            emergency: None,
            image: [0; IMG],
        }
    }

    /// The AL state (1 INIT, 2 PRE-OP, 3 BOOT, 4 SAFE-OP, 8 OP).
    pub fn state(&self) -> u8 {
        self.state
    }

    /// Whether a reply or an emergency waits for the read mailbox.
    pub fn has_pending(&self) -> bool {
        self.reply_len != 0 || self.info.is_some() || self.emergency.is_some()
    }

    /// The entries mapped into the process data sync managers (SAFE-OP and OP).
    pub fn mapped(&self) -> &[Mapped] {
        self.mapped.get(..self.used).unwrap_or(&[])
    }

    /// Queues a CoE emergency (ETG.1000.6 §5.6.4: the CiA 301 error code, error register and
    /// 5 bytes of manufacturer data), sent when the read mailbox is free; a later one replaces
    /// one not yet sent.
    pub fn emergency(&mut self, error_code: u16, register: u8, data: [u8; 5]) {
        let c = error_code.to_le_bytes();
        self.emergency = Some([c[0], c[1], register, data[0], data[1], data[2], data[3], data[4]]);
    }

    /// Serves what the AL event request says happened: a state request, a mailbox written by
    /// the master, a mailbox read by it.
    ///
    /// # Errors
    ///
    /// The ESC access's.
    #[inline(never)]
    pub fn poll<E, D, A>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &mut D,
        app: &mut A,
    ) -> Result<(), E::Error>
    where
        E: Esc + ?Sized,
        D: Storage + ?Sized,
        A: Application<D> + ?Sized,
    {
        let ev = esc.al_event()?;
        if ev & 1 != 0 {
            self.al_control(cfg, esc, od, app)?;
        }
        let (out_sm, in_sm) = mailboxes(cfg);
        let event = |n: Option<u8>| n.is_some_and(|n| ev >> (8 + u32::from(n)) & 1 != 0);
        if event(out_sm) {
            self.mailbox_received(cfg, esc, od, app)?;
        }
        if event(in_sm) || self.reply_len != 0 || self.emergency.is_some() {
            self.send_pending(cfg, esc, od)?;
        }
        Ok(())
    }

    /// One cycle of process data in SAFE-OP and OP: the outputs into the dictionary (OP
    /// only), the application's [`Application::cycle`], the inputs from the dictionary.
    ///
    /// # Errors
    ///
    /// The ESC access's.
    #[inline(never)]
    pub fn cycle<E, D, A>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &mut D,
        app: &mut A,
    ) -> Result<(), E::Error>
    where
        E: Esc + ?Sized,
        D: Storage + ?Sized,
        A: Application<D> + ?Sized,
    {
        if self.state != state::SAFE_OP && self.state != state::OP {
            return Ok(());
        }
        if self.state == state::OP {
            self.exchange(cfg, esc, od, al::OUTPUTS)?;
        }
        app.cycle(od, self.state);
        self.exchange(cfg, esc, od, al::INPUTS)
    }

    /// The process data of the sync managers of `kind`: [`al::OUTPUTS`] from the ESC into
    /// the dictionary, [`al::INPUTS`] from the dictionary (gaps and unmapped bits as zeros)
    /// to the ESC. One loop for both directions: the firmware links it once.
    #[inline(never)]
    fn exchange<E: Esc + ?Sized, D: Storage + ?Sized>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &mut D,
        kind: u8,
    ) -> Result<(), E::Error> {
        for spec in cfg.sync_managers.iter().filter(|s| s.kind == kind) {
            let regs = SmRegs::read(esc, spec.number)?;
            let n = usize::from(regs.len).min(IMG);
            let Some(image) = self.image.get_mut(..n) else { continue };
            let mapped = self.mapped.get(..self.used).unwrap_or(&[]);
            if kind == al::OUTPUTS {
                esc.read(regs.start, image)?;
                pdo::image_to_dictionary(mapped, spec.number, image, od);
            } else {
                image.fill(0);
                pdo::dictionary_to_image(mapped, spec.number, od, image);
                esc.write(regs.start, image)?;
            }
        }
        Ok(())
    }

    #[inline(never)]
    fn set_status<E: Esc + ?Sized>(&mut self, esc: &mut E, status: u16) -> Result<(), E::Error> {
        self.error = status != code::NONE;
        let s = u16::from(self.state) | u16::from(self.error) << 4;
        esc.write(register::AL_STATUS, &s.to_le_bytes())?;
        esc.write(register::AL_STATUS_CODE, &status.to_le_bytes())
    }

    /// A write of AL control: the requested state, checked; on failure the device stays
    /// where it is with the error flag and the status code.
    #[inline(never)]
    fn al_control<E, D, A>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &mut D,
        app: &mut A,
    ) -> Result<(), E::Error>
    where
        E: Esc + ?Sized,
        D: Storage + ?Sized,
        A: Application<D> + ?Sized,
    {
        let mut b = [0u8; 2];
        esc.read(register::AL_CONTROL, &mut b)?;
        let control = u16::from_le_bytes(b);
        let requested = (control & 0x0F) as u8;
        let ack = control & 0x10 != 0;
        // With the error flag set, only an acknowledgement or a step down is taken
        // (ETG.1000.6 §6.4.1.3).
        if self.error && !ack && requested > self.state {
            return Ok(());
        }
        let result = match self.transition(cfg, esc, od, requested)? {
            Ok(()) => app.entering(od, self.state, requested),
            Err(c) => Err(c),
        };
        match result {
            Ok(()) => {
                self.state = requested;
                if matches!(requested, state::SAFE_OP) {
                    self.exchange(cfg, esc, od, al::INPUTS)?;
                }
                self.set_status(esc, code::NONE)
            }
            Err(c) => {
                if requested == state::SAFE_OP && self.state == state::PRE_OP {
                    self.used = 0;
                }
                self.set_status(esc, c)
            }
        }
    }

    /// The checks and work of entering `to`; `Ok(Err(code))` when refused.
    #[inline(never)]
    fn transition<E, D>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &D,
        to: u8,
    ) -> Result<Result<(), u16>, E::Error>
    where
        E: Esc + ?Sized,
        D: Storage + ?Sized,
    {
        if let Err(c) = al::allowed(self.state, to, cfg.boot) {
            return Ok(Err(c));
        }
        // BOOT, PRE-OP and SAFE-OP from PRE-OP check the mailbox first: one check, its code
        // BOOT's own for BOOT.
        let checks_mailbox = match to {
            state::BOOT | state::PRE_OP => true,
            state::SAFE_OP => self.state == state::PRE_OP,
            _ => false,
        };
        if checks_mailbox && al::check_mailbox(esc, cfg.sync_managers)?.is_err() {
            return Ok(Err(match to {
                state::BOOT => code::INVALID_MAILBOX_CONFIG_BOOT,
                _ => code::INVALID_MAILBOX_CONFIG,
            }));
        }
        match to {
            state::INIT => {
                self.transfer = Transfer::None;
                self.foe = foe::Transfer::None;
                self.info = None;
                self.reply_len = 0;
                self.counter = 0;
                self.deactivate_process_data(cfg, esc)?;
            }
            state::PRE_OP if self.state >= state::SAFE_OP => {
                self.deactivate_process_data(cfg, esc)?;
            }
            state::SAFE_OP if self.state == state::PRE_OP => {
                let mut bits = [0u32; 16];
                let mut sink = pdo::Sink { entries: &mut self.mapped, used: 0 };
                for spec in cfg.sync_managers.iter().filter(|s| is_process_data(s)) {
                    let outputs = spec.kind == al::OUTPUTS;
                    // ETG.1000.6 Table 11: a mapping the device cannot serve is an invalid
                    // mapping; a process image it has no room for, an invalid configuration.
                    let err = |r: pdo::Refused| match (r, outputs) {
                        (pdo::Refused::Mapping, true) => code::INVALID_OUTPUT_MAPPING,
                        (pdo::Refused::Mapping, false) => code::INVALID_INPUT_MAPPING,
                        (pdo::Refused::Room, true) => code::INVALID_OUTPUT_CONFIG,
                        (pdo::Refused::Room, false) => code::INVALID_INPUT_CONFIG,
                    };
                    // Without CoE no master can read or change an assignment: the device
                    // runs the PDOs its SII gives (ETG.2010 PDO categories, the ESI's fixed
                    // PDOs), whatever assignment objects its model has (an SoE drive's PDO
                    // indices are IDNs, not objects).
                    let laid =
                        if cfg.coe { pdo::layout(od, spec.number, &mut sink) } else { Ok(None) };
                    let n = match laid {
                        Ok(Some(n)) => n,
                        Ok(None) => match pdo::fixed(spec.number, cfg.fixed, &mut sink) {
                            Ok(n) => n,
                            Err(r) => return Ok(Err(err(r))),
                        },
                        Err(r) => return Ok(Err(err(r))),
                    };
                    if n.div_ceil(8) > IMG as u32 {
                        return Ok(Err(err(pdo::Refused::Room)));
                    }
                    if let Some(b) = bits.get_mut(usize::from(spec.number)) {
                        *b = n;
                    }
                }
                let used = sink.used;
                let bytes_of = |sm: u8| {
                    let b = bits.get(usize::from(sm)).copied().unwrap_or(0);
                    u16::try_from(b.div_ceil(8)).unwrap_or(u16::MAX)
                };
                if let Err(c) = al::check_process_data(esc, cfg.sync_managers, bytes_of)? {
                    return Ok(Err(c));
                }
                self.used = used;
                pdi_control(cfg, esc, 0)?;
            }
            _ => {}
        }
        Ok(Ok(()))
    }

    /// Outside SAFE-OP and OP the application keeps the process data sync managers
    /// deactivated (PDI control bit 0): the master's process data access is not counted.
    fn deactivate_process_data<E: Esc + ?Sized>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
    ) -> Result<(), E::Error> {
        self.used = 0;
        pdi_control(cfg, esc, 1)
    }

    /// The write mailbox is full: read it, answer in the read mailbox.
    #[inline(never)]
    fn mailbox_received<E, D, A>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        od: &mut D,
        app: &mut A,
    ) -> Result<(), E::Error>
    where
        E: Esc + ?Sized,
        D: Storage + ?Sized,
        A: Application<D> + ?Sized,
    {
        let (Some(out_sm), Some(in_sm)) = mailboxes(cfg) else { return Ok(()) };
        let rx = SmRegs::read(esc, out_sm)?;
        if rx.status & SM_FULL == 0 {
            return Ok(());
        }
        let n = usize::from(rx.len).min(MBX);
        let mut request = [0u8; MBX];
        let request = request.get_mut(..n).unwrap_or(&mut []);
        esc.read(rx.start, request)?;
        if usize::from(rx.len) > n {
            // Reading the last byte hands the mailbox back to the master.
            esc.read(rx.start + rx.len - 1, &mut [0])?;
        }
        let tx = SmRegs::read(esc, in_sm)?;
        if self.state < state::PRE_OP || !tx.enabled() {
            return Ok(());
        }
        let room = usize::from(tx.len).min(MBX);
        self.info = None;
        self.reply_len = self.handle(cfg, request, room, od, app);
        self.send_pending(cfg, esc, od)?;
        app.mailbox_served(od);
        Ok(())
    }

    /// The reply (header included) to mailbox `request` in `self.reply`, at most `room`
    /// bytes; returns its length (0: none).
    #[inline(never)]
    fn handle<D: Storage + ?Sized, A: Application<D> + ?Sized>(
        &mut self,
        cfg: &Config<'_>,
        request: &[u8],
        room: usize,
        od: &mut D,
        app: &mut A,
    ) -> usize {
        let (len, kind) = match request.get(..HEADER) {
            Some(&[l0, l1, _, _, _, t]) => (usize::from(u16::from_le_bytes([l0, l1])), t & 0x0F),
            _ => return self.error(mailbox_error::SYNTAX, room),
        };
        let Some(data) = request.get(HEADER..HEADER + len) else {
            return self.error(mailbox_error::INVALID_SIZE, room);
        };
        let foe = kind == TYPE_FOE && cfg.foe;
        // In BOOT only FoE is served (ETG.1000.6 §6.4.1).
        if !foe && (kind != TYPE_COE || !cfg.coe || self.state == state::BOOT) {
            return self.error(mailbox_error::UNSUPPORTED_PROTOCOL, room);
        }
        // CoE: the service (bits 12–15 of its header) and what follows.
        let (service, sdo) = match data.split_first_chunk::<2>() {
            Some((&[_, service], sdo)) => (service >> 4, sdo),
            None if foe => (0, data),
            None => return self.error(mailbox_error::SIZE_TOO_SHORT, room),
        };
        let info = service == 8 && cfg.describe.is_some();
        // Emergency, TxPDO, RxPDO and remote requests are not served.
        if !foe && !info && service != 2 {
            return self.error(mailbox_error::UNSUPPORTED_PROTOCOL, room);
        }
        // One reply area and one framing for FoE and CoE.
        let area = self.reply.get_mut(HEADER..room).unwrap_or(&mut []);
        let mut out = Out { buf: area, len: 0 };
        if foe {
            // Packets from the master carry its mailbox less the mailbox and FoE headers.
            let max_in = request.len().saturating_sub(HEADER + 6);
            foe::handle(&mut self.foe, data, max_in, app, &mut out);
        } else if let (true, Some(describe)) = (info, cfg.describe) {
            self.info = info::start(sdo, describe, &mut out);
        } else {
            let mut server = coe::Server {
                transfer: &mut self.transfer,
                buf: &mut self.buf,
                complete_access: cfg.complete_access,
                pdo_writable: self.state == state::PRE_OP,
            };
            server.handle(sdo, od, &mut out);
        }
        match out.len {
            0 => 0,
            n => self.frame(if foe { TYPE_FOE } else { TYPE_COE }, n),
        }
    }

    /// Writes the mailbox header before `n` bytes of data in `self.reply`; returns the
    /// length.
    #[inline(never)]
    fn frame(&mut self, kind: u8, n: usize) -> usize {
        // The counter runs 1..=7 (ETG.1000.4 §5.6: 0 is reserved for the first mailbox).
        self.counter = self.counter % 7 + 1;
        let len = u16::try_from(n).unwrap_or(u16::MAX).to_le_bytes();
        let header = [len[0], len[1], 0, 0, 0, kind | self.counter << 4];
        if let Some(h) = self.reply.get_mut(..HEADER) {
            h.copy_from_slice(&header);
        }
        HEADER + n
    }

    #[inline(never)]
    fn error(&mut self, detail: u16, room: usize) -> usize {
        let d = detail.to_le_bytes();
        let data = [0x01, 0x00, d[0], d[1]];
        match self.reply.get_mut(HEADER..HEADER + data.len()) {
            Some(area) if room >= HEADER + data.len() => {
                area.copy_from_slice(&data);
                self.frame(TYPE_ERROR, data.len())
            }
            _ => 0,
        }
    }

    /// The waiting reply into the read mailbox if it is empty, then the next one ready.
    #[inline(never)]
    fn send_pending<E: Esc + ?Sized, D: Storage + ?Sized>(
        &mut self,
        cfg: &Config<'_>,
        esc: &mut E,
        _od: &D,
    ) -> Result<(), E::Error> {
        let (_, Some(in_sm)) = mailboxes(cfg) else { return Ok(()) };
        let tx = SmRegs::read(esc, in_sm)?;
        if tx.status & SM_FULL != 0 || !tx.enabled() || self.state < state::PRE_OP {
            return Ok(());
        }
        let room = usize::from(tx.len).min(MBX);
        if self.reply_len == 0 {
            self.refill(cfg, room);
        }
        if self.reply_len == 0 {
            return Ok(());
        }
        // The whole area, to its last byte: that hands the mailbox to the master.
        if let Some(rest) = self.reply.get_mut(self.reply_len..room) {
            rest.fill(0);
        }
        esc.write(tx.start, self.reply.get(..room).unwrap_or(&[]))?;
        let mut at = room;
        while at < usize::from(tx.len) {
            let zeros = [0u8; 32];
            let n = (usize::from(tx.len) - at).min(zeros.len());
            let addr = tx.start.wrapping_add(u16::try_from(at).unwrap_or(u16::MAX));
            esc.write(addr, zeros.get(..n).unwrap_or(&[]))?;
            at += n;
        }
        self.reply_len = 0;
        self.refill(cfg, room);
        Ok(())
    }

    /// The next reply to send: a fragment of SDO Information, or an emergency.
    fn refill(&mut self, cfg: &Config<'_>, room: usize) {
        if let (Some(mut p), Some(describe)) = (self.info, cfg.describe) {
            let area = self.reply.get_mut(HEADER..room).unwrap_or(&mut []);
            let mut out = Out { buf: area, len: 0 };
            info::next(&mut p, describe, &mut out);
            let n = out.len;
            self.info = p.more().then_some(p);
            self.reply_len = self.frame(TYPE_COE, n);
        } else if let Some(e) = self.emergency.take() {
            // CoE header: number 0, service 1 (emergency).
            let mut data = [0u8; 10];
            data[1] = 0x10;
            data[2..].copy_from_slice(&e);
            if let Some(area) = self.reply.get_mut(HEADER..HEADER + data.len()) {
                area.copy_from_slice(&data);
                self.reply_len = self.frame(TYPE_COE, data.len());
            }
        }
    }
}
