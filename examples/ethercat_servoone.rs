//! An LTI ServoOne on EtherCAT, with ethercrab: `cargo run -p odc-examples --features ethercrab
//! --example ethercat_servoone -- eth0` (raw sockets: root or `CAP_NET_RAW`).
//!
//! The code generated from `esi/servoone.xml` (role master) gives the start-up, the typed
//! dictionary and the identity to look for. The ServoOne has no factory PDO mapping (its ESI
//! assigns nothing, manual 8.3), so after the generated `startup::configure` the program maps
//! its own cyclic-synchronous-position image (controlword and target position out, statusword
//! and actual position in) with the structs below, whose mapping values come from the same
//! `#[derive(odc::Pdo)]` that packs them. Then: CSP mode (0x6060 = 8), distributed clocks
//! from the ESI's `DC` op-mode (SYNC0 every millisecond), OP, the CiA 402 walk to "operation
//! enabled", and a slow ramp of the target position, one step per cycle.

use std::error::Error;
use std::sync::Arc;
use std::time::Duration;

use ethercrab::std::{ethercat_now, tx_rx_task};
use ethercrab::subdevice_group::{CycleInfo, DcConfiguration};
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, SubDeviceRef, Timeouts, TxRxResponse};
use odc::Pdo;
use odc::cia402::{Controlword, ModeOfOperation, State, Statusword};
use odc::ethercat::ethercrab::{self as ec, wire::EtherCrabWireRead, wire::EtherCrabWireWrite};

/// The master side of `esi/servoone.xml` (a program uses part of it; the generated modules
/// allow the dead code that leaves).
mod servoone {
    odc::include_od!("servoone_ecat");
}
use servoone::{od, startup};

/// The outputs this program maps into RxPDO 1 (0x1600) for cyclic synchronous position.
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
struct CspOutputs {
    #[pdo(index = 0x6040, bits = 16)]
    controlword: Controlword,
    #[pdo(index = 0x607A)]
    target_position: i32,
}
odc::impl_wire!(CspOutputs);

/// The inputs this program maps into TxPDO 1 (0x1A00).
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
struct CspInputs {
    #[pdo(index = 0x6041, bits = 16)]
    statusword: Statusword,
    #[pdo(index = 0x6064)]
    position_actual_value: i32,
}
odc::impl_wire!(CspInputs);

const MAX_SUBDEVICES: usize = 16;
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
const MAX_FRAMES: usize = 16;
const PDI_LEN: usize = 64;
/// The bus cycle and SYNC0 period (the ServoOne takes multiples of 125 µs).
const CYCLE: Duration = Duration::from_millis(1);
static PDU_STORAGE: PduStorage<MAX_FRAMES, MAX_PDU_DATA> = PduStorage::new();

/// Maps `T`'s entries into the mapping object `pdo` and assigns it alone to sync manager
/// `sm` (0x1C10 + sm), in the order ETG.1020 gives: clear, fill, count.
async fn map<T: Pdo, S>(
    sd: &SubDeviceRef<'_, S>,
    sm: u8,
    pdo: u16,
) -> Result<(), ethercrab::error::Error>
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let assign = 0x1C10 + u16::from(sm);
    sd.sdo_write(assign, 0, 0u8).await?;
    sd.sdo_write(pdo, 0, 0u8).await?;
    for (sub, entry) in (1u8..).zip(T::MAPPING) {
        sd.sdo_write(pdo, sub, entry.to_u32()).await?;
    }
    sd.sdo_write(pdo, 0, u8::try_from(T::MAPPING.len()).unwrap_or(u8::MAX)).await?;
    sd.sdo_write(assign, 1, pdo).await?;
    sd.sdo_write(assign, 0, 1u8).await
}

fn main() -> Result<(), Box<dyn Error>> {
    let interface = std::env::args().nth(1).ok_or("usage: ethercat_servoone <interface>")?;
    smol::block_on(run(&interface))
}

async fn run(interface: &str) -> Result<(), Box<dyn Error>> {
    let (tx, rx, pdu_loop) = PDU_STORAGE.try_split().map_err(|()| "PDU storage split twice")?;
    let maindevice = Arc::new(MainDevice::new(
        pdu_loop,
        Timeouts { mailbox_response: Duration::from_millis(1000), ..Timeouts::default() },
        MainDeviceConfig::default(),
    ));
    smol::spawn(tx_rx_task(interface, tx, rx)?).detach();

    // INIT → PRE-OP: the mailbox works, the process data do not yet.
    let mut group = maindevice.init_single_group::<MAX_SUBDEVICES, PDI_LEN>(ethercat_now).await?;
    // The ESI's distributed-clocks mode named `DC` (AssignActivate 0x0300: SYNC0).
    let dc = startup::DC_OP_MODES.iter().find(|m| m.name == "DC").ok_or("no DC op-mode")?;
    let mut drive = None;
    for (i, mut sd) in group.iter_mut(&maindevice).enumerate() {
        // Checks vendor, product and revision against the ESI, then writes its start-up.
        match startup::configure(&sd).await {
            Ok(()) => {
                map::<CspOutputs, _>(&sd, 2, 0x1600).await?;
                map::<CspInputs, _>(&sd, 3, 0x1A00).await?;
                // Typed by the generated descriptor: 0x6060 is an i8.
                let csp = ModeOfOperation::CyclicSyncPosition.to_i8();
                ec::sdo_write(&sd, &od::MODES_OF_OPERATION, csp).await?;
                sd.set_dc_sync(ec::dc_sync(dc, CYCLE));
                drive = Some(i);
            }
            Err(ec::ConfigureError::WrongDevice { .. }) => {}
            Err(e) => return Err(e.into()),
        }
    }
    let drive = drive.ok_or("no ServoOne on the bus")?;

    // PRE-OP with process data (ethercrab reads the mapping back and sizes the image), the
    // SYNC0 pulses, SAFE-OP, then OP once every SubDevice follows the clock.
    let group = group.into_pre_op_pdi(&maindevice).await?;
    let group = group
        .configure_dc_sync(
            &maindevice,
            DcConfiguration {
                start_delay: Duration::from_millis(100),
                sync0_period: CYCLE,
                sync0_shift: CYCLE / 2,
            },
        )
        .await?;
    let group = group.into_safe_op(&maindevice).await?;
    let group = group.request_into_op(&maindevice).await?;
    let mut target = None;
    for _cycle in 0..20_000 {
        let now = std::time::Instant::now();
        let TxRxResponse { extra: CycleInfo { next_cycle_wait, .. }, .. } =
            group.tx_rx_dc(&maindevice).await?;
        let sd = group.subdevice(&maindevice, drive)?;
        let inputs = CspInputs::unpack_from_slice(&sd.inputs_raw())?;
        let state = inputs.statusword.state();
        // Hold the actual position until enabled, so enabling does not jump.
        let position = match (state, target) {
            (Some(State::OperationEnabled), Some(t)) => t + 10,
            _ => inputs.position_actual_value,
        };
        target = Some(position);
        let controlword = match state.and_then(State::next_command_towards_enabled) {
            Some(cw) => cw,
            None => Controlword::ENABLE_OPERATION,
        };
        let outputs = CspOutputs { controlword, target_position: position };
        outputs.pack_to_slice(&mut sd.outputs_raw_mut())?;
        smol::Timer::at(now + next_cycle_wait).await;
    }
    let group = group.into_safe_op(&maindevice).await?;
    let group = group.into_pre_op(&maindevice).await?;
    group.into_init(&maindevice).await?;
    Ok(())
}
