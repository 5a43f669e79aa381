//! odc's SPI adapters (`odc::ethercat::esc_spi`) against the SPI side of the emulated ESC
//! (`odc_sim::ethercat::spi`): the frames they send, byte for byte as the datasheets' command
//! tables give them; what they read and write; and the firmware stack reaching OP under
//! ethercrab through each.
//!
//! Sources of the expected bytes:
//! - Beckhoff ET1100 datasheet, section II, "SPI Slave Interface": the address/command
//!   phase (2-byte addressing: A[12:5], then A[4:0] and CMD0; 3-byte addressing: CMD0 0b110
//!   and a third byte A[15:13], CMD1, 0b00), the commands (NOP 0b000, READ 0b010, READ with
//!   wait state byte 0b011, WRITE 0b100, address extension 0b110), the wait state byte
//!   0xFF, data read with 0x00 and the read termination byte 0xFF last, and the AL event
//!   request register (0x0220, 0x0221, 0x0222) shifted out during the address phase.
//! - Microchip LAN9252 datasheet (DS00001909): the SPI instructions (READ 0x03, FAST READ
//!   0x0B with one dummy byte, WRITE 0x02; a 16-bit address, high byte first; registers
//!   little endian), BYTE_TEST (0x0064, 0x87654321), HW_CFG (0x0074, READY bit 27),
//!   ECAT_CSR_DATA (0x0300) and ECAT_CSR_CMD (0x0304: bit 31 busy, bit 30 read, bits 18:16
//!   size, bits 15:0 address), ECAT_PRAM_RD/WR_ADDR_LEN (0x0308/0x0310: length in bits
//!   31:16, address in 15:0), ECAT_PRAM_RD/WR_CMD (0x030C/0x0314: bit 31 busy, bits 12:8
//!   the count, bit 0 available), the FIFO ports 0x0000 (read) and 0x0020 (write), the
//!   first word carrying the data from byte `address & 3`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use odc::ethercat::esc_spi::beckhoff::EscSpi;
use odc::ethercat::esc_spi::lan9252::Lan9252;
use odc::ethercat::subdevice::Esc as _;
use odc_sim::ethercat::esc::{Esc, Pdi};
use odc_sim::ethercat::spi::{EscSpiChip, Lan9252Chip};

/// An ESC at power-on without an SII image.
fn esc() -> Esc {
    Esc::new(vec![0; 128], 0, false)
}

/// Each frame's MOSI and MISO bytes, on the way to the chip.
struct Recording<S> {
    chip: S,
    frames: Vec<(Vec<u8>, Vec<u8>)>,
}

impl<S> Recording<S> {
    fn new(chip: S) -> Self {
        Self { chip, frames: Vec::new() }
    }
    /// The MOSI bytes of every frame.
    fn mosi(&self) -> Vec<Vec<u8>> {
        self.frames.iter().map(|(o, _)| o.clone()).collect()
    }
}

impl<S: ErrorType> ErrorType for Recording<S> {
    type Error = S::Error;
}

/// The frame goes to the chip as one transfer of all its bytes (MOSI of a read: 0x00, as
/// the emulation takes it), and the MISO bytes come back into the caller's buffers.
impl<S: SpiDevice> SpiDevice for Recording<S> {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), S::Error> {
        let mut mosi = Vec::new();
        for op in ops.iter() {
            match op {
                Operation::Read(b) => mosi.extend(std::iter::repeat_n(0u8, b.len())),
                Operation::Write(b) => mosi.extend_from_slice(b),
                Operation::Transfer(r, w) => {
                    let mut bytes = w.to_vec();
                    bytes.resize(r.len().max(w.len()), 0);
                    mosi.extend(bytes);
                }
                Operation::TransferInPlace(b) => mosi.extend_from_slice(b),
                Operation::DelayNs(_) => {}
            }
        }
        let mut miso = vec![0u8; mosi.len()];
        self.chip.transaction(&mut [Operation::Transfer(&mut miso, &mosi)])?;
        let mut at = 0;
        for op in ops.iter_mut() {
            let n = match op {
                Operation::Read(b) | Operation::TransferInPlace(b) => {
                    b.copy_from_slice(&miso[at..at + b.len()]);
                    b.len()
                }
                Operation::Write(b) => b.len(),
                Operation::Transfer(r, w) => {
                    let n = r.len().max(w.len());
                    let k = r.len();
                    r.copy_from_slice(&miso[at..at + k]);
                    n
                }
                Operation::DelayNs(_) => 0,
            };
            at += n;
        }
        self.frames.push((mosi, miso));
        Ok(())
    }
}

