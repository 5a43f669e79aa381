//! One cyclic frame through one simulated EtherCAT device, as ethercrab's `tx_rx` sends it in
//! OP: an LRW of the process image (6 output and 6 input bytes, the CSP image of
//! `esi/servoone.xml` the ethercrab test maps) and a BRD of AL status. The time includes
//! what the device's firmware does with the frame: outputs into the dictionary, the CiA 402
//! drive, inputs out of it. Target: under 2 µs (issue #18). The same frame through a line of
//! 100 such devices (1,200 bytes of process data): a 1 kHz cycle needs it well under 1 ms
//! (issue #31; `examples/line100.rs` runs that line under ethercrab).
//!
//! Wall time: an iteration is shorter than the scheduler's accounting of thread CPU time (the
//! clock of the parse benches reads 0 for many samples), so a busy machine inflates it.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use odc_sim::ethercat::Chain;

mod common;

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

/// A line of `n` ServoOnes in OP with the CSP image mapped (the mapping written as the
/// firmware side, the registers as a master writes them): device k's 12 bytes at logical
/// address 12·k, outputs first.
fn servoones_in_op(n: u16) -> Chain {
    let model = common::servoone();
    let mut c = Chain::new((0..n).map(|_| common::servoone_csp(&model)).collect());
    for k in 0..n {
        let a = 0x1001 + k;
        let (out, inp) = (u32::from(k) * 12, u32::from(k) * 12 + 6);
        run(&mut c, &[(2, 0u16.wrapping_sub(k), 0x0010, a.to_le_bytes().to_vec())]);
        run(
            &mut c,
            &[
                (5, a, 0x0800, sm(0x1000, 128, 0x26)),
                (5, a, 0x0808, sm(0x1080, 128, 0x22)),
                (5, a, 0x0120, vec![2, 0]),
                (5, a, 0x0810, sm(0x1100, 6, 0x64)),
                (5, a, 0x0818, sm(0x1180, 6, 0x20)),
                (5, a, 0x0600, fmmu(out, 6, 0x1100, 2)),
                (5, a, 0x0610, fmmu(inp, 6, 0x1180, 1)),
                (5, a, 0x0120, vec![4, 0]),
                (5, a, 0x0120, vec![8, 0]),
            ],
        );
    }
    for d in c.devices() {
        assert_eq!(d.al_state(), 8, "AL status code {:#06x}", d.al_status_code());
    }
    c
}

/// One LRW of the whole image (controlword 0x000F, enable operation, and target position
/// 1000 for every device; inputs zero) and a BRD of AL status, timed through the line.
fn line(c: &mut Criterion, n: u16) {
    let mut chain = servoones_in_op(n);
    let mut image = Vec::new();
    for _ in 0..n {
        image.extend([0x0F, 0x00, 0xE8, 0x03, 0, 0, 0, 0, 0, 0, 0, 0]);
    }
    let dgs = [(12u8, 0u16, 0u16, image.clone()), (7, 0, 0x0130, vec![0, 0])];
    let template = frame(&dgs);
    let mut buf = template.clone();
    // Check once that the frame does what it should: LRW WKC 3 a device, BRD 1 a device.
    chain.process(&mut buf, 0).unwrap();
    let w = 16 + 10 + image.len();
    assert_eq!(u16::from_le_bytes([buf[w], buf[w + 1]]), 3 * n);
    assert_eq!(u16::from_le_bytes([buf[w + 14], buf[w + 15]]), n);
    let mut t = 0u64;
    let name = match n {
        1 => "ethercat/lrw+al_status, one device (servoone, 6+6 bytes)".to_string(),
        _ => format!("ethercat/lrw+al_status, a line of {n} devices (servoone, 6+6 bytes each)"),
    };
    c.bench_function(&name, |b| {
        b.iter(|| {
            buf.copy_from_slice(&template);
            t += 1_000_000;
            chain.process(black_box(&mut buf), t).unwrap();
            black_box(&buf);
        })
    });
}

fn bench(c: &mut Criterion) {
    line(c, 1);
    line(c, 100);
}

criterion_group!(benches, bench);
criterion_main!(benches);
