//! ethercrab (crates.io), an EtherCAT master nobody here wrote, against simulated devices
//! built from ESI files, in one process: ethercrab's frames go through
//! `PduStorage::try_split`'s `PduTx`, through the simulated chain, and back through `PduRx`
//! (no network). What ethercrab finds (identities read from the SII, names, states, process
//! image sizes) is compared with what the ESI says.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use odc_sim::ethercat::{Chain, EthercrabLink, SubDevice};

const MAX_FRAMES: usize = 16;
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);

/// The clock both sides use (ethercrab's DC set-up and the chain's): ns since the first use.
fn now() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

fn load(path: &str) -> odc_model::Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

/// A master on its own PDU storage (each test has one: `try_split` works once per storage).
fn master(chain: Chain) -> (MainDevice<'static>, EthercrabLink) {
    let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().unwrap();
    let link = EthercrabLink::start(tx, rx, chain, now);
    let config = MainDeviceConfig { dc_static_sync_iterations: 100, ..Default::default() };
    // ethercrab's defaults (10 ms for the EEPROM, 30 ms a PDU) suit a device that answers in
    // microseconds; the simulated one answers from a thread that a loaded 2-core machine may
    // not schedule for longer (Timeout(Eeprom) seen with 4 busy loops beside the tests).
    let timeouts = Timeouts {
        eeprom: Duration::from_secs(1),
        pdu: Duration::from_secs(1),
        ..Timeouts::default()
    };
    (MainDevice::new(pdu_loop, timeouts, config), link)
}

fn ethercrab_finds_the_servoone_and_reaches_pre_op() {
    let servoone = load("esi/servoone.xml");
    let chain = Chain::new(vec![SubDevice::new(&servoone).unwrap()]);
    let (maindevice, link) = master(chain);
    let group = smol::block_on(maindevice.init_single_group::<4, 64>(now)).unwrap();
    assert_eq!(group.len(), 1);
    let sd = group.iter(&maindevice).next().unwrap();
    let id = sd.identity();
    // esi/servoone.xml: Vendor/Id #x00000000, ProductCode #x00000000, RevisionNo #x00000000.
    assert_eq!((id.vendor_id, id.product_id, id.revision), (0, 0, 0));
    // ethercrab's name is the SII General category's order string (ETG.2010 Table 7,
    // OrderIdx: the ESI's `Type` text), its description the name string (`Name`, LcId 1033).
    assert_eq!(sd.name(), "ServoOne");
    let description = smol::block_on(sd.description()).unwrap().unwrap();
    assert_eq!(description.as_str(), "ServoOne EtherCAT (S0xx.xxx.xx3x.xxxx.x), CiA 402");
    assert_eq!(sd.configured_address(), 0x1000);
    let status = smol::block_on(sd.status()).unwrap();
    assert_eq!(format!("{:?}", status.0), "PreOp");
    // Distributed clocks: ethercrab wrote the offset that makes the device's system time
    // its own clock (`now`), then synchronised it with FRMW.
    let system_time: u64 = smol::block_on(sd.register_read(0x0910u16)).unwrap();
    let master_time = now();
    assert!(master_time.abs_diff(system_time) < 50_000_000, "{system_time} vs {master_time}");
    let (state, datagrams) = {
        let chain = link.chain();
        (chain.devices()[0].al_state(), chain.datagrams())
    };
    assert_eq!(state, 2, "the simulated device is in PRE-OP");
    let carried = link.stop();
    eprintln!("servoone to PRE-OP: {} frames, {datagrams} datagrams", carried.frames);
    assert!(carried.frames > 10, "{carried:?}");
    assert_eq!(carried.dropped, 0, "every frame ethercrab sent was an EtherCAT frame");
}

/// The master side odc generates from `esi/servoone.xml`: descriptors, start-up.
mod servoone {
    odc_macros::include_device!("../../esi/servoone.xml", role = "master");
}

use ethercrab::error::{CoeAbortCode, Error, MailboxError};
use odc::ethercat::ethercrab as ec;

/// The abort code of a failed SDO transfer.
fn abort<T: std::fmt::Debug>(r: Result<T, Error>) -> CoeAbortCode {
    match r {
        Err(Error::Mailbox(MailboxError::Aborted { code, .. })) => code,
        other => panic!("expected an SDO abort, got {other:?}"),
    }
}