// ---- Beckhoff ESC SPI ----

#[test]
fn esc_spi_read_is_address_phase_wait_state_and_terminated_data() {
    let mut esc = esc();
    esc.set_u16(0x0130, 0x0002);
    // AL event request: AL control (bit 0) and SM1 (bit 9).
    esc.set_bytes(0x0220, &[0x01, 0x02, 0x00, 0x00]);
    let mut spi = EscSpi::new(Recording::new(EscSpiChip::new(Pdi(&mut esc))));
    let mut status = [0u8; 2];
    spi.read(0x0130, &mut status).unwrap();
    assert_eq!(status, [0x02, 0x00]);
    assert_eq!(spi.last_al_event(), 0x0201);
    let rec = spi.release();
    // 0x0130: A[12:5] = 0x09; A[4:0] = 0x10 → 0x80 | READ_WAIT 0b011; wait state 0xFF; data
    // 0x00, then 0xFF with the last byte.
    let (mosi, miso) = &rec.frames[0];
    assert_eq!(mosi, &[0x09, 0x83, 0xFF, 0x00, 0xFF]);
    // The AL event request in the address phase, the data after the wait state byte.
    assert_eq!(&miso[..2], &[0x01, 0x02]);
    assert_eq!(&miso[3..], &[0x02, 0x00]);
}

#[test]
fn esc_spi_write_is_address_phase_and_data() {
    let mut esc = esc();
    let mut spi = EscSpi::new(Recording::new(EscSpiChip::new(Pdi(&mut esc))));
    spi.write(0x0134, &[0x1D, 0x00]).unwrap();
    let rec = spi.release();
    // 0x0134: A[12:5] = 0x09; A[4:0] = 0x14 → 0xA0 | WRITE 0b100.
    assert_eq!(rec.mosi(), vec![vec![0x09, 0xA4, 0x1D, 0x00]]);
    assert_eq!(esc.u16(0x0134), 0x001D);
}

#[test]
fn esc_spi_addresses_above_0x1fff_take_the_address_extension() {
    let mut esc = esc();
    esc.set_bytes(0x2345, &[0x5A]);
    esc.set_bytes(0x0220, &[0x00, 0x00, 0x04, 0x00]);
    let mut spi = EscSpi::new(Recording::new(EscSpiChip::new(Pdi(&mut esc))));
    let mut b = [0u8; 1];
    spi.read(0x2345, &mut b).unwrap();
    spi.write(0x2FFE, &[0x11, 0x22]).unwrap();
    assert_eq!(b, [0x5A]);
    // The third address byte shifts out 0x0222.
    assert_eq!(spi.last_al_event(), 0x04_0000);
    let rec = spi.release();
    // 0x2345: A[12:5] = 0x1A; A[4:0] = 0x05 → 0x28 | 0b110; A[15:13] = 0b001 → 0x20 |
    // READ_WAIT << 2; a single data byte is the termination byte.
    // 0x2FFE: A[12:5] = 0x7F; A[4:0] = 0x1E → 0xF0 | 0b110; 0b001 → 0x20 | WRITE << 2.
    assert_eq!(
        rec.mosi(),
        vec![vec![0x1A, 0x2E, 0x2C, 0xFF, 0xFF], vec![0x7F, 0xF6, 0x30, 0x11, 0x22]]
    );
    assert_eq!(rec.frames[0].1[4], 0x5A);
    assert_eq!(esc.bytes(0x2FFE, 2), &[0x11, 0x22]);
}

#[test]
fn esc_spi_al_event_is_one_nop_address_phase() {
    let mut esc = esc();
    // AL control (bit 0), SM0 (bit 8), SM8 (bit 16).
    esc.set_bytes(0x0220, &[0x01, 0x01, 0x01, 0x00]);
    let mut spi = EscSpi::new(Recording::new(EscSpiChip::new(Pdi(&mut esc))));
    assert_eq!(spi.al_event().unwrap(), 0x01_0101);
    let rec = spi.release();
    // NOP with address extension: address 0, CMD0 0b110, CMD1 0b000.
    assert_eq!(rec.frames, vec![(vec![0x00, 0x06, 0x00], vec![0x01, 0x01, 0x01])]);
    // A NOP reads nothing: AL control's event is still there.
    assert_eq!(esc.al_event() & 1, 1);
}

