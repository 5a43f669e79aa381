//! [`SubDevice`]: an emulated ESC with the firmware stack a device runs behind it, the
//! runtime's [`odc::ethercat::subdevice`] (AL state machine and its checks, the mailbox with
//! CoE, process data between the sync managers and the dictionary), on the runtime's own
//! dictionary table built from the model, and a CiA 402 drive when the device is one.

use odc::cia402::{DeviceControl, Drive};
use odc::ethercat::subdevice::pdo::{self, Mapped};
use odc::ethercat::subdevice::{self as stack, Application, Config, SmSpec, al};
use odc_model::Device;
use odc_model::ethercat::SmUsage;

use super::esc::{Esc, Passing, Pdi};
use super::frame::Datagram;
use super::info::ModelInfo;
use super::registers as reg;
use super::spi::{EscSpiChip, Lan9252Chip, PdiPath};
use crate::ModelDictionary;

/// The firmware stack's sizes in the simulator: mailboxes up to 2 KiB served whole, SDO values
/// up to [`crate::SDO_BUFFER`] bytes, 1024 mapped entries, process images of the whole RAM.
type Stack = stack::SubDevice<2048, { crate::SDO_BUFFER }, 1024, { reg::RAM_KIB as usize * 1024 }>;

/// A simulated EtherCAT SubDevice built from an ESI device.
#[derive(Debug)]
pub struct SubDevice {
    esc: Esc,
    name: String,
    sms: Vec<SmSpec>,
    /// The mapping values the ESI gives the sync managers (for a device without assignment
    /// objects): `(sm, index << 16 | sub << 8 | bits)`.
    fixed: Vec<(u8, u32)>,
    coe: Option<odc_model::ethercat::CoE>,
    info: Option<Info>,
    stack: Box<Stack>,
    od: ModelDictionary,
    app: Firmware,
    /// The process data of an ESC without a microcontroller (device emulation, see
    /// [`Esc::device_emulation`]): no firmware runs, its fixed PDOs stand for the I/O pins
    /// the ESC's digital I/O PDI drives. Empty for a device with firmware.
    pins: Vec<Mapped>,
    /// How the firmware stack reaches the ESC, and the first failure on that path.
    pdi: PdiPath,
    pdi_error: Option<String>,
}

/// What the device's SDO Information serves.
#[derive(Debug)]
enum Info {
    /// The descriptions of the model the device was built from.
    Model(ModelInfo),
    /// A generated dictionary's `slave::DESCRIPTION`, as a firmware serves it.
    Generated(odc::slave::Description<'static>),
}

impl Info {
    fn describe(&self) -> &dyn stack::Describe {
        match self {
            Info::Model(m) => m,
            Info::Generated(d) => d,
        }
    }
}

/// Runs `$self.stack.$method` with `$cfg` through the PDI path of `$self`; a failure of the
/// SPI path (the emulated chip refused a frame) is kept, the first one.
macro_rules! through_pdi {
    ($self:ident, $method:ident, $cfg:expr) => {{
        let cfg = $cfg;
        let result = match $self.pdi {
            PdiPath::Direct => {
                let Ok(()) = $self.stack.$method(
                    &cfg,
                    &mut Pdi(&mut $self.esc),
                    &mut $self.od,
                    &mut $self.app,
                );
                Ok(())
            }
            PdiPath::EscSpi => {
                let mut esc = odc::ethercat::esc_spi::beckhoff::EscSpi::new(EscSpiChip::new(Pdi(
                    &mut $self.esc,
                )));
                $self
                    .stack
                    .$method(&cfg, &mut esc, &mut $self.od, &mut $self.app)
                    .map_err(|e| e.to_string())
            }
            PdiPath::Lan9252 => {
                let mut esc = odc::ethercat::esc_spi::lan9252::Lan9252::new(Lan9252Chip::new(Pdi(
                    &mut $self.esc,
                )));
                $self
                    .stack
                    .$method(&cfg, &mut esc, &mut $self.od, &mut $self.app)
                    .map_err(|e| e.to_string())
            }
        };
        if let Err(e) = result {
            $self.pdi_error.get_or_insert(e);
        }
    }};
}

/// What the device's application does: a CiA 402 drive when it is one, stepped by the time
/// between frames.
#[derive(Debug)]
struct Firmware {
    drive: Option<Drive>,
    last_ns: Option<u64>,
    carry_ns: u64,
    dt: odc::time::Duration,
}

impl Application<ModelDictionary> for Firmware {
    fn cycle(&mut self, od: &mut ModelDictionary, _state: u8) {
        if let Some(drive) = &mut self.drive {
            drive.update(od);
            drive.step(od, self.dt);
        }
    }