fn sdo_through_generated_descriptors_values_and_aborts() {
    use servoone::od;
    let servoone = load("esi/servoone.xml");
    let chain = Chain::new(vec![SubDevice::new(&servoone).unwrap()]);
    let (maindevice, link) = master(chain);
    // The firmware's name in 0x1008 (STRING(32), no default in the ESI): 31 characters, more
    // than an expedited transfer carries.
    let name = "ServoOne simulated from its ESI";
    link.chain().devices_mut()[0]
        .dictionary_mut()
        .set(0x1008, 0, odc::VisibleString::<32>::new(name).unwrap())
        .unwrap();
    smol::block_on(async {
        let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        let sd = group.iter(&maindevice).next().unwrap();
        // The generated start-up: identity check, then 0x1C12:00 = 0 and 0x1C13:00 = 0.
        servoone::startup::configure(&sd).await.unwrap();
        // Expedited uploads: 0x1000 device type, the ESI's DefaultData 92010000 (LE).
        assert_eq!(ec::sdo_read(&sd, &od::DEVICE_TYPE).await.unwrap(), 0x0000_0192);
        assert_eq!(ec::sdo_read(&sd, &od::identity_object::NUMBER_OF_ENTRIES).await.unwrap(), 4);
        assert_eq!(
            ec::sdo_read(&sd, &od::rx_pdo_assign::NUMBER_OF_ASSIGNED_RX_PDOS).await.unwrap(),
            0
        );
        // Normal upload of a string longer than 4 bytes.
        let read = ec::sdo_read(&sd, &od::MANUFACTURER_DEVICE_NAME).await.unwrap();
        assert_eq!(read.as_str(), name);
        // Expedited downloads read back.
        ec::sdo_write(&sd, &od::MODES_OF_OPERATION, 8).await.unwrap();
        assert_eq!(ec::sdo_read(&sd, &od::MODES_OF_OPERATION).await.unwrap(), 8);
        ec::sdo_write(&sd, &od::TARGET_POSITION, -123_456).await.unwrap();
        assert_eq!(ec::sdo_read(&sd, &od::TARGET_POSITION).await.unwrap(), -123_456);
        // Aborts, with the codes of ETG.1000.6 Table 41 / CiA 301: a read-only object
        // written, an object and a sub-index that do not exist.
        let r = ec::sdo_write(&sd, &od::DEVICE_TYPE, 1).await;
        assert_eq!(abort(r), CoeAbortCode::ReadOnlyWrite);
        assert_eq!(abort(sd.sdo_read::<u32>(0x5FFE, 0).await), CoeAbortCode::NotFound);
        assert_eq!(abort(sd.sdo_read::<u8>(0x1018, 9).await), CoeAbortCode::SubIndexNotFound);
        // PDO assignment: sub-index 1 while sub-index 0 is not 0 (ETG.1000.6: 0x06010003),
        // an object that is no receive PDO (0x06090030), a mapping of an object the device
        // does not have (0x06040041).
        sd.sdo_write(0x1C12, 1, 0x1600u16).await.unwrap();
        sd.sdo_write(0x1C12, 0, 1u8).await.unwrap();
        assert_eq!(abort(sd.sdo_write(0x1C12, 1, 0x1601u16).await), CoeAbortCode::IndexOnly);
        sd.sdo_write(0x1C12, 0, 0u8).await.unwrap();
        let r = sd.sdo_write(0x1C12, 1, 0x1A00u16).await;
        assert_eq!(abort(r), CoeAbortCode::ValueOutOfRange);
        sd.sdo_write(0x1600, 0, 0u8).await.unwrap();
        let r = sd.sdo_write(0x1600, 1, 0x5FFE_0010u32).await;
        assert_eq!(abort(r), CoeAbortCode::PdoMappingFailed);
        // Complete access: the ESI says CompleteAccess="false", so the device refuses it.
        let r = sd.sdo_read::<u16>(0x1C12, ethercrab::SubIndex::Complete).await;
        assert_eq!(abort(r), CoeAbortCode::UnsupportedAccess);
    });
    let carried = link.stop();
    eprintln!("servoone SDO test: {} frames", carried.frames);
}

/// An SM register block (ETG.1000.4 Table 58) as ethercrab writes a u64: start, length,
/// control, status, activate, PDI control.
fn sm_regs(start: u16, len: u16, control: u8, enable: bool) -> u64 {
    let mut b = [0u8; 8];
    b[..2].copy_from_slice(&start.to_le_bytes());
    b[2..4].copy_from_slice(&len.to_le_bytes());
    b[4] = control;
    b[6] = u8::from(enable);
    u64::from_le_bytes(b)
}