/// SM0 as a write mailbox at 0x1000 (4 bytes), full.
fn full_write_mailbox(esc: &mut Esc) {
    // Start, length, control (mailbox, master writes), status (full), activate.
    esc.set_bytes(0x0800, &[0x00, 0x10, 0x04, 0x00, 0x26, 0x08, 0x01, 0x00]);
    esc.set_bytes(0x1000, &[1, 2, 3, 4]);
}

#[test]
fn esc_spi_read_termination_ends_the_prefetch_at_the_mailbox_end() {
    let mut esc = esc();
    full_write_mailbox(&mut esc);
    {
        // The first three bytes: the mailbox stays full.
        let mut spi = EscSpi::new(EscSpiChip::new(Pdi(&mut esc)));
        let mut b = [0u8; 3];
        spi.read(0x1000, &mut b).unwrap();
        assert_eq!(b, [1, 2, 3]);
    }
    assert_eq!(esc.u8(0x0805) & 0x08, 0x08);
    {
        let mut spi = EscSpi::new(EscSpiChip::new(Pdi(&mut esc)));
        let mut b = [0u8; 4];
        spi.read(0x1000, &mut b).unwrap();
        assert_eq!(b, [1, 2, 3, 4]);
    }
    // Its last byte read: empty, the master may write the next.
    assert_eq!(esc.u8(0x0805) & 0x08, 0);
}

#[test]
fn the_emulated_esc_spi_refuses_a_read_without_termination() {
    let mut esc = esc();
    let mut chip = EscSpiChip::new(Pdi(&mut esc));
    let mut data = [0u8; 2];
    // READ_WAIT at 0x0130, wait state byte, then two 0x00 bytes and no 0xFF.
    let r = chip.transaction(&mut [
        Operation::Write(&[0x09, 0x83, 0xFF]),
        Operation::TransferInPlace(&mut data),
    ]);
    assert!(r.unwrap_err().0.contains("termination"));
    // A reserved command (0b111).
    let r = chip.transaction(&mut [Operation::Write(&[0x09, 0x87])]);
    assert!(r.unwrap_err().0.contains("reserved"));
}

// ---- LAN9252 ----

#[test]
fn lan9252_ready_reads_byte_test_and_hw_cfg() {
    let mut esc = esc();
    let mut spi = Lan9252::new(Recording::new(Lan9252Chip::new(Pdi(&mut esc))));
    assert!(spi.ready().unwrap());
    let rec = spi.release();
    // FAST READ, address 0x0064 high byte first, one dummy byte, four data bytes.
    assert_eq!(
        rec.mosi(),
        vec![vec![0x0B, 0x00, 0x64, 0x00, 0, 0, 0, 0], vec![0x0B, 0x00, 0x74, 0x00, 0, 0, 0, 0]]
    );
    assert_eq!(&rec.frames[0].1[4..], &[0x21, 0x43, 0x65, 0x87]);
    assert_eq!(rec.frames[1].1[7] & 0x08, 0x08, "HW_CFG bit 27");
}

#[test]
fn the_emulated_lan9252_takes_read_without_dummy_and_refuses_other_instructions() {
    let mut esc = esc();
    let mut chip = Lan9252Chip::new(Pdi(&mut esc));
    // READ (0x03): the address, then the data at once (no dummy byte).
    let mut word = [0u8; 4];
    chip.transaction(&mut [Operation::Write(&[0x03, 0x00, 0x64]), Operation::Read(&mut word)])
        .unwrap();
    assert_eq!(word, [0x21, 0x43, 0x65, 0x87]);
    // SQI's instructions (0x6B fast read quad, say) are not SPI ones.
    let r = chip.transaction(&mut [Operation::Write(&[0x6B, 0x00, 0x64])]);
    assert!(r.unwrap_err().0.contains("instruction"));
    // A CSR write of 3 bytes: the chip takes sizes 1, 2 and 4.
    let r = chip.transaction(&mut [Operation::Write(&[0x02, 0x03, 0x04, 0x30, 0x01, 0x03, 0x80])]);
    assert!(r.unwrap_err().0.contains("size"));
}

