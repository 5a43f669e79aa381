//! The driver in a closed loop with the device side ([`Drive`]) or a scripted drive. The
//! expected controlwords and bits are CiA 402's (transitions 2, 3, 4; set-point hand-shake of
//! bits 4/12; fault reset on the rising edge of bit 7; homing bits 12/13).

extern crate std;
use std::vec::Vec;

use super::*;
use crate::cia402::{Drive, DriveObjects};
use crate::time::{Duration, Instant};

#[derive(Default)]
struct Objects {
    cw: Controlword,
    sw: Statusword,
    mode: Option<ModeOfOperation>,
    target: i32,
    velocity_target: i32,
    position: i32,
    velocity: i32,
}

impl DriveObjects for Objects {
    fn controlword(&self) -> Controlword {
        self.cw
    }
    fn set_statusword(&mut self, sw: Statusword) {
        self.sw = sw;
    }
    fn modes_of_operation(&self) -> Option<ModeOfOperation> {
        self.mode
    }
    fn target_position(&self) -> Option<i32> {
        Some(self.target)
    }
    fn target_velocity(&self) -> Option<i32> {
        Some(self.velocity_target)
    }
    fn profile_velocity(&self) -> Option<u32> {
        Some(10_000)
    }
    fn set_position_actual_value(&mut self, p: i32) {
        self.position = p;
    }
    fn set_velocity_actual_value(&mut self, v: i32) {
        self.velocity = v;
    }
}

/// The driver and a simulated drive, 10 ms a cycle.
struct Loop {
    driver: Driver,
    od: Objects,
    drive: Drive,
    now: u64,
    sent: Vec<u16>,
}

impl Loop {
    fn new(supported: u32) -> Self {
        let mut l = Loop {
            driver: Driver::new(SupportedModes(supported))
                .with_timeout(Duration::from_millis(2_000)),
            od: Objects::default(),
            drive: Drive::new(),
            now: 0,
            sent: Vec::new(),
        };
        l.drive.start(&mut l.od);
        l
    }

    fn cycle(&mut self) {
        let inputs =
            Inputs::new(self.od.sw).with_position(self.od.position).with_velocity(self.od.velocity);
        let out = self.driver.cycle(&inputs, Instant::from_micros(self.now));
        if self.sent.last() != Some(&out.controlword.bits()) {
            self.sent.push(out.controlword.bits());
        }
        self.od.cw = out.controlword;
        self.od.mode = out.mode;
        self.od.target = out.target_position.unwrap_or(self.od.target);
        self.od.velocity_target = out.target_velocity.unwrap_or(self.od.velocity_target);
        self.drive.update(&mut self.od);
        self.drive.step(&mut self.od, crate::time::Duration::from_millis(10));
        self.now += 10_000;
    }

    fn run(&mut self) -> DriverStatus {
        for _ in 0..10_000 {
            if self.driver.status() != DriverStatus::Busy {
                break;
            }
            self.cycle();
        }
        self.driver.status()
    }

    fn enabled(supported: u32) -> Self {
        let mut l = Loop::new(supported);
        l.driver.enable();
        assert_eq!(l.run(), DriverStatus::Done);
        l.sent.clear();
        l
    }
}

#[test]
fn enable_walks_transitions_2_3_4() {
    let mut l = Loop::new(0x1);
    assert_eq!(l.driver.status(), DriverStatus::Idle);
    l.driver.enable();
    assert_eq!(l.run(), DriverStatus::Done);
    // Shutdown 0x06, switch on 0x07, enable operation 0x0F.
    assert_eq!(l.sent, [0x0006, 0x0007, 0x000F]);
    assert_eq!(l.od.sw.state(), Some(State::OperationEnabled));
}

#[test]
fn a_profile_position_move_with_the_set_point_hand_shake() {
    let mut l = Loop::enabled(0x1);
    l.driver.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    l.sent.clear();
    l.driver.move_to(1_000, false).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    // New set-point (bit 4: 0x1F) until acknowledged, then bit 4 clear (0x0F).
    assert_eq!(l.sent, [0x001F, 0x000F]);
    assert_eq!(l.od.position, 1_000);
    // Relative (bit 6): by 250 from where it is.
    l.sent.clear();
    l.driver.move_to(250, true).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    assert_eq!(l.sent, [0x005F, 0x004F]);
    assert_eq!(l.od.position, 1_250);
}