    fn mailbox_served(&mut self, od: &mut ModelDictionary) {
        if let Some(drive) = &mut self.drive {
            drive.update(od);
        }
    }
}

/// The mapping values of the ESI's PDOs of sync manager `sm` (`RxPdo@Sm`, `TxPdo@Sm`, in file
/// order): what a device without assignment objects serves, and what its SII's PDO
/// categories tell the master.
fn fixed_mapping(device: &Device, sm: u8) -> impl Iterator<Item = (u8, u32)> + '_ {
    device.pdos.iter().filter(move |p| p.sync_manager == Some(sm)).flat_map(move |pdo| {
        pdo.entries.iter().map(move |e| {
            let index = if e.is_gap() { 0 } else { u32::from(e.index) };
            (sm, index << 16 | u32::from(e.sub) << 8 | u32::from(e.bits))
        })
    })
}

/// The fixed PDOs of the process data sync managers, laid out as the firmware stack lays them
/// out (for an ESC without a microcontroller, whose I/O they describe).
fn pins(sms: &[SmSpec], fixed: &[(u8, u32)]) -> Vec<Mapped> {
    let mut entries = vec![Mapped::default(); fixed.len()];
    let mut sink = pdo::Sink { entries: &mut entries, used: 0 };
    for spec in sms.iter().filter(|s| matches!(s.kind, al::OUTPUTS | al::INPUTS)) {
        // Room for every fixed entry was made above: a refusal cannot happen.
        let _ = pdo::fixed(spec.number, fixed, &mut sink);
    }
    let used = sink.used;
    entries.truncate(used);
    entries
}

fn kind(usage: &SmUsage) -> u8 {
    match usage {
        SmUsage::MBoxOut => al::MBOX_OUT,
        SmUsage::MBoxIn => al::MBOX_IN,
        SmUsage::Outputs => al::OUTPUTS,
        SmUsage::Inputs => al::INPUTS,
        _ => 0,
    }
}

/// The byte of SII word 0x001C, the mailbox protocols (ETG.2010 Table 2), with SoE's bit.
const SII_MAILBOX_PROTOCOLS: usize = 0x1C * 2;
const SII_SOE: u8 = 0x10;

/// The process RAM of the device's ESC in KiB: the default ([`reg::RAM_KIB`], an ET1100's)
/// or, where the ESI places a sync manager beyond it, enough to hold it (up to
/// [`reg::MAX_RAM_KIB`], an IP core's). The ESI does not name the ESC, but its sync managers
/// sit in its RAM: Beckhoff's EL6695 has its inputs at 0x8E00, which an 8 KiB ESC does not
/// have, and the FMMU reading them counted nothing (working counter 0).
fn ram_kib(sms: &[odc_model::ethercat::SyncManager]) -> u8 {
    let end = sms
        .iter()
        .filter_map(|sm| {
            let start = u32::from(sm.start_address.as_ref()?.value);
            Some(start.saturating_add(sm.default_size.unwrap_or(0).max(sm.min_size.unwrap_or(0))))
        })
        .max()
        .unwrap_or(0);
    let kib = end.saturating_sub(u32::from(reg::PROCESS_RAM)).div_ceil(1024);
    u8::try_from(kib).unwrap_or(u8::MAX).clamp(reg::RAM_KIB, reg::MAX_RAM_KIB)
}

/// The image with SoE cleared from its mailbox protocols. The firmware stack serves CoE and
/// not SoE (ETG.1000.6 §5.6, servo drives over EtherCAT): a device that announced it would send
/// a master that reads a SoE drive's mapping (SOEM's config_map, IDN S-0-0016 and S-0-0024 of
/// up to 8 drives) into requests answered "protocol not supported" (mailbox error 0x0002),
/// and SOEM then fails the mapping. Without it, SOEM maps the device from its SII PDO
/// categories, which hold the ESI's PDOs. `odc sii` still writes the ESI's protocols.
fn without_soe(mut image: Vec<u8>) -> Vec<u8> {
    if let Some(b) = image.get_mut(SII_MAILBOX_PROTOCOLS) {
        *b &= !SII_SOE;
    }
    image
}