fn al_state_machine_refuses_what_a_device_refuses() {
    let servoone = load("esi/servoone.xml");
    let (maindevice, link) = master(Chain::new(vec![SubDevice::new(&servoone).unwrap()]));
    smol::block_on(async {
        let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        let sd = group.iter(&maindevice).next().unwrap();
        let status = async || -> (u16, u16) {
            let s: u16 = sd.register_read(0x0130u16).await.unwrap();
            let c: u16 = sd.register_read(0x0134u16).await.unwrap();
            (s, c)
        };
        // PRE-OP → OP skips SAFE-OP: refused, error flag (bit 4), 0x0011.
        sd.register_write(0x0120u16, 0x0008u16).await.unwrap();
        assert_eq!(status().await, (0x0012, 0x0011));
        // With the error flag set, a request upwards without acknowledgement is ignored.
        sd.register_write(0x0120u16, 0x0004u16).await.unwrap();
        assert_eq!(status().await, (0x0012, 0x0011));
        // Acknowledged (bit 4): the error goes.
        sd.register_write(0x0120u16, 0x0012u16).await.unwrap();
        assert_eq!(status().await, (0x0002, 0x0000));
        // The assignment is empty (0x1C12:00 = 0), but SM2 is enabled with 4 bytes:
        // PRE-OP → SAFE-OP refused with 0x001D, invalid output configuration.
        sd.register_write(0x0810u16, sm_regs(0x1100, 4, 0x64, true)).await.unwrap();
        sd.register_write(0x0120u16, 0x0004u16).await.unwrap();
        assert_eq!(status().await, (0x0012, 0x001D));
        // SM2 off, SM3 (inputs) enabled with 2 bytes: 0x001E, invalid input configuration.
        sd.register_write(0x0810u16, sm_regs(0x1100, 0, 0x64, false)).await.unwrap();
        sd.register_write(0x0818u16, sm_regs(0x1180, 2, 0x20, true)).await.unwrap();
        sd.register_write(0x0120u16, 0x0014u16).await.unwrap();
        assert_eq!(status().await, (0x0012, 0x001E));
        // Both as the (empty) assignment says: SAFE-OP.
        sd.register_write(0x0818u16, sm_regs(0x1180, 0, 0x20, false)).await.unwrap();
        sd.register_write(0x0120u16, 0x0014u16).await.unwrap();
        assert_eq!(status().await, (0x0004, 0x0000));
        // Back to INIT; a write mailbox shorter than the ESI's MinSize (34): PRE-OP refused
        // with 0x0016, invalid mailbox configuration.
        sd.register_write(0x0120u16, 0x0001u16).await.unwrap();
        assert_eq!(status().await, (0x0001, 0x0000));
        sd.register_write(0x0800u16, sm_regs(0x1000, 16, 0x26, true)).await.unwrap();
        sd.register_write(0x0120u16, 0x0002u16).await.unwrap();
        assert_eq!(status().await, (0x0011, 0x0016));
        // INIT → SAFE-OP skips PRE-OP: 0x0011 (acknowledging the previous error).
        sd.register_write(0x0120u16, 0x0014u16).await.unwrap();
        assert_eq!(status().await, (0x0011, 0x0011));
    });
    link.stop();
}

fn segmented_upload_with_the_smallest_mailbox() {
    // The ServoOne with its mailboxes at the ESI's MinSize (34 bytes) instead of DefaultSize:
    // the SII then says 34, ethercrab sets 34, and a 31-byte string no longer fits one
    // mailbox (34 − 6 mailbox − 2 CoE − 8 SDO header = 18 bytes): the device answers with
    // an initiate carrying 18 bytes, then one upload segment of 13 (ETG.1000.6 §5.6.2.3 and
    // §5.6.2.6, checked byte by byte in `ethercat_coe.rs`).
    let mut servoone = load("esi/servoone.xml");
    for sm in &mut servoone.ethercat.as_mut().unwrap().sync_managers[..2] {
        sm.default_size = sm.min_size;
    }
    let name = "ServoOne simulated from its ESI";
    let mut device = SubDevice::new(&servoone).unwrap();
    device.dictionary_mut().set(0x1008, 0, odc::VisibleString::<32>::new(name).unwrap()).unwrap();
    let (maindevice, link) = master(Chain::new(vec![device]));
    smol::block_on(async {
        let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        let sd = group.iter(&maindevice).next().unwrap();
        let sm1_len: u16 = sd.register_read(0x080Au16).await.unwrap();
        assert_eq!(sm1_len, 34);
        // ethercrab 0.7.1 cannot decode the upload segment response: its `CoeCommand` has
        // no command specifier 0, which CiA 301 and ETG.1000.6 give the upload segment
        // response (tests/interop/README.md, "ethercrab and the simulated EtherCAT device").
        let r = ec::sdo_read(&sd, &servoone::od::MANUFACTURER_DEVICE_NAME).await;
        assert!(matches!(r, Err(Error::Wire(_))), "{r:?}");
    });
    link.stop();
}