/// After homing, bit 12 ("homing attained") may still be set in the first statuswords the
/// driver sees in pp (a TPDO sampled before the mode switch): it acknowledges no set-point of
/// this move. The driver waits for it to clear, then hand-shakes; taking it for the
/// acknowledge, it cleared bit 4 before the drive saw it and the move never started (the drive
/// crate's test timed out so under load).
#[test]
fn a_set_point_acknowledge_left_from_homing_is_not_this_moves() {
    let enabled = State::OperationEnabled.statusword();
    let mut d = Driver::new(SupportedModes(1));
    d.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    d.cycle(&Inputs::new(enabled), Instant::ZERO);
    d.move_to(1_000, false).unwrap();
    let (mut sw, mut position, mut accepted) = (enabled.with_bit(12, true), 0, false);
    sw = sw.with_target_reached(true);
    let mut sent: Vec<u16> = Vec::new();
    for k in 0..100u64 {
        let out =
            d.cycle(&Inputs::new(sw).with_position(position), Instant::from_micros(k * 1_000));
        if sent.last() != Some(&out.controlword.bits()) {
            sent.push(out.controlword.bits());
        }
        if d.status() != DriverStatus::Busy {
            break;
        }
        // Three stale statuswords from homing, then a pp drive: bit 12 follows bit 4, the
        // move ends at once once accepted.
        if k >= 2 {
            let new_setpoint = out.controlword.bit(4);
            accepted |= new_setpoint;
            position = if accepted { 1_000 } else { 0 };
            sw = enabled.with_bit(12, new_setpoint).with_target_reached(accepted && !new_setpoint);
        }
    }
    assert_eq!(d.status(), DriverStatus::Done);
    // Bit 4 held low while bit 12 was stale, then the hand-shake: 0x1F until acknowledged.
    assert_eq!(sent, [0x000F, 0x001F, 0x000F]);
    assert_eq!(position, 1_000);
}

#[test]
fn profile_velocity_until_velocity_reached() {
    let mut l = Loop::enabled(0x5);
    l.driver.set_mode(ModeOfOperation::ProfileVelocity).unwrap();
    l.run();
    l.driver.run_at(2_000).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    assert_eq!(l.od.velocity, 2_000);
}

#[test]
fn a_fault_fails_the_job_and_a_reset_clears_it() {
    let mut l = Loop::enabled(0x1);
    l.driver.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    l.run();
    l.driver.move_to(100_000, false).unwrap();
    l.cycle();
    l.drive.fault(&mut l.od);
    assert_eq!(l.run(), DriverStatus::Failed(DriverError::Fault));
    // Enabling does not reset a fault by itself.
    l.driver.enable();
    assert_eq!(l.run(), DriverStatus::Failed(DriverError::Fault));
    l.sent.clear();
    l.driver.fault_reset();
    assert_eq!(l.run(), DriverStatus::Done);
    // Bit 7 low first, then its rising edge (0x80), then back to 0.
    assert_eq!(l.sent, [0x0000, 0x0080, 0x0000]);
    assert_eq!(l.od.sw.state(), Some(State::SwitchOnDisabled));
}

#[test]
fn quick_stop_and_disable() {
    let mut l = Loop::enabled(0x1);
    l.driver.quick_stop();
    assert_eq!(l.run(), DriverStatus::Done);
    assert!(matches!(l.od.sw.state(), Some(State::QuickStopActive | State::SwitchOnDisabled)));
    assert_eq!(l.sent.first(), Some(&0x0002));
    let mut l = Loop::enabled(0x1);
    l.driver.disable();
    assert_eq!(l.run(), DriverStatus::Done);
    assert_eq!(l.od.sw.state(), Some(State::SwitchOnDisabled));
}

#[test]
fn modes_are_checked_against_0x6502() {
    let mut l = Loop::enabled(0x1);
    assert_eq!(
        l.driver.set_mode(ModeOfOperation::CyclicSyncPosition),
        Err(DriverError::ModeNotSupported(ModeOfOperation::CyclicSyncPosition))
    );
    assert_eq!(
        l.driver.move_to(1, false),
        Err(DriverError::WrongMode { needs: ModeOfOperation::ProfilePosition })
    );
    // The mode display confirms a mode: a drive reporting another one is a timeout.
    let mut d = Driver::new(SupportedModes(0x1)).with_timeout(Duration::from_millis(50));
    d.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    let wrong = Inputs::new(State::OperationEnabled.statusword()).with_mode(3);
    let mut now = 0;
    while d.status() == DriverStatus::Busy {
        d.cycle(&wrong, Instant::from_micros(now));
        now += 10_000;
    }
    assert_eq!(
        d.status(),
        DriverStatus::Failed(DriverError::Timeout { waiting_for: "the mode display (0x6061)" })
    );
    assert!(now <= 80_000, "{now}");
}

