//! One cyclic frame through one simulated EtherCAT device, as ethercrab's `tx_rx` sends it in
//! OP: an LRW of the process image (6 output and 6 input bytes, the CSP image of
//! `esi/servoone.xml` the ethercrab test maps) and an FPRD of AL status. The time includes
//! what the device's firmware does with the frame: outputs into the dictionary, the CiA 402
//! drive, inputs out of it. Target: under 2 µs (issue #18).
//!
//! Wall time: an iteration is shorter than the scheduler's accounting of thread CPU time (the
//! clock of the parse benches reads 0 for many samples), so a busy machine inflates it.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use odc::slave::ObjectDictionary;
use odc_sim::ethercat::{Chain, SubDevice};

/// A frame of `dgs` (command, ADP, ADO, data).
fn frame(dgs: &[(u8, u16, u16, Vec<u8>)]) -> Vec<u8> {
    let mut body = Vec::new();
    for (i, (cmd, adp, ado, data)) in dgs.iter().enumerate() {
        let more = if i + 1 < dgs.len() { 0x8000u16 } else { 0 };
        body.extend([*cmd, i as u8]);
        body.extend(adp.to_le_bytes());
        body.extend(ado.to_le_bytes());
        body.extend((data.len() as u16 | more).to_le_bytes());
        body.extend([0, 0]);
        body.extend(data);
        body.extend([0, 0]);
    }
    let mut f = vec![0xFF; 6];
    f.extend([0x02, 0, 0, 0, 0, 0, 0x88, 0xA4]);
    f.extend((body.len() as u16 | 0x1000).to_le_bytes());
    f.extend(body);
    f
}

fn run(c: &mut Chain, dgs: &[(u8, u16, u16, Vec<u8>)]) -> Vec<u8> {
    let mut f = frame(dgs);
    c.process(&mut f, 0).unwrap();
    f
}

fn sm(start: u16, len: u16, control: u8) -> Vec<u8> {
    let mut v = start.to_le_bytes().to_vec();
    v.extend(len.to_le_bytes());
    v.extend([control, 0, 1, 0]);
    v
}

fn fmmu(logical: u32, len: u16, physical: u16, kind: u8) -> Vec<u8> {
    let mut v = logical.to_le_bytes().to_vec();
    v.extend(len.to_le_bytes());
    v.extend([0, 7]);
    v.extend(physical.to_le_bytes());
    v.extend([0, kind, 1, 0, 0, 0]);
    v
}

/// The ServoOne in OP with the CSP image mapped (the mapping written as the firmware side,
/// the registers as a master writes them).
fn servoone_in_op() -> Chain {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut device = SubDevice::new(loaded.device().unwrap()).unwrap();
    let od = device.dictionary_mut();
    for (index, sub, data) in [
        (0x1600u16, 1u8, 0x6040_0010u32.to_le_bytes().to_vec()),
        (0x1600, 2, 0x607A_0020u32.to_le_bytes().to_vec()),
        (0x1600, 0, vec![2]),
        (0x1A00, 1, 0x6041_0010u32.to_le_bytes().to_vec()),
        (0x1A00, 2, 0x6064_0020u32.to_le_bytes().to_vec()),
        (0x1A00, 0, vec![2]),
        (0x1C12, 1, 0x1600u16.to_le_bytes().to_vec()),
        (0x1C12, 0, vec![1]),
        (0x1C13, 1, 0x1A00u16.to_le_bytes().to_vec()),
        (0x1C13, 0, vec![1]),
        (0x6060, 0, vec![8]),
    ] {
        od.write(index, sub, &data).unwrap();
    }
    let mut c = Chain::new(vec![device]);
    let a = 0x1001u16;
    run(&mut c, &[(2, 0, 0x0010, a.to_le_bytes().to_vec())]);
    run(
        &mut c,
        &[
            (5, a, 0x0800, sm(0x1000, 128, 0x26)),
            (5, a, 0x0808, sm(0x1080, 128, 0x22)),
            (5, a, 0x0120, vec![2, 0]),
            (5, a, 0x0810, sm(0x1100, 6, 0x64)),
            (5, a, 0x0818, sm(0x1180, 6, 0x20)),
            (5, a, 0x0600, fmmu(0, 6, 0x1100, 2)),
            (5, a, 0x0610, fmmu(6, 6, 0x1180, 1)),
            (5, a, 0x0120, vec![4, 0]),
            (5, a, 0x0120, vec![8, 0]),
        ],
    );
    assert_eq!(
        c.devices()[0].al_state(),
        8,
        "AL status code {:#06x}",
        c.devices()[0].al_status_code()
    );
    c
}

fn bench(c: &mut Criterion) {
    let mut chain = servoone_in_op();
    // Controlword 0x000F (enable operation), target position 1000; inputs zero.
    let dgs = [
        (12u8, 0u16, 0u16, vec![0x0F, 0x00, 0xE8, 0x03, 0, 0, 0, 0, 0, 0, 0, 0]),
        (4, 0x1001, 0x0130, vec![0, 0]),
    ];
    let template = frame(&dgs);
    let mut buf = template.clone();
    // Check once that the frame does what it should: LRW WKC 3.
    chain.process(&mut buf, 0).unwrap();
    assert_eq!(u16::from_le_bytes([buf[38], buf[39]]), 3);
    let mut t = 0u64;
    c.bench_function("ethercat/lrw+al_status, one device (servoone, 6+6 bytes)", |b| {
        b.iter(|| {
            buf.copy_from_slice(&template);
            t += 1_000_000;
            chain.process(black_box(&mut buf), t).unwrap();
            black_box(&buf);
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