/// The outputs the test maps into RxPDO 1 (0x1600) for cyclic synchronous position (as
/// `examples/ethercat_servoone.rs` does: the ServoOne has no factory mapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
struct CspOutputs {
    #[pdo(index = 0x6040, bits = 16)]
    controlword: odc::cia402::Controlword,
    #[pdo(index = 0x607A)]
    target_position: i32,
}
odc::impl_wire!(CspOutputs);

/// The inputs mapped into TxPDO 1 (0x1A00).
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
struct CspInputs {
    #[pdo(index = 0x6041, bits = 16)]
    statusword: odc::cia402::Statusword,
    #[pdo(index = 0x6064)]
    position_actual_value: i32,
}
odc::impl_wire!(CspInputs);

/// Maps `T`'s entries into `pdo` and assigns it alone to SM `sm` (ETG.1020's order: clear,
/// fill, count).
async fn map<T: odc::Pdo, S>(
    sd: &ethercrab::SubDeviceRef<'_, S>,
    sm: u8,
    pdo: u16,
) -> Result<(), Error>
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let assign = 0x1C10 + u16::from(sm);
    sd.sdo_write(assign, 0, 0u8).await?;
    sd.sdo_write(pdo, 0, 0u8).await?;
    for (sub, entry) in (1u8..).zip(T::MAPPING) {
        sd.sdo_write(pdo, sub, entry.to_u32()).await?;
    }
    sd.sdo_write(pdo, 0, T::MAPPING.len() as u8).await?;
    sd.sdo_write(assign, 1, pdo).await?;
    sd.sdo_write(assign, 0, 1u8).await
}

fn op_with_a_csp_ramp_for_a_thousand_cycles() {
    use ethercrab::EtherCrabWireRead;
    use ethercrab::EtherCrabWireWrite;
    use odc::Pdo;
    use odc::cia402::{Controlword, ModeOfOperation, State};
    use servoone::od;

    let servoone = load("esi/servoone.xml");
    let (maindevice, link) = master(Chain::new(vec![SubDevice::new(&servoone).unwrap()]));
    let (cycles_enabled, last_position, wkc) = smol::block_on(async {
        let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        {
            let sd = group.iter(&maindevice).next().unwrap();
            servoone::startup::configure(&sd).await.unwrap();
            map::<CspOutputs, _>(&sd, 2, 0x1600).await.unwrap();
            map::<CspInputs, _>(&sd, 3, 0x1A00).await.unwrap();
            let csp = ModeOfOperation::CyclicSyncPosition.to_i8();
            ec::sdo_write(&sd, &od::MODES_OF_OPERATION, csp).await.unwrap();
        }
        // ethercrab reads 0x1C12/0x1C13 and the mappings back and sizes the image.
        let group = group.into_pre_op_pdi(&maindevice).await.unwrap();
        {
            let sd = group.subdevice(&maindevice, 0).unwrap();
            assert_eq!(sd.outputs_raw().len(), CspOutputs::LEN);
            assert_eq!(sd.inputs_raw().len(), CspInputs::LEN);
            assert_eq!((CspOutputs::LEN, CspInputs::LEN), (6, 6));
        }
        let group = group.into_safe_op(&maindevice).await.unwrap();
        let group = group.into_op(&maindevice).await.unwrap();
        let mut target: Option<i32> = None;
        // The set-point the previous frame carried: the device takes the outputs after the
        // frame has passed and has its inputs ready for the next one, so a cycle reads what
        // the drive did with the previous cycle's outputs.
        let mut sent: Option<i32> = None;
        let mut enabled = 0u32;
        let mut last = 0;
        let mut wkc = 0;
        for _ in 0..1500 {
            let response = group.tx_rx(&maindevice).await.unwrap();
            wkc = response.working_counter;
            let sd = group.subdevice(&maindevice, 0).unwrap();
            let inputs = CspInputs::unpack_from_slice(&sd.inputs_raw()).unwrap();
            let state = inputs.statusword.state();
            if state == Some(State::OperationEnabled) {
                // The drive follows the set-point of the previous frame (an ideal CSP loop).
                if enabled > 0
                    && let Some(t) = sent
                {
                    assert_eq!(inputs.position_actual_value, t);
                }
                enabled += 1;
            }
            let position = match (state, target) {
                (Some(State::OperationEnabled), Some(t)) => t + 10,
                _ => inputs.position_actual_value,
            };
            sent = target;
            target = Some(position);
            last = inputs.position_actual_value;
            let controlword = state
                .and_then(State::next_command_towards_enabled)
                .unwrap_or(Controlword::ENABLE_OPERATION);
            let outputs = CspOutputs { controlword, target_position: position };
            outputs.pack_to_slice(&mut sd.outputs_raw_mut()).unwrap();
        }
        let group = group.into_safe_op(&maindevice).await.unwrap();
        let group = group.into_pre_op(&maindevice).await.unwrap();
        group.into_init(&maindevice).await.unwrap();
        (enabled, last, wkc)
    });
    // LRW through one device: read 1 + write 2 (ETG.1000.4 Table 7).
    assert_eq!(wkc, 3);
    assert!(cycles_enabled >= 1000, "{cycles_enabled} cycles in operation enabled");
    // The ramp: 10 increments a cycle while enabled, from 0, one cycle behind.
    assert_eq!(last_position, 10 * (cycles_enabled as i32 - 2));
    let (frames, datagrams) = {
        let chain = link.chain();
        (chain.frames(), chain.datagrams())
    };
    link.stop();
    eprintln!(
        "servoone OP: {cycles_enabled} cycles enabled, {frames} frames, {datagrams} datagrams"
    );
}