#[test]
fn lan9252_register_read_is_a_csr_command_polled_then_the_data() {
    let mut esc = esc();
    esc.set_u16(0x0130, 0x0004);
    let mut spi = Lan9252::new(Recording::new(Lan9252Chip::new(Pdi(&mut esc))));
    let mut status = [0u8; 2];
    spi.read(0x0130, &mut status).unwrap();
    assert_eq!(status, [0x04, 0x00]);
    let rec = spi.release();
    // ECAT_CSR_CMD = busy | read | size 2 << 16 | 0x0130 = 0xC002_0130, little endian.
    let command = vec![0x02, 0x03, 0x04, 0x30, 0x01, 0x02, 0xC0];
    let poll = vec![0x0B, 0x03, 0x04, 0x00, 0, 0, 0, 0];
    let data = vec![0x0B, 0x03, 0x00, 0x00, 0, 0, 0, 0];
    assert_eq!(rec.mosi(), vec![command, poll.clone(), poll, data]);
    // The first poll still busy (bit 31), the second done; the data right-aligned.
    assert_eq!(rec.frames[1].1[7] & 0x80, 0x80);
    assert_eq!(rec.frames[2].1[7] & 0x80, 0x00);
    assert_eq!(&rec.frames[3].1[4..], &[0x04, 0x00, 0x00, 0x00]);
}

#[test]
fn lan9252_register_write_is_data_then_csr_command() {
    let mut esc = esc();
    let mut spi = Lan9252::new(Recording::new(Lan9252Chip::new(Pdi(&mut esc))));
    // 0x0131 is odd: one byte, then 0x0132 two (the CSR's size against address table).
    spi.write(0x0131, &[0xAA, 0xBB, 0xCC]).unwrap();
    let rec = spi.release();
    let poll = vec![0x0B, 0x03, 0x04, 0x00, 0, 0, 0, 0];
    assert_eq!(
        rec.mosi(),
        vec![
            vec![0x02, 0x03, 0x00, 0xAA, 0, 0, 0],
            // busy | write | size 1 << 16 | 0x0131 = 0x8001_0131.
            vec![0x02, 0x03, 0x04, 0x31, 0x01, 0x01, 0x80],
            poll.clone(),
            poll.clone(),
            vec![0x02, 0x03, 0x00, 0xBB, 0xCC, 0, 0],
            // 0x8002_0132.
            vec![0x02, 0x03, 0x04, 0x32, 0x01, 0x02, 0x80],
            poll.clone(),
            poll,
        ]
    );
    assert_eq!(esc.bytes(0x0131, 3), &[0xAA, 0xBB, 0xCC]);
}

#[test]
fn lan9252_process_ram_goes_through_the_fifos() {
    let mut esc = esc();
    let mut spi = Lan9252::new(Recording::new(Lan9252Chip::new(Pdi(&mut esc))));
    spi.write(0x1001, &[0xAA, 0xBB, 0xCC]).unwrap();
    let mut back = [0u8; 3];
    spi.read(0x1001, &mut back).unwrap();
    assert_eq!(back, [0xAA, 0xBB, 0xCC]);
    let rec = spi.release();
    let wr_poll = vec![0x0B, 0x03, 0x14, 0x00, 0, 0, 0, 0];
    let rd_poll = vec![0x0B, 0x03, 0x0C, 0x00, 0, 0, 0, 0];
    assert_eq!(
        rec.mosi(),
        vec![
            // ECAT_PRAM_WR_ADDR_LEN = 3 << 16 | 0x1001; ECAT_PRAM_WR_CMD = busy (start).
            vec![0x02, 0x03, 0x10, 0x01, 0x10, 0x03, 0x00],
            vec![0x02, 0x03, 0x14, 0x00, 0x00, 0x00, 0x80],
            wr_poll.clone(),
            wr_poll,
            // One word into the write FIFO, the data from byte 1 (0x1001 & 3).
            vec![0x02, 0x00, 0x20, 0x00, 0xAA, 0xBB, 0xCC],
            vec![0x02, 0x03, 0x08, 0x01, 0x10, 0x03, 0x00],
            vec![0x02, 0x03, 0x0C, 0x00, 0x00, 0x00, 0x80],
            rd_poll.clone(),
            rd_poll,
            vec![0x0B, 0x00, 0x00, 0x00, 0, 0, 0, 0],
        ]
    );
    // Write space: count 1 (bits 12:8), available (bit 0); read likewise.
    assert_eq!(&rec.frames[3].1[4..6], &[0x01, 0x01]);
    assert_eq!(&rec.frames[8].1[4..6], &[0x01, 0x01]);
    assert_eq!(&rec.frames[9].1[4..], &[0x00, 0xAA, 0xBB, 0xCC]);
    assert_eq!(esc.bytes(0x1000, 5), &[0, 0xAA, 0xBB, 0xCC, 0]);
}

