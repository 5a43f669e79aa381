//! [`SubDevice`]: an ESC with the application a device's firmware runs behind it: the AL
//! state machine and its checks, the mailbox with the CoE server, process data between the
//! sync managers and the dictionary, and a CiA 402 drive when the device is one.

use odc::cia402::{DeviceControl, Drive};
use odc_model::Device;
use odc_model::ethercat::SmUsage;

use super::al::{self, SmSpec, code, state};
use super::esc::{Esc, Passing, SM_FULL};
use super::frame::Datagram;
use super::mailbox::Mailbox;
use super::pdo::{self, Layout};
use super::registers as reg;
use crate::ModelDictionary;

/// A simulated EtherCAT SubDevice built from an ESI device.
#[derive(Debug)]
pub struct SubDevice {
    esc: Esc,
    name: String,
    sms: Vec<SmSpec>,
    mailbox: Mailbox,
    od: ModelDictionary,
    /// The AL state (AL status bits 0–3).
    state: u8,
    /// The layouts of the process data sync managers, fixed on entering SAFE-OP.
    layouts: Vec<(u8, Layout)>,
    /// The layouts the ESI gives the sync managers (for a device without assignment
    /// objects).
    fixed: Vec<(u8, Layout)>,
    drive: Option<Drive>,
    /// Mailbox replies waiting for the read mailbox (fragments after the first).
    pending: std::collections::VecDeque<Vec<u8>>,
    last_ns: Option<u64>,
    carry_ns: u64,
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

/// The device with 0x1C00, the sync managers' communication types (ETG.1000.6: 1 mailbox
/// out, 2 mailbox in, 3 outputs, 4 inputs, 0 unused), built from the ESI's `Sm` elements when
/// a CoE device's dictionary leaves it out. The firmware of such a device has it, and masters
/// read it: SOEM's `config_map` asks for 0x1C00 before it reads a CoE device's PDO assignment.
/// `None` when there is nothing to add.
fn sm_types(device: &Device, sms: &[odc_model::ethercat::SyncManager]) -> Option<Device> {
    use odc_model::{Access, DataType, Object, ObjectKind, Span, Spanned, SubObject, Value};
    let coe = device
        .ethercat
        .as_deref()
        .is_some_and(|e| e.mailbox.as_ref().is_some_and(|m| m.coe.is_some()));
    if !coe || sms.is_empty() || device.objects.contains_key(&0x1C00) {
        return None;
    }
    let mut object = Object::new(0x1C00, "Sync manager type", ObjectKind::Array, Span::DUMMY);
    let count = u8::try_from(sms.len()).unwrap_or(u8::MAX);
    let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
    s0.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(count))));
    object.subs.insert(0, s0);
    for (n, sm) in (1..=count).zip(sms) {
        let mut s = SubObject::new(n, format!("SubIndex {n:03}"), DataType::Unsigned8, Access::Ro);
        s.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(kind(&sm.usage)))));
        object.subs.insert(n, s);
    }
    let mut device = device.clone();
    device.objects.insert(0x1C00, object);
    Some(device)
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
        let image = odc_sii::write(device)?;
        let ram = u16::try_from(reg::MEMORY).unwrap_or(u16::MAX);
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
        let with_types = sm_types(device, &ecat.sync_managers);
        let od = ModelDictionary::new(with_types.as_ref().unwrap_or(device), None);
        let fixed = ecat
            .sync_managers
            .iter()
            .map(|sm| (sm.number, pdo::fixed_layout(device, sm.number)))
            .collect();
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
            esc: Esc::new(image, 0, false),
            name,
            sms,
            mailbox: Mailbox::new(device),
            od,
            state: state::INIT,
            layouts: Vec::new(),
            fixed,
            drive,
            pending: Default::default(),
            last_ns: None,
            carry_ns: 0,
        };
        dev.restart_drive();
        Ok(dev)
    }

    /// Powers the ESC on again as device number `position` of a chain, with a device after
    /// it or not (the link of port 1), and a local clock of its own.
    pub(super) fn place(&mut self, position: usize, downstream: bool) {
        let image = self.esc.sii.image().to_vec();
        // Devices power up at different moments: a clock 1.234567 s apart per position.
        let base = 1_234_567_000u64.wrapping_mul(position as u64 + 1);
        self.esc = Esc::new(image, base, downstream);
        self.state = state::INIT;
        self.deactivate_process_data();
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

    /// The AL state (1 INIT, 2 PRE-OP, 4 SAFE-OP, 8 OP).
    pub fn al_state(&self) -> u8 {
        self.state
    }

    /// The AL status code (0 without error).
    pub fn al_status_code(&self) -> u16 {
        self.esc.u16(reg::AL_STATUS_CODE)
    }

    /// Whether it runs a CiA 402 drive.
    pub fn is_drive(&self) -> bool {
        self.drive.is_some()
    }

    fn restart_drive(&mut self) {
        if let Some(drive) = &mut self.drive {
            let option = self.od.get::<i16>(0x605A, 0).unwrap_or(2);
            *drive = Drive::new().with_control(DeviceControl::new().with_quick_stop_option(option));
            drive.start(&mut self.od);
        }
    }

    /// Executes one datagram as it passes, then what the application does with it.
    pub(super) fn execute(&mut self, d: &mut Datagram<'_>, at: &Passing) {
        self.esc.execute(d, at);
        let ev = self.esc.take_events();
        if ev.al_control {
            self.al_control();
        }
        if ev.mailbox_received {
            self.mailbox_received();
        }
        if ev.mailbox_read {
            self.send_pending();
        }
    }

    /// After the frame has passed: process data and the drive.
    pub(super) fn after_frame(&mut self, at: &Passing) {
        if self.state != state::SAFE_OP && self.state != state::OP {
            return;
        }
        if self.state == state::OP {
            for (sm, layout) in &self.layouts {
                let regs = self.esc.sm(*sm);
                if regs.master_writes() {
                    let image = self.esc.bytes(regs.start, usize::from(regs.len));
                    pdo::image_to_dictionary(layout, image, &mut self.od);
                }
            }
        }
        let dt = match self.last_ns {
            Some(last) => {
                let ns = at.arrival_ns.saturating_sub(last) + self.carry_ns;
                self.carry_ns = ns % 1000;
                odc::time::Duration::from_micros(ns / 1000)
            }
            None => odc::time::Duration::ZERO,
        };
        self.last_ns = Some(at.arrival_ns);
        if let Some(drive) = &mut self.drive {
            drive.update(&mut self.od);
            drive.step(&mut self.od, dt);
        }
        self.write_inputs();
    }

    fn write_inputs(&mut self) {
        for (sm, layout) in &self.layouts {
            let regs = self.esc.sm(*sm);
            if !regs.master_writes() {
                let mut image = vec![0u8; usize::from(regs.len)];
                pdo::dictionary_to_image(layout, &self.od, &mut image);
                self.esc.set_bytes(regs.start, &image);
            }
        }
    }

    fn set_status(&mut self, error: bool, status_code: u16) {
        self.esc.set_u16(reg::AL_STATUS, u16::from(self.state) | u16::from(error) << 4);
        self.esc.set_u16(reg::AL_STATUS_CODE, status_code);
    }

    /// A write of AL control: the requested state, checked; on failure the device stays
    /// where it is with the error flag and the status code.
    fn al_control(&mut self) {
        let control = self.esc.u16(reg::AL_CONTROL);
        let requested = (control & 0x0F) as u8;
        let ack = control & 0x10 != 0;
        let error = self.esc.u16(reg::AL_STATUS) & 0x10 != 0;
        // With the error flag set, only an acknowledgement or a step down is taken
        // (ETG.1000.6 §6.4.1.3).
        if error && !ack && requested > self.state {
            return;
        }
        match self.transition(requested) {
            Ok(()) => self.set_status(false, code::NONE),
            Err(c) => self.set_status(true, c),
        }
    }

    fn transition(&mut self, to: u8) -> Result<(), u16> {
        al::allowed(self.state, to)?;
        let ram = u32::try_from(reg::MEMORY).unwrap_or(u32::MAX);
        match to {
            state::INIT => {
                self.mailbox.reset();
                self.pending.clear();
                self.deactivate_process_data();
            }
            state::PRE_OP => {
                al::check_mailbox(&self.esc, &self.sms, ram)?;
                if self.state >= state::SAFE_OP {
                    self.deactivate_process_data();
                }
            }
            state::SAFE_OP if self.state == state::PRE_OP => {
                al::check_mailbox(&self.esc, &self.sms, ram)?;
                let mut layouts = Vec::new();
                for spec in self.sms.iter().filter(|s| matches!(s.kind, al::OUTPUTS | al::INPUTS)) {
                    let err = match spec.kind {
                        al::OUTPUTS => code::INVALID_OUTPUT_CONFIG,
                        _ => code::INVALID_INPUT_CONFIG,
                    };
                    let layout = match pdo::layout(&self.od, spec.number).map_err(|_| err)? {
                        Some(layout) => layout,
                        None => self
                            .fixed
                            .iter()
                            .find(|(n, _)| *n == spec.number)
                            .map(|(_, l)| l.clone())
                            .unwrap_or_default(),
                    };
                    layouts.push((spec.number, layout));
                }
                let bytes =
                    |n: u8| layouts.iter().find(|(sm, _)| *sm == n).map_or(0, |(_, l)| l.bytes());
                al::check_process_data(&self.esc, &self.sms, bytes)?;
                self.layouts = layouts;
                for spec in &self.sms {
                    if matches!(spec.kind, al::OUTPUTS | al::INPUTS) {
                        self.esc.set_sm_pdi_control(spec.number, 0);
                    }
                }
                self.write_inputs();
            }
            state::SAFE_OP | state::OP => {}
            _ => {}
        }
        self.state = to;
        Ok(())
    }

    /// Outside SAFE-OP and OP the application keeps the process data sync managers
    /// deactivated (PDI control bit 0): the master's process data access is not counted.
    fn deactivate_process_data(&mut self) {
        self.layouts.clear();
        for spec in &self.sms {
            if matches!(spec.kind, al::OUTPUTS | al::INPUTS) {
                self.esc.set_sm_pdi_control(spec.number, 1);
            }
        }
    }

    /// The write mailbox is full: read it, answer in the read mailbox.
    fn mailbox_received(&mut self) {
        let find = |kind: u8| self.sms.iter().find(|s| s.kind == kind).map(|s| s.number);
        let (Some(out_sm), Some(in_sm)) = (find(al::MBOX_OUT), find(al::MBOX_IN)) else {
            return;
        };
        let (rx, tx) = (self.esc.sm(out_sm), self.esc.sm(in_sm));
        let request = self.esc.bytes(rx.start, usize::from(rx.len)).to_vec();
        // The application has read the mailbox: empty again.
        self.esc.set_sm_status(out_sm, rx.status & !SM_FULL);
        if self.state < state::PRE_OP || tx.activate & 1 == 0 {
            return;
        }
        let pre_op = self.state == state::PRE_OP;
        // PDO assignment and mapping may be written in PRE-OP only (ETG.1000.6 §5.6.7.4).
        let writable = move |index: u16| pre_op || !pdo::is_pdo_config(index);
        let replies = self.mailbox.handle(&request, usize::from(tx.len), &mut self.od, &writable);
        self.pending = replies.into();
        self.send_pending();
        if let Some(drive) = &mut self.drive {
            drive.update(&mut self.od);
        }
    }

    /// The next waiting reply into the read mailbox, if it is empty.
    fn send_pending(&mut self) {
        let Some(in_sm) = self.sms.iter().find(|s| s.kind == al::MBOX_IN).map(|s| s.number) else {
            return;
        };
        let tx = self.esc.sm(in_sm);
        if tx.status & SM_FULL != 0 || tx.activate & 1 == 0 {
            return;
        }
        if let Some(mut reply) = self.pending.pop_front() {
            reply.resize(usize::from(tx.len), 0);
            self.esc.set_bytes(tx.start, &reply);
            self.esc.set_sm_status(in_sm, tx.status | SM_FULL);
        }
    }
}