/// The default RxPDO 1 of the corpus drive (`ingenia__ecat402-drive.xml`, 0x1600).
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
#[pdo(max_bits = 88)]
struct DriveOutputs {
    #[pdo(index = 0x6040, bits = 16)]
    controlword: odc::cia402::Controlword,
    #[pdo(index = 0x607A)]
    target_position: i32,
    #[pdo(index = 0x60FF)]
    target_velocity: i32,
    #[pdo(index = 0x6060)]
    modes_of_operation: i8,
}
odc::impl_wire!(DriveOutputs);

/// Its default TxPDO 1 (0x1A00).
#[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
#[pdo(max_bits = 88)]
struct DriveInputs {
    #[pdo(index = 0x6041, bits = 16)]
    statusword: odc::cia402::Statusword,
    #[pdo(index = 0x6064)]
    position_actual_value: i32,
    #[pdo(index = 0x606C)]
    velocity_actual_value: i32,
    #[pdo(index = 0x6061)]
    modes_of_operation_display: i8,
}
odc::impl_wire!(DriveInputs);

/// Downloads the mapping and assignment an ESI gives its PDOs (`RxPdo@Sm`, `TxPdo@Sm`), in
/// ETG.1020's order: assignment cleared, each mapping cleared, filled and counted, then the
/// assignment filled and counted.
async fn esi_assignment<S>(sd: &ethercrab::SubDeviceRef<'_, S>, device: &odc_model::Device)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    for sm in [2u8, 3] {
        let assign = 0x1C10 + u16::from(sm);
        let pdos: Vec<_> = device.pdos.iter().filter(|p| p.sync_manager == Some(sm)).collect();
        sd.sdo_write(assign, 0, 0u8).await.unwrap();
        for pdo in &pdos {
            sd.sdo_write(pdo.mapping_index, 0, 0u8).await.unwrap();
            for (sub, e) in (1u8..).zip(&pdo.entries) {
                let v = u32::from(e.index) << 16 | u32::from(e.sub) << 8 | u32::from(e.bits);
                sd.sdo_write(pdo.mapping_index, sub, v).await.unwrap();
            }
            sd.sdo_write(pdo.mapping_index, 0, pdo.entries.len() as u8).await.unwrap();
        }
        for (sub, pdo) in (1u8..).zip(&pdos) {
            sd.sdo_write(assign, sub, pdo.mapping_index).await.unwrap();
        }
        sd.sdo_write(assign, 0, pdos.len() as u8).await.unwrap();
    }
}

/// A device of the real-world corpus (`ODC_CORPUS`, found by the build script).
fn load_corpus(file: &str, select: Option<&str>) -> odc_model::Device {
    let path = odc_tests_support::corpus().join("esi").join(file);
    let mut options = odc_pipeline::Options::new();
    if let Some(s) = select {
        options = options.select(odc_pipeline::Select::Spec(s.into()));
    }
    let loaded = odc_pipeline::load(&path, &options).unwrap();
    loaded.device().unwrap().clone()
}

