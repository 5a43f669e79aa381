//! A line of 100 simulated devices (each `esi/servoone.xml` with the CSP image mapped: the
//! emulated ESC and odc's firmware stack, with its CiA 402 drive) driven by ethercrab at a
//! 1 kHz cycle for 10 s, in one process (#31):
//!
//! ```text
//! cargo build --release -p odc-sim --example line100
//! taskset -c 1 target/release/examples/line100 [--devices 100] [--seconds 10] [--period-us 1000]
//! ```
//!
//! Each cycle is one `tx_rx` (ethercrab's LRW of the whole image and its AL status reads),
//! started on the period's tick. Reported: cycles, missed cycles (an exchange not finished
//! within its period, or one whose working counter is not 3 a device), and the distribution of
//! the exchange times and of the wake-ups' lateness (the executor's timer). The drives are led to operation enabled and follow a ramp, so the
//! firmware does its whole cyclic work.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../benches/common/mod.rs"]
mod common;

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use odc_sim::ethercat::{Chain, EthercrabLink};

static STORAGE: PduStorage<16, { PduStorage::element_size(1486) }> = PduStorage::new();

fn now() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

fn arg(name: &str, default: u64) -> u64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted.get(i).copied().unwrap_or_default()
}

fn main() {
    use odc::cia402::{Controlword, State, Statusword};
    let n = arg("--devices", 100) as usize;
    let seconds = arg("--seconds", 10);
    let period = Duration::from_micros(arg("--period-us", 1000));
    let model = common::servoone();
    let chain = Chain::new((0..n).map(|_| common::servoone_csp(&model)).collect());
    let (tx, rx, pdu_loop) = STORAGE.try_split().unwrap();
    let link = EthercrabLink::start(tx, rx, chain, now);
    let timeouts = Timeouts {
        eeprom: Duration::from_secs(1),
        pdu: Duration::from_secs(1),
        ..Timeouts::default()
    };
    let maindevice = MainDevice::new(pdu_loop, timeouts, MainDeviceConfig::default());
    let (exchanges, mut wakeups, late, wrong_wkc, enabled) = smol::block_on(async {
        let t = Instant::now();
        let group = maindevice.init_single_group::<128, 4096>(now).await.unwrap();
        assert_eq!(group.len(), n);
        eprintln!("{n} devices in PRE-OP after {:?}", t.elapsed());
        let group = group.into_op(&maindevice).await.unwrap();
        eprintln!("in OP after {:?}", t.elapsed());
        for sd in group.iter(&maindevice) {
            assert_eq!((sd.outputs_raw().len(), sd.inputs_raw().len()), common::IMAGE);
        }
        let cycles = seconds * 1_000_000 / period.as_micros() as u64;
        let mut exchanges = Vec::with_capacity(cycles as usize);
        let mut wakeups = Vec::with_capacity(cycles as usize);
        let (mut late, mut wrong_wkc) = (0u64, 0u64);
        let mut targets = vec![None::<i32>; n];
        let mut tick = Instant::now() + period;
        for _ in 0..cycles {
            smol::Timer::at(tick).await;
            let start = Instant::now();
            wakeups.push(start.saturating_duration_since(tick));
            let r = group.tx_rx(&maindevice).await.unwrap();
            let done = Instant::now();
            exchanges.push(done - start);
            if done > tick + period {
                late += 1;
            }
            if usize::from(r.working_counter) != 3 * n {
                wrong_wkc += 1;
            }
            for (sd, target) in group.iter(&maindevice).zip(&mut targets) {
                // The inputs' guard goes before the outputs' is taken (one lock on the image).
                let (status, actual) = {
                    let i = sd.inputs_raw();
                    (
                        Statusword(u16::from_le_bytes([i[0], i[1]])),
                        i32::from_le_bytes([i[2], i[3], i[4], i[5]]),
                    )
                };
                let state = status.state();
                let next = match (state, *target) {
                    (Some(State::OperationEnabled), Some(t)) => t + 10,
                    _ => actual,
                };
                *target = Some(next);
                let cw = state
                    .and_then(State::next_command_towards_enabled)
                    .unwrap_or(Controlword::ENABLE_OPERATION);
                let mut o = sd.outputs_raw_mut();
                o[..2].copy_from_slice(&cw.bits().to_le_bytes());
                o[2..6].copy_from_slice(&next.to_le_bytes());
            }
            tick += period;
        }
        let enabled = group
            .iter(&maindevice)
            .filter(|sd| {
                let i = sd.inputs_raw();
                Statusword(u16::from_le_bytes([i[0], i[1]])).state()
                    == Some(State::OperationEnabled)
            })
            .count();
        (exchanges, wakeups, late, wrong_wkc, enabled)
    });
    let carried = link.stop();
    let mut sorted = exchanges.clone();
    sorted.sort();
    let missed = late.max(wrong_wkc);
    println!(
        "{n} devices, period {} µs, {} s: {} cycles, {missed} missed ({late} finished after \
         their period, {wrong_wkc} with a wrong working counter), {enabled} drives in operation \
         enabled at the end",
        period.as_micros(),
        seconds,
        exchanges.len()
    );
    println!(
        "exchange time: p50 {:?}, p99 {:?}, p99.9 {:?}, max {:?}; frames carried {}, dropped {}",
        percentile(&sorted, 0.5),
        percentile(&sorted, 0.99),
        percentile(&sorted, 0.999),
        sorted.last().copied().unwrap_or_default(),
        carried.frames,
        carried.dropped
    );
    wakeups.sort();
    println!(
        "wake-up after the tick: p50 {:?}, p99 {:?}, max {:?}",
        percentile(&wakeups, 0.5),
        percentile(&wakeups, 0.99),
        wakeups.last().copied().unwrap_or_default()
    );
}