impl SubDevice {
    /// The device of an ESI `device`: its EEPROM holds `odc_sii::write`'s image, its
    /// dictionary is the [`ModelDictionary`] of the device.
    ///
    /// # Errors
    ///
    /// The device has no ESI part, or its SII image cannot be written.
    pub fn new(device: &Device) -> Result<Self, odc_sii::Error> {
        let ecat = device.ethercat.as_deref().ok_or(odc_sii::Error::NotEtherCat)?;
        let image = without_soe(odc_sii::write(device)?);
        let ram_kib = ram_kib(&ecat.sync_managers);
        let ram = u16::try_from(usize::from(reg::PROCESS_RAM) + usize::from(ram_kib) * 1024)
            .unwrap_or(u16::MAX);
        let sms = ecat
            .sync_managers
            .iter()
            .map(|sm| SmSpec {
                number: sm.number,
                kind: kind(&sm.usage),
                min: sm.min_size.map_or(0, |v| u16::try_from(v).unwrap_or(u16::MAX)),
                max: sm.max_size.map_or(ram, |v| u16::try_from(v).unwrap_or(u16::MAX)),
                control: sm.control_byte.as_ref().map_or(0, |c| c.value),
            })
            .collect();
        // The objects a CoE device has and its ESI may leave out (0x1C00, 0x1C1n, mapping
        // objects) are in the model already: odc-esi synthesises them (`Origin::CoeImplied`),
        // and starts the file's empty ones with the ESI's PDOs (`EtherCat::esi_defaults`).
        let od = ModelDictionary::new(device, None);
        let fixed =
            ecat.sync_managers.iter().flat_map(|sm| fixed_mapping(device, sm.number)).collect();
        let coe = ecat.mailbox.as_ref().and_then(|m| m.coe.clone());
        let info = coe.as_ref().filter(|c| c.sdo_info).map(|_| Info::Model(ModelInfo::new(device)));
        let drive = od.is_drive().then(Drive::new);
        let name = ecat
            .names
            .iter()
            .find(|n| n.lc_id == Some(1033))
            .or(ecat.names.first())
            .map(|n| n.text.clone())
            .or_else(|| device.device_info.product_name.as_ref().map(|n| n.value.clone()))
            .unwrap_or_default();
        let mut dev = Self {
            esc: Esc::new(image, 0, false).with_ram_kib(ram_kib),
            name,
            sms,
            fixed,
            coe,
            info,
            stack: Box::new(Stack::new()),
            od,
            app: Firmware { drive, last_ns: None, carry_ns: 0, dt: odc::time::Duration::ZERO },
            pins: Vec::new(),
            pdi: PdiPath::Direct,
            pdi_error: None,
        };
        if dev.no_firmware() {
            dev.pins = pins(&dev.sms, &dev.fixed);
        }
        dev.restart_drive();
        Ok(dev)
    }

    /// Powers the ESC on again as device number `position` of a chain, with a device after
    /// it or not (the link of port 1), and a local clock of its own.
    pub(super) fn place(&mut self, position: usize, downstream: bool) {
        let image = self.esc.sii.image().to_vec();
        // Devices power up at different moments: a clock 1.234567 s apart per position.
        let base = 1_234_567_000u64.wrapping_mul(position as u64 + 1);
        self.esc = Esc::new(image, base, downstream).with_ram_kib(self.esc.ram_kib());
        *self.stack = Stack::new();
        self.deactivate_process_data();
    }

    /// The device with its firmware stack reaching the ESC through `path` (an SPI adapter of
    /// odc on an emulated chip, or directly).
    #[must_use]
    pub fn with_pdi(mut self, path: PdiPath) -> Self {
        self.pdi = path;
        self
    }

    /// The device serving SDO Information from `description` (the `slave::DESCRIPTION` that
    /// odc generates for the same ESI) instead of from the model, as its firmware would; a
    /// device whose ESI says no SDO Information (`CoE@SdoInfo`) still serves none.
    #[must_use]
    pub fn with_description(mut self, description: odc::slave::Description<'static>) -> Self {
        if self.info.is_some() {
            self.info = Some(Info::Generated(description));
        }
        self
    }

    /// The first frame the emulated SPI chip refused (a fault of the adapter), if any.
    pub fn pdi_error(&self) -> Option<&str> {
        self.pdi_error.as_deref()
    }

    /// The device's name (the ESI's English `Name`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The dictionary.
    pub fn dictionary(&self) -> &ModelDictionary {
        &self.od
    }

    /// The dictionary, to change values as the device's firmware would.
    pub fn dictionary_mut(&mut self) -> &mut ModelDictionary {
        &mut self.od
    }

    /// The ESC (its registers and memory).
    pub fn esc(&self) -> &Esc {
        &self.esc
    }

    /// An ESC without a microcontroller: device emulation set by its SII and no mailbox
    /// (a device with one has a microcontroller serving it, which runs the firmware stack;
    /// an XMC4800 or TMC8462 set-up may set device emulation too).
    fn no_firmware(&self) -> bool {
        self.esc.device_emulation()
            && !self.sms.iter().any(|s| matches!(s.kind, al::MBOX_OUT | al::MBOX_IN))
    }