fn a_chain_of_three_to_op() {
    use ethercrab::EtherCrabWireRead;
    use ethercrab::EtherCrabWireWrite;
    use odc::cia402::{Controlword, ModeOfOperation, State};

    let servoone = load("esi/servoone.xml");
    // A Beckhoff terminal with fixed PDOs and no mailbox, and a CiA 402 drive with fixed PDOs.
    let el2008 = load_corpus("beckhoff__Beckhoff_EL2xxx.xml", Some("EL2008"));
    let drive = load_corpus("ingenia__ecat402-drive.xml", None);
    let devices = [&servoone, &el2008, &drive].map(|d| SubDevice::new(d).unwrap());
    let (maindevice, link) = master(Chain::new(devices.into()));
    let (enabled, terminal_byte) = smol::block_on(async {
        let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        assert_eq!(group.len(), 3);
        let ids: Vec<_> = group
            .iter(&maindevice)
            .map(|sd| {
                let id = sd.identity();
                (sd.name().to_string(), id.vendor_id, id.product_id, id.revision)
            })
            .collect();
        // The identities of the three ESIs (Vendor/Id, Type@ProductCode, Type@RevisionNo),
        // as ethercrab reads them from each SII.
        assert_eq!(
            ids,
            [
                ("ServoOne".to_string(), 0, 0, 0),
                ("EL2008".to_string(), 2, 0x07D8_3052, 0x0010_0000),
                // Vendor #x0000029c, ProductCode 61935618, RevisionNo 327685 (decimal).
                ("EVS-NET-01".to_string(), 0x29C, 61_935_618, 327_685),
            ]
        );
        {
            let mut sds = group.iter(&maindevice);
            let sd = sds.next().unwrap();
            servoone::startup::configure(&sd).await.unwrap();
            map::<CspOutputs, _>(&sd, 2, 0x1600).await.unwrap();
            map::<CspInputs, _>(&sd, 3, 0x1A00).await.unwrap();
            let csp = ModeOfOperation::CyclicSyncPosition.to_i8();
            sd.sdo_write(0x6060, 0, csp).await.unwrap();
            // The drive's ESI assigns its PDOs (`@Sm`) but its 0x1C12/0x1C13 start empty: the
            // master downloads the ESI's mapping and assignment (what odc's generated
            // `startup::configure` does for it).
            esi_assignment(&sds.nth(1).unwrap(), &drive).await;
        }
        let group = group.into_pre_op_pdi(&maindevice).await.unwrap();
        // The sizes ethercrab computed: from CoE (ServoOne, drive) and from the SII's PDO
        // categories (EL2008: eight 1-bit outputs).
        let sizes: Vec<_> = group
            .iter(&maindevice)
            .map(|sd| (sd.outputs_raw().len(), sd.inputs_raw().len()))
            .collect();
        // The drive's default assignment (0x1C12/0x1C13 → 0x1600/0x1A00, 11 bytes each).
        assert_eq!(sizes, [(6, 6), (1, 0), (11, 11)]);
        let group = group.into_safe_op(&maindevice).await.unwrap();
        let group = group.into_op(&maindevice).await.unwrap();
        let mut targets = [None::<i32>; 2];
        let mut enabled = [0u32; 2];
        let mut byte = 0u8;
        for cycle in 0..1200u32 {
            let response = group.tx_rx(&maindevice).await.unwrap();
            // Two drives read and write (3 each), the terminal is written (2).
            assert_eq!(response.working_counter, 8);
            for (k, i) in [0usize, 2].into_iter().enumerate() {
                let sd = group.subdevice(&maindevice, i).unwrap();
                let (statusword, actual) = match i {
                    0 => {
                        let inputs = CspInputs::unpack_from_slice(&sd.inputs_raw()).unwrap();
                        (inputs.statusword, inputs.position_actual_value)
                    }
                    _ => {
                        let inputs = DriveInputs::unpack_from_slice(&sd.inputs_raw()).unwrap();
                        (inputs.statusword, inputs.position_actual_value)
                    }
                };
                let state = statusword.state();
                if state == Some(State::OperationEnabled) {
                    enabled[k] += 1;
                }
                let position = match (state, targets[k]) {
                    (Some(State::OperationEnabled), Some(t)) => t + 10,
                    _ => actual,
                };
                targets[k] = Some(position);
                let controlword = state
                    .and_then(State::next_command_towards_enabled)
                    .unwrap_or(Controlword::ENABLE_OPERATION);
                let mut image = sd.outputs_raw_mut();
                match i {
                    0 => CspOutputs { controlword, target_position: position }
                        .pack_to_slice(&mut image)
                        .map(|_| ())
                        .unwrap(),
                    _ => DriveOutputs {
                        controlword,
                        target_position: position,
                        target_velocity: 0,
                        modes_of_operation: ModeOfOperation::CyclicSyncPosition.to_i8(),
                    }
                    .pack_to_slice(&mut image)
                    .map(|_| ())
                    .unwrap(),
                }
            }
            byte = (cycle % 251) as u8;
            group.subdevice(&maindevice, 1).unwrap().outputs_raw_mut()[0] = byte;
        }
        // One more exchange carries the last outputs.
        group.tx_rx(&maindevice).await.unwrap();
        (enabled, byte)
    });
    assert!(enabled.iter().all(|&n| n >= 1000), "{enabled:?}");
    let chain = link.chain();
    // The terminal's eight outputs (0x7000:01, 0x7010:01, … BOOLEAN) hold the bits of the
    // last byte, channel 1 in bit 0 (the SII's PDO order).
    let terminal = chain.devices()[1].dictionary();
    for ch in 0..8u16 {
        let v = terminal.raw(0x7000 + 0x10 * ch, 1).unwrap()[0];
        assert_eq!(v, terminal_byte >> ch & 1, "channel {}", ch + 1);
    }
    // Both drives followed their ramps.
    for i in [0, 2] {
        let position: i32 = chain.devices()[i].dictionary().get(0x6064, 0).unwrap();
        assert!(position >= 10 * 990, "device {i}: {position}");
    }
    eprintln!(
        "chain of three: {enabled:?} cycles enabled, {} frames, {} datagrams",
        chain.frames(),
        chain.datagrams()
    );
    drop(chain);
    link.stop();
}