/// A move that outlasts the job timeout (1,000,000 units at 10,000 units/s, 2 s allowed)
/// fails with the timeout, and the drive stops: the halt bit (CiA 402-2 controlword bit 8)
/// goes out in the cycle the timeout fires, the drive stays enabled, the position no longer
/// changes.
#[test]
fn a_job_timeout_halts_the_drive() {
    let mut l = Loop::enabled(0x1);
    l.driver.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    l.driver.move_to(1_000_000, false).unwrap();
    assert_eq!(
        l.run(),
        DriverStatus::Failed(DriverError::Timeout { waiting_for: "target reached (bit 10)" })
    );
    assert_eq!(l.od.cw.bits(), 0x010F, "enable operation with halt");
    // 2 s at 10,000 units/s: about 20,000 units, far from the target.
    let stopped_at = l.od.position;
    assert!((19_000..=21_000).contains(&stopped_at), "{stopped_at}");
    for _ in 0..50 {
        l.cycle();
    }
    assert_eq!(l.od.position, stopped_at, "the drive kept moving after the timeout");
    assert_eq!(l.od.sw.state(), Some(State::OperationEnabled));
    // The next job takes over from the halt.
    l.driver.move_to(stopped_at + 100, false).unwrap();
    assert_eq!(l.run(), DriverStatus::Done);
    assert_eq!(l.od.position, stopped_at + 100);
}

#[test]
fn a_silent_drive_is_a_timeout() {
    let mut d = Driver::new(SupportedModes(0x1)).with_timeout(Duration::from_millis(100));
    d.enable();
    let stuck = Inputs::new(State::SwitchOnDisabled.statusword());
    let mut now = 0;
    while d.status() == DriverStatus::Busy {
        let out = d.cycle(&stuck, Instant::from_micros(now));
        assert_eq!(out.controlword, Controlword::SHUTDOWN);
        now += 10_000;
    }
    assert_eq!(
        d.status(),
        DriverStatus::Failed(DriverError::Timeout { waiting_for: "operation enabled" })
    );
}

/// A scripted drive in operation enabled: homing attained `after` cycles of bit 4 (or a
/// homing error), csp following the set-point one cycle late.
fn scripted(d: &mut Driver, cycles: usize, mut device: impl FnMut(Outputs, usize) -> Statusword) {
    let mut sw = State::OperationEnabled.statusword();
    for k in 0..cycles {
        let out = d.cycle(&Inputs::new(sw), Instant::from_micros(k as u64 * 1_000));
        sw = device(out, k);
        if d.status() != DriverStatus::Busy {
            return;
        }
    }
}

#[test]
fn homing_to_attained_and_a_homing_error() {
    let enabled = State::OperationEnabled.statusword();
    let mut d = Driver::new(SupportedModes(1 << 5));
    d.set_mode(ModeOfOperation::Homing).unwrap();
    d.cycle(&Inputs::new(enabled), Instant::ZERO);
    d.home().unwrap();
    let mut starts = 0;
    scripted(&mut d, 100, |out, _| {
        if out.controlword.bit(4) {
            starts += 1;
        }
        // Attained (12) and target reached (10) after five cycles of bit 4.
        enabled.with_bit(12, starts >= 5).with_target_reached(starts >= 5)
    });
    assert_eq!(d.status(), DriverStatus::Done);
    assert_eq!(d.outputs().controlword, Controlword::ENABLE_OPERATION);
    d.home().unwrap();
    scripted(&mut d, 100, |_, k| enabled.with_bit(13, k >= 3));
    assert_eq!(d.status(), DriverStatus::Failed(DriverError::Homing));
}

#[test]
fn a_csp_ramp_of_1000_cycles_then_a_following_error() {
    let enabled = State::OperationEnabled.statusword();
    let mut d = Driver::new(SupportedModes(1 << 7));
    d.set_mode(ModeOfOperation::CyclicSyncPosition).unwrap();
    d.cycle(&Inputs::new(enabled), Instant::ZERO);
    let mut followed = Vec::new();
    for k in 0..1000i32 {
        d.stream_position(k * 10).unwrap();
        let out = d.cycle(
            &Inputs::new(enabled).with_position((k - 1) * 10),
            Instant::from_micros(u64::from(k.unsigned_abs()) * 1_000),
        );
        followed.push(out.target_position);
        assert_eq!(d.status(), DriverStatus::Busy, "cycle {k}");
    }
    // Every set-point went out, in its cycle.
    assert!(followed.iter().enumerate().all(|(k, t)| *t == Some(k as i32 * 10)));
    d.stream_position(10_000).unwrap();
    d.cycle(&Inputs::new(enabled.with_following_error(true)), Instant::from_micros(2_000_000));
    assert_eq!(d.status(), DriverStatus::Failed(DriverError::FollowingError));
}