/// Writes through `spi`, reads back directly and through it, for ranges over registers,
/// across 0x1000 and over more than a FIFO holds.
fn round_trips(esc: &mut Esc, through: fn(&mut Esc, u16, &[u8]) -> Vec<u8>) {
    for (addr, len) in [(0x0F80u16, 7usize), (0x0FFD, 9), (0x1003, 130), (0x2F00, 256)] {
        let data: Vec<u8> =
            (0..len).map(|k| (k as u8).wrapping_mul(37).wrapping_add(len as u8)).collect();
        let back = through(esc, addr, &data);
        assert_eq!(esc.bytes(addr, len), &data[..], "{addr:#06x}+{len}: written");
        assert_eq!(back, data, "{addr:#06x}+{len}: read back");
    }
}

#[test]
fn both_adapters_read_and_write_any_range() {
    round_trips(&mut esc(), |esc, addr, data| {
        let mut spi = EscSpi::new(EscSpiChip::new(Pdi(esc)));
        spi.write(addr, data).unwrap();
        let mut back = vec![0; data.len()];
        spi.read(addr, &mut back).unwrap();
        back
    });
    round_trips(&mut esc(), |esc, addr, data| {
        let mut spi = Lan9252::new(Lan9252Chip::new(Pdi(esc)).with_busy_reads(3));
        spi.write(addr, data).unwrap();
        let mut back = vec![0; data.len()];
        spi.read(addr, &mut back).unwrap();
        back
    });
}

#[test]
fn lan9252_gives_up_on_a_command_that_stays_busy() {
    let mut esc = esc();
    let mut spi =
        Lan9252::new(Lan9252Chip::new(Pdi(&mut esc)).with_busy_reads(50)).with_poll_limit(10);
    let r = spi.read(0x0130, &mut [0u8; 2]);
    assert_eq!(r, Err(odc::ethercat::esc_spi::lan9252::Error::Busy));
}

// ---- The firmware stack through each adapter, under ethercrab ----

mod op {
    use std::sync::OnceLock;
    use std::time::{Duration, Instant};

    use ethercrab::{EtherCrabWireRead, EtherCrabWireWrite, MainDevice, MainDeviceConfig};
    use ethercrab::{PduStorage, Timeouts};
    use odc::cia402::{Controlword, ModeOfOperation, State};
    use odc::ethercat::ethercrab as ec;
    use odc_sim::ethercat::spi::PdiPath;
    use odc_sim::ethercat::{Chain, EthercrabLink, SubDevice};

    /// The master side odc generates from `esi/servoone.xml`.
    mod servoone {
        odc_macros::include_device!("../../esi/servoone.xml", role = "master");
    }

    fn now() -> u64 {
        static START: OnceLock<Instant> = OnceLock::new();
        START.get_or_init(Instant::now).elapsed().as_nanos() as u64
    }

    /// RxPDO 1 (0x1600) for cyclic synchronous position.
    #[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
    struct Outputs {
        #[pdo(index = 0x6040, bits = 16)]
        controlword: odc::cia402::Controlword,
        #[pdo(index = 0x607A)]
        target_position: i32,
    }
    odc::impl_wire!(Outputs);

    /// TxPDO 1 (0x1A00).
    #[derive(Clone, Copy, Debug, Default, PartialEq, odc::Pdo)]
    struct Inputs {
        #[pdo(index = 0x6041, bits = 16)]
        statusword: odc::cia402::Statusword,
        #[pdo(index = 0x6064)]
        position_actual_value: i32,
    }
    odc::impl_wire!(Inputs);