fn sdo_information_object_lists() {
    use ethercrab::ObjectDescriptionListQuery as Q;
    let servoone = load("esi/servoone.xml");
    // The indices of the ESI's dictionary, in order (the parsed file, not the simulation).
    let all: Vec<u16> = servoone.objects.keys().copied().collect();
    let (maindevice, link) = master(Chain::new(vec![SubDevice::new(&servoone).unwrap()]));
    // ethercrab's SDO information buffers are large arrays (128 KiB each) on the stack:
    // more than a test thread's default 2 MiB holds in a debug build.
    let run = move || {
        smol::block_on(async {
            let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
            let sd = group.iter(&maindevice).next().unwrap();
            let counts = sd.sdo_info_object_quantities().await.unwrap().unwrap();
            assert_eq!(counts.all as usize, all.len());
            // The list of all objects (96 indices, 192 bytes) does not fit one 128-byte mailbox:
            // the device sends it in two fragments. ethercrab takes 8 bytes off every fragment's
            // length for the headers and the list type, which only the first carries
            // (ETG.1000.6 §5.6.3.3), so it loses the last index of each later fragment.
            let list = sd.sdo_info_object_description_list(Q::All).await.unwrap().unwrap();
            let lost: Vec<u16> = all.iter().copied().filter(|i| !list.contains(i)).collect();
            assert_eq!(list.len(), all.len() - 1, "lost {lost:04X?}");
            assert_eq!(lost, [all[all.len() - 1]]);
            assert!(list.iter().zip(&all).all(|(a, b)| a == b));
        });
    };
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, run)
            .unwrap()
            .join()
            .unwrap();
    });
    link.stop();
}

fn distributed_clocks_as_the_example_sets_them_up() {
    use ethercrab::subdevice_group::DcConfiguration;
    let servoone = load("esi/servoone.xml");
    let (maindevice, link) = master(Chain::new(vec![SubDevice::new(&servoone).unwrap()]));
    let cycle = Duration::from_millis(1);
    let (cycles, sync0) = smol::block_on(async {
        let mut group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
        // The ESI's op-mode `DC` (AssignActivate 0x0300: cyclic unit and SYNC0).
        let dc = servoone::startup::DC_OP_MODES.iter().find(|m| m.name == "DC").unwrap();
        for mut sd in group.iter_mut(&maindevice) {
            sd.set_dc_sync(ec::dc_sync(dc, cycle));
        }
        let group = group.into_pre_op_pdi(&maindevice).await.unwrap();
        let config = DcConfiguration {
            start_delay: Duration::from_millis(10),
            sync0_period: cycle,
            sync0_shift: cycle / 2,
        };
        let group = group.configure_dc_sync(&maindevice, config).await.unwrap();
        let sync0 = {
            let sd = group.subdevice(&maindevice, 0).unwrap();
            let active: u8 = sd.register_read(0x0981u16).await.unwrap();
            let period: u32 = sd.register_read(0x09A0u16).await.unwrap();
            (active, period)
        };
        let group = group.into_safe_op(&maindevice).await.unwrap();
        let group = group.request_into_op(&maindevice).await.unwrap();
        let mut cycles = 0;
        for _ in 0..200 {
            let start = Instant::now();
            let response = group.tx_rx_dc(&maindevice).await.unwrap();
            cycles += 1;
            smol::Timer::at(start + response.extra.next_cycle_wait).await;
        }
        (cycles, sync0)
    });
    // SYNC0 active with the cyclic unit (0x0981 bits 0 and 1), period 1 ms in ns (0x09A0).
    assert_eq!(sync0, (0x03, 1_000_000));
    assert_eq!(cycles, 200);
    assert_eq!(link.chain().devices()[0].al_state(), 8, "OP");
    link.stop();
}