    /// The AL state (1 INIT, 2 PRE-OP, 4 SAFE-OP, 8 OP).
    pub fn al_state(&self) -> u8 {
        match self.no_firmware() {
            true => self.esc.u8(reg::AL_STATUS) & 0x0F,
            false => self.stack.state(),
        }
    }

    /// The AL status code (0 without error).
    pub fn al_status_code(&self) -> u16 {
        self.esc.u16(reg::AL_STATUS_CODE)
    }

    /// Whether it runs a CiA 402 drive.
    pub fn is_drive(&self) -> bool {
        self.app.drive.is_some()
    }

    fn restart_drive(&mut self) {
        if let Some(drive) = &mut self.app.drive {
            let option = self.od.get::<i16>(0x605A, 0).unwrap_or(2);
            *drive = Drive::new().with_control(DeviceControl::new().with_quick_stop_option(option));
            drive.start(&mut self.od);
        }
    }

    /// Executes one datagram as it passes, then what the firmware does with it.
    pub(super) fn execute(&mut self, d: &mut Datagram<'_>, at: &Passing) {
        self.esc.execute(d, at);
        if self.no_firmware() {
            return;
        }
        if self.esc.al_event() != 0 || self.stack.has_pending() {
            let cfg = Config {
                sync_managers: &self.sms,
                fixed: &self.fixed,
                coe: self.coe.is_some(),
                complete_access: self.coe.as_ref().is_some_and(|c| c.complete_access),
                boot: false,
                foe: false,
                describe: self.info.as_ref().map(Info::describe),
            };
            through_pdi!(self, poll, cfg);
        }
    }

    /// After the frame has passed: process data and the drive.
    pub(super) fn after_frame(&mut self, at: &Passing) {
        if self.no_firmware() {
            self.drive_pins();
            return;
        }
        let state = self.stack.state();
        if state != al::state::SAFE_OP && state != al::state::OP {
            return;
        }
        let app = &mut self.app;
        app.dt = match app.last_ns {
            Some(last) => {
                let ns = at.arrival_ns.saturating_sub(last) + app.carry_ns;
                app.carry_ns = ns % 1000;
                odc::time::Duration::from_micros(ns / 1000)
            }
            None => odc::time::Duration::ZERO,
        };
        app.last_ns = Some(at.arrival_ns);
        let cfg = Config {
            sync_managers: &self.sms,
            fixed: &self.fixed,
            coe: self.coe.is_some(),
            complete_access: self.coe.as_ref().is_some_and(|c| c.complete_access),
            boot: false,
            foe: false,
            describe: None,
        };
        through_pdi!(self, cycle, cfg);
    }

    /// An ESC without a microcontroller in SAFE-OP or OP: its inputs (pins) into the process
    /// RAM where the master's sync manager puts them, and in OP the outputs onto its pins.
    /// The digital I/O PDI writes the inputs as any PDI does, so a sync manager in one-buffer
    /// (mailbox) mode, as Beckhoff's EL1252 has for its inputs (`ControlByte` 0x22), is full
    /// and the master's read is served (ESC datasheets, section I, sync manager one-buffer
    /// mode: the master reads a buffer only after the PDI wrote it).
    fn drive_pins(&mut self) {
        let state = self.esc.u8(reg::AL_STATUS) & 0x0F;
        if state != al::state::SAFE_OP && state != al::state::OP {
            return;
        }
        for spec in self.sms.iter().filter(|s| matches!(s.kind, al::OUTPUTS | al::INPUTS)) {
            let n = spec.number;
            let bits = self.pins.iter().filter(|e| e.sm == n).map(|e| e.bit + u16::from(e.bits));
            let len = usize::from(bits.max().unwrap_or(0).div_ceil(8));
            let start = self.esc.sm(n).start;
            if spec.kind == al::INPUTS {
                let mut image = self.esc.bytes(start, len).to_vec();
                pdo::dictionary_to_image(&self.pins, n, &self.od, &mut image);
                // The emulated ESC's PDI cannot fail (`Infallible`).
                let Ok(()) = stack::Esc::write(&mut Pdi(&mut self.esc), start, &image);
            } else if state == al::state::OP {
                let image = self.esc.bytes(start, len).to_vec();
                pdo::image_to_dictionary(&self.pins, n, &image, &mut self.od);
            }
        }
    }

    /// At power-on the firmware keeps the process data sync managers deactivated (PDI
    /// control bit 0): the master's process data access is not counted. An ESC without a
    /// microcontroller has no firmware to do so.
    fn deactivate_process_data(&mut self) {
        if self.no_firmware() {
            return;
        }
        for spec in &self.sms {
            if matches!(spec.kind, al::OUTPUTS | al::INPUTS) {
                self.esc.set_sm_pdi_control(spec.number, 1);
            }
        }
    }
}