    async fn map<T: odc::Pdo>(
        sd: &ethercrab::SubDeviceRef<'_, &ethercrab::SubDevice>,
        sm: u8,
        pdo: u16,
    ) {
        let assign = 0x1C10 + u16::from(sm);
        sd.sdo_write(assign, 0, 0u8).await.unwrap();
        sd.sdo_write(pdo, 0, 0u8).await.unwrap();
        for (sub, entry) in (1u8..).zip(T::MAPPING) {
            sd.sdo_write(pdo, sub, entry.to_u32()).await.unwrap();
        }
        sd.sdo_write(pdo, 0, T::MAPPING.len() as u8).await.unwrap();
        sd.sdo_write(assign, 1, pdo).await.unwrap();
        sd.sdo_write(assign, 0, 1u8).await.unwrap();
    }

    /// The ServoOne with its stack on `path`: ethercrab maps CSP, takes it to OP and runs
    /// 300 cycles, enabling the drive and ramping its position; returns the cycles in
    /// operation enabled.
    fn servoone_to_op(path: PdiPath) -> u32 {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let loaded =
            odc_pipeline::load(&root.join("esi/servoone.xml"), &odc_pipeline::Options::new())
                .unwrap();
        let device = SubDevice::new(loaded.device().unwrap()).unwrap().with_pdi(path);
        let storage: &'static PduStorage<16, { PduStorage::element_size(1100) }> =
            Box::leak(Box::new(PduStorage::new()));
        let (tx, rx, pdu_loop) = storage.try_split().unwrap();
        let link = EthercrabLink::start(tx, rx, Chain::new(vec![device]), now);
        // Long timeouts: the simulated device answers from a thread a loaded machine may
        // not schedule at once (as in ethercat_ethercrab.rs).
        let timeouts = Timeouts {
            eeprom: Duration::from_secs(1),
            pdu: Duration::from_secs(1),
            ..Timeouts::default()
        };
        let maindevice = MainDevice::new(pdu_loop, timeouts, MainDeviceConfig::default());
        let enabled = smol::block_on(async {
            let group = maindevice.init_single_group::<4, 64>(now).await.unwrap();
            {
                let sd = group.iter(&maindevice).next().unwrap();
                map::<Outputs>(&sd, 2, 0x1600).await;
                map::<Inputs>(&sd, 3, 0x1A00).await;
                let csp = ModeOfOperation::CyclicSyncPosition.to_i8();
                ec::sdo_write(&sd, &servoone::od::MODES_OF_OPERATION, csp).await.unwrap();
            }
            let group = group.into_op(&maindevice).await.unwrap();
            let mut enabled = 0u32;
            let mut sent: Option<i32> = None;
            let mut target: Option<i32> = None;
            for _ in 0..300 {
                let response = group.tx_rx(&maindevice).await.unwrap();
                // LRW through one device: read 1 + write 2 (ETG.1000.4 Table 7).
                assert_eq!(response.working_counter, 3);
                let sd = group.subdevice(&maindevice, 0).unwrap();
                let inputs = Inputs::unpack_from_slice(&sd.inputs_raw()).unwrap();
                let state = inputs.statusword.state();
                if state == Some(State::OperationEnabled) {
                    // The drive follows the previous frame's set-point.
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
                let controlword = state
                    .and_then(State::next_command_towards_enabled)
                    .unwrap_or(Controlword::ENABLE_OPERATION);
                let outputs = Outputs { controlword, target_position: position };
                outputs.pack_to_slice(&mut sd.outputs_raw_mut()).unwrap();
            }
            group.into_safe_op(&maindevice).await.unwrap();
            enabled
        });
        {
            let chain = link.chain();
            let device = &chain.devices()[0];
            assert_eq!(device.pdi_error(), None, "every SPI frame as the chip takes it");
            assert_eq!(device.al_state(), 4, "SAFE-OP after OP");
        }
        link.stop();
        enabled
    }

    #[test]
    fn servoone_reaches_op_through_the_lan9252() {
        let enabled = servoone_to_op(PdiPath::Lan9252);
        assert!(enabled >= 290, "{enabled} cycles in operation enabled");
    }

    #[test]
    fn servoone_reaches_op_through_the_esc_spi() {
        let enabled = servoone_to_op(PdiPath::EscSpi);
        assert!(enabled >= 290, "{enabled} cycles in operation enabled");
    }
}