#[path = "crabsweep/mod.rs"]
mod crabsweep;

/// A fixed sample of the ethercrab sweep (`examples/crabsweep.rs` runs the whole corpus): one
/// device of each kind the sweep found a fault of odc in, and one whose ESI is at fault, each
/// brought up by ethercrab's default sequence and run 1,000 cycles
/// (tests/ethercat-sweep/ethercrab.md).
fn crabsweep_sample() {
    crabsweep::catch_panics();
    let corpus = odc_tests_support::corpus();
    let sample = [
        // A terminal without a mailbox, fixed PDOs: OP.
        ("esi/beckhoff__Beckhoff_EL2xxx.xml", 4, crabsweep::Stage::Done, 0),
        // A coupler without a microcontroller (device emulation): OP.
        ("esi/beckhoff__Beckhoff_EKxxxx.xml", 5, crabsweep::Stage::Done, 0),
        // An SoE drive (IDN PDOs, one-buffer inputs SM): OP.
        ("esi/beckhoff__Beckhoff_AX5xxx.xml", 33, crabsweep::Stage::Done, 0),
        // A CoE chassis whose synthesised dictionary lacked 0x1C12: OP.
        ("esi/ni__NI9144.xml", 1, crabsweep::Stage::Done, 0),
        // A CoE drive with its default assignment: OP.
        ("esi/ingenia__ecat402-drive.xml", 0, crabsweep::Stage::Done, 0),
        // An EL6695 bridge terminal, inputs at 0x8E00 beyond an ET1100's 8 KiB: OP, and the
        // LRW counted (was working counter 0).
        ("esi/beckhoff__Beckhoff_EL66xx.xml", 42, crabsweep::Stage::Done, 0),
        // The ESI's mailbox DefaultSize 54 below its MinSize 64 (odc check T606): ethercrab
        // sets 54 from the SII, the device refuses PRE-OP with 0x0016.
        ("esi/beckhoff__Beckhoff_EL2xxx.xml", 38, crabsweep::Stage::Init, 0x0016),
    ];
    for (file, index, stage, code) in sample {
        let devices = crabsweep::file_devices(&corpus, file);
        let (_, _, device) = devices.iter().find(|(_, i, _)| *i == index).unwrap();
        let row = crabsweep::run(file, index, device);
        eprintln!("{}", row.tsv());
        assert_eq!((row.stage, row.al_code), (stage, code), "{}", row.tsv());
        if stage == crabsweep::Stage::Done {
            assert_eq!(row.cycles_ok, crabsweep::CYCLES);
        } else {
            // The failure's class names the ESI's fault and the rule that flags it.
            let want = "ESI: T606, mailbox DefaultSize outside MinSize..MaxSize (AL 0x0016)";
            assert_eq!(row.class, want);
        }
    }
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "ethercrab_finds_the_servoone_and_reaches_pre_op",
            run: ethercrab_finds_the_servoone_and_reaches_pre_op,
            needs: &[],
        },
        Test {
            name: "sdo_through_generated_descriptors_values_and_aborts",
            run: sdo_through_generated_descriptors_values_and_aborts,
            needs: &[],
        },
        Test {
            name: "al_state_machine_refuses_what_a_device_refuses",
            run: al_state_machine_refuses_what_a_device_refuses,
            needs: &[],
        },
        Test {
            name: "segmented_upload_with_the_smallest_mailbox",
            run: segmented_upload_with_the_smallest_mailbox,
            needs: &[],
        },
        Test {
            name: "op_with_a_csp_ramp_for_a_thousand_cycles",
            run: op_with_a_csp_ramp_for_a_thousand_cycles,
            needs: &[],
        },
        Test {
            name: "a_chain_of_three_to_op",
            run: a_chain_of_three_to_op,
            needs: &[Need::Corpus],
        },
        Test {
            name: "sdo_information_object_lists",
            run: sdo_information_object_lists,
            needs: &[],
        },
        Test { name: "crabsweep_sample", run: crabsweep_sample, needs: &[Need::Corpus] },
        Test {
            name: "distributed_clocks_as_the_example_sets_them_up",
            run: distributed_clocks_as_the_example_sets_them_up,
            needs: &[],
        },
    ])
}
