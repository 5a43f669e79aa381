//! The drive's side of CiA 402: the objects a drive's firmware reads and sets
//! ([`DriveObjects`]), the power state machine the controlword drives ([`DeviceControl`]),
//! and a simple axis ([`Axis`]) that runs profile position, profile velocity, homing
//! (methods 35/37 and 19, see [`HOME_SWITCH`]) and the cyclic synchronous position, velocity
//! and torque modes. [`Drive`]
//! puts the three together for a simulated device.
//!
//! No bus code: the application (or `odc simulate`) calls [`Drive::update`] after each
//! received frame and [`Drive::step`] with the time that passed; both read the commands from
//! the dictionary and write the statusword and actual values back into it.
//!
//! ```
//! use odc::cia402::{Controlword, Drive, DriveObjects, ModeOfOperation, State, Statusword};
//! use odc::time::Duration;
//!
//! /// The 402 objects of a tiny drive (generated dictionaries implement the trait).
//! #[derive(Default)]
//! struct Objects { cw: Controlword, sw: Statusword, target: i32, position: i32 }
//! impl DriveObjects for Objects {
//!     fn controlword(&self) -> Controlword { self.cw }
//!     fn set_statusword(&mut self, sw: Statusword) { self.sw = sw }
//!     fn modes_of_operation(&self) -> Option<ModeOfOperation> { Some(ModeOfOperation::ProfilePosition) }
//!     fn target_position(&self) -> Option<i32> { Some(self.target) }
//!     fn profile_velocity(&self) -> Option<u32> { Some(1000) }
//!     fn set_position_actual_value(&mut self, p: i32) { self.position = p }
//! }
//!
//! let mut od = Objects::default();
//! let mut drive = Drive::new();
//! drive.start(&mut od);
//! assert_eq!(od.sw.state(), Some(State::SwitchOnDisabled));
//! for cw in [Controlword::SHUTDOWN, Controlword::SWITCH_ON, Controlword::ENABLE_OPERATION] {
//!     od.cw = cw; // the master writes 0x6040
//!     drive.update(&mut od);
//! }
//! assert_eq!(od.sw.state(), Some(State::OperationEnabled));
//! od.target = 250;
//! od.cw = Controlword::ENABLE_OPERATION.with_new_setpoint(true);
//! drive.update(&mut od);
//! assert!(od.sw.setpoint_ack() && !od.sw.target_reached());
//! drive.step(&mut od, Duration::from_millis(100)); // at 1000 units/s
//! assert_eq!(od.position, 100);
//! drive.step(&mut od, Duration::from_millis(200));
//! assert_eq!(od.position, 250);
//! assert!(od.sw.target_reached());
//! ```

#[cfg(feature = "cia402")]
pub use super::homing::HOME_SWITCH;
#[cfg(feature = "cia402")]
use super::homing::{Homing, Method};
#[cfg_attr(not(feature = "cia402"), allow(unused_imports))]
use super::{Controlword, ModeOfOperation, State, Statusword};
#[cfg(feature = "cia402")]
use crate::time::Duration;

/// The CiA 402 objects a drive's firmware reads (what the master commands) and sets (what
/// the drive reports, read-only over SDO). Generated slave dictionaries implement it when the
/// device file has the controlword 0x6040 and statusword 0x6041; the other objects have
/// defaults (absent: `None`, or the value is not stored) and are implemented for those the
/// file has with the profile's data type.
pub trait DriveObjects {
    /// 0x6040 controlword.
    fn controlword(&self) -> Controlword;
    /// 0x6041 statusword.
    fn set_statusword(&mut self, statusword: Statusword);
    /// 0x6060 modes of operation, INTEGER8.
    fn modes_of_operation(&self) -> Option<ModeOfOperation> {
        None
    }
    /// 0x6061 modes of operation display, INTEGER8.
    fn set_modes_of_operation_display(&mut self, mode: ModeOfOperation) {
        let _ = mode;
    }
    /// 0x607A target position, INTEGER32 (position units).
    fn target_position(&self) -> Option<i32> {
        None
    }
    /// 0x60FF target velocity, INTEGER32 (velocity units).
    fn target_velocity(&self) -> Option<i32> {
        None
    }
    /// 0x6081 profile velocity, UNSIGNED32 (velocity units; the axis takes them as position
    /// units per second).
    fn profile_velocity(&self) -> Option<u32> {
        None
    }
    /// 0x6064 position actual value, INTEGER32.
    fn set_position_actual_value(&mut self, position: i32) {
        let _ = position;
    }
    /// 0x606C velocity actual value, INTEGER32.
    fn set_velocity_actual_value(&mut self, velocity: i32) {
        let _ = velocity;
    }
    /// 0x6098 homing method, INTEGER8.
    fn homing_method(&self) -> Option<i8> {
        None
    }
    /// 0x6099:01 homing speed during search for switch, UNSIGNED32 (velocity units).
    fn homing_speed(&self) -> Option<u32> {
        None
    }
    /// 0x607C home offset, INTEGER32: the position actual value at the home position.
    fn home_offset(&self) -> Option<i32> {
        None
    }
    /// 0x6071 target torque, INTEGER16.
    fn target_torque(&self) -> Option<i16> {
        None
    }
    /// 0x6077 torque actual value, INTEGER16.
    fn set_torque_actual_value(&mut self, torque: i16) {
        let _ = torque;
    }
}

/// The CiA 402 power state machine on the device side (CiA 402-2 §6.2, IEC 61800-7-201
/// figure "state machine"): transitions 2–12, 15 and 16 from the controlword, 0/1 at start,
/// 13 on a fault, 14 and 12 when the drive has stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg(feature = "cia402")]
pub struct DeviceControl {
    state: State,
    last: Controlword,
    quick_stop_option: i16,
    /// After a lost connection stopped the drive: the master's last controlword is not acted
    /// on again until it changes (a stale "enable operation" would undo the stop).
    held: bool,
}

#[cfg(feature = "cia402")]
impl Default for DeviceControl {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(feature = "cia402")]
impl DeviceControl {
    /// A drive in "not ready to switch on" (transition 0 done), quick stop option code 2
    /// (the default of 0x605A: slow down on the quick stop ramp, then "switch on disabled").
    pub const fn new() -> Self {
        Self {
            state: State::NotReadyToSwitchOn,
            last: Controlword::DISABLE_VOLTAGE,
            quick_stop_option: 2,
            held: false,
        }
    }

    /// The same machine with another quick stop option code (0x605A): 0–4 leave "quick stop
    /// active" for "switch on disabled" once stopped (transition 12), 5–8 stay in it and allow
    /// transition 16 back to "operation enabled".
    pub const fn with_quick_stop_option(mut self, code: i16) -> Self {
        self.quick_stop_option = code;
        self
    }

    /// The current state.
    pub const fn state(&self) -> State {
        self.state
    }

    fn go(&mut self, to: State) -> Option<u8> {
        let number = transition(self.state, to)?;
        self.state = to;
        Some(number)
    }

    /// Transition 1: initialisation and self-test are done; the drive enters "switch on
    /// disabled". Returns the transition number, `None` when not in "not ready to switch on".
    pub fn initialised(&mut self) -> Option<u8> {
        if self.state == State::NotReadyToSwitchOn {
            return self.go(State::SwitchOnDisabled);
        }
        None
    }

    /// The controlword the master wrote (call it for every write, or every cycle with the
    /// current value: a repeated controlword takes no transition, and fault reset acts on the
    /// rising edge of bit 7 only). Returns the number of the transition taken.
    pub fn controlword(&mut self, cw: Controlword) -> Option<u8> {
        if self.held && cw == self.last {
            return None;
        }
        self.held = false;
        let edge = cw.bit(7) && !self.last.bit(7);
        self.last = cw;
        let to = self.state.after(cw, edge);
        if self.state == State::QuickStopActive
            && to == State::OperationEnabled
            && !(5..=8).contains(&self.quick_stop_option)
        {
            // Transition 16 only with quick stop option codes 5–8.
            return None;
        }
        if to == self.state { None } else { self.go(to) }
    }

    /// Transition 13: a fault occurred (from any state but the fault states).
    pub fn fault(&mut self) -> Option<u8> {
        match self.state {
            State::FaultReactionActive | State::Fault => None,
            _ => self.go(State::FaultReactionActive),
        }
    }

    /// The connection to the master was lost (a heartbeat the node consumes, life guarding):
    /// the abort connection option code (0x6007, CiA 402-2 §6.5.1) says what follows. 1: a
    /// fault (transition 13); 2: the "disable voltage" command; 3: the "quick stop" command;
    /// 0 (no action) and the manufacturer-specific negative codes: nothing here. After 2 or
    /// 3 the master's last controlword is held until it changes. Returns the transition.
    pub fn connection_lost(&mut self, code: i16) -> Option<u8> {
        let command = match code {
            1 => return self.fault(),
            2 => Controlword::DISABLE_VOLTAGE,
            3 => Controlword::QUICK_STOP,
            _ => return None,
        };
        self.held = true;
        let to = self.state.after(command, false);
        if to == self.state { None } else { self.go(to) }
    }

    /// The drive has come to a standstill: the fault reaction ends in "fault" (14); a quick
    /// stop ends in "switch on disabled" (12) unless the option code keeps it in "quick stop
    /// active".
    pub fn stopped(&mut self) -> Option<u8> {
        match self.state {
            State::FaultReactionActive => self.go(State::Fault),
            State::QuickStopActive if (0..=4).contains(&self.quick_stop_option) => {
                self.go(State::SwitchOnDisabled)
            }
            _ => None,
        }
    }

    /// Whether the drive is stopping on its own (quick stop or fault reaction).
    pub const fn stopping(&self) -> bool {
        matches!(self.state, State::QuickStopActive | State::FaultReactionActive)
    }

    /// The statusword of the state (CiA 402-2 table "state coding"), with bit 4 (voltage
    /// enabled) set in the states with the power stage on and bit 9 (remote) set: the
    /// controlword is processed.
    pub const fn statusword(&self) -> Statusword {
        let powered = matches!(
            self.state,
            State::ReadyToSwitchOn
                | State::SwitchedOn
                | State::OperationEnabled
                | State::QuickStopActive
                | State::FaultReactionActive
        );
        self.state.statusword().with_voltage_enabled(powered).with_remote(true)
    }
}

/// The number of the CiA 402 transition from `from` to `to`, `None` for a pair the state
/// machine has no transition for. "Ready to switch on" to "operation enabled" is transitions
/// 3 and 4 in one step (the profile lets enable operation do both); it is reported as 4.
#[cfg(feature = "cia402")]
pub const fn transition(from: State, to: State) -> Option<u8> {
    use State::*;
    Some(match (from, to) {
        (NotReadyToSwitchOn, SwitchOnDisabled) => 1,
        (SwitchOnDisabled, ReadyToSwitchOn) => 2,
        (ReadyToSwitchOn, SwitchedOn) => 3,
        (SwitchedOn | ReadyToSwitchOn, OperationEnabled) => 4,
        (OperationEnabled, SwitchedOn) => 5,
        (SwitchedOn, ReadyToSwitchOn) => 6,
        (ReadyToSwitchOn, SwitchOnDisabled) => 7,
        (OperationEnabled, ReadyToSwitchOn) => 8,
        (OperationEnabled, SwitchOnDisabled) => 9,
        (SwitchedOn, SwitchOnDisabled) => 10,
        (OperationEnabled, QuickStopActive) => 11,
        (QuickStopActive, SwitchOnDisabled) => 12,
        (FaultReactionActive, Fault) => 14,
        (Fault, SwitchOnDisabled) => 15,
        (QuickStopActive, OperationEnabled) => 16,
        (Fault | FaultReactionActive, _) => return None,
        (_, FaultReactionActive) => 13,
        _ => return None,
    })
}

/// A simple axis: profile position (a set-point handshake on controlword bit 4, absolute or
/// relative by bit 6, motion at the profile velocity), profile velocity (the actual
/// velocity is the target velocity at once), homing (bit 4 starts it: methods 35 and 37 at
/// once, 19 by moving to the home switch at [`HOME_SWITCH`] at 0x6099:01, else the profile
/// velocity; another method ends in homing error), and the cyclic synchronous modes, which
/// follow their targets within the cycle (CSP the position, CSV the velocity, CST the
/// torque); halt (bit 8) stops it. Positions in position units, velocities in position units
/// per second.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg(feature = "cia402")]
pub struct Axis {
    position: i64,
    velocity: i64,
    target: Option<i64>,
    setpoint_ack: bool,
    last: Controlword,
    mode: Option<ModeOfOperation>,
    /// Motion of less than one unit carried to the next step, in units × µs.
    carry: i64,
    homing: Homing,
    /// The position of the mechanics minus the position actual value (homing moves the
    /// latter).
    shift: i64,
    /// The home offset of the homing under way.
    home_offset: i64,
    torque: i16,
    /// In a cyclic synchronous mode with operation enabled: following the command value.
    following: bool,
}

#[cfg(feature = "cia402")]
impl Axis {
    /// An axis at position 0, standing.
    pub const fn new() -> Self {
        Self {
            position: 0,
            velocity: 0,
            target: None,
            setpoint_ack: false,
            last: Controlword::DISABLE_VOLTAGE,
            mode: None,
            carry: 0,
            homing: Homing::Idle,
            shift: 0,
            home_offset: 0,
            torque: 0,
            following: false,
        }
    }

    /// The actual torque (cyclic synchronous torque: the target torque).
    pub const fn torque(&self) -> i16 {
        self.torque
    }

    /// Whether the axis is homed (statusword bit 12 in homing mode).
    pub fn homed(&self) -> bool {
        self.homing == Homing::Attained
    }

    /// Controlword bit 4 rose in homing mode: start the method of 0x6098.
    fn start_homing<D: DriveObjects + ?Sized>(&mut self, od: &D) {
        self.home_offset = od.home_offset().map_or(0, i64::from);
        self.homing = match Method::of(od.homing_method()) {
            Method::Here => {
                self.home();
                Homing::Attained
            }
            Method::HomeSwitch => {
                let speed = od.homing_speed().filter(|&s| s > 0).or(od.profile_velocity());
                match speed.filter(|&s| s > 0) {
                    Some(_) => {
                        self.target = Some(HOME_SWITCH - self.shift);
                        Homing::Searching
                    }
                    None => Homing::Error,
                }
            }
            Method::Unsupported => Homing::Error,
        };
    }

    /// The axis is at its home position: the position actual value becomes the home offset.
    fn home(&mut self) {
        self.shift += self.position - self.home_offset;
        self.position = self.home_offset;
        self.target = None;
        self.velocity = 0;
        self.carry = 0;
    }

    /// The actual position.
    pub const fn position(&self) -> i64 {
        self.position
    }

    /// The actual velocity.
    pub const fn velocity(&self) -> i64 {
        self.velocity
    }

    /// The commands of `od` with the drive in `state`: the mode, a new set-point (bit 4
    /// rising in profile position), the target velocity (profile velocity), halt.
    pub fn command<D: DriveObjects + ?Sized>(&mut self, od: &D, state: State) {
        let cw = od.controlword();
        let mode = od.modes_of_operation();
        let enabled = state == State::OperationEnabled;
        if mode != self.mode {
            self.target = None;
            self.mode = mode;
            if self.homing == Homing::Searching {
                self.homing = Homing::Idle;
            }
        }
        match mode {
            Some(ModeOfOperation::ProfilePosition) => {
                if enabled
                    && cw.bit(4)
                    && !self.last.bit(4)
                    && let Some(target) = od.target_position()
                {
                    let target = i64::from(target);
                    self.target = Some(if cw.bit(6) { self.position + target } else { target });
                    self.setpoint_ack = true;
                }
                if !cw.bit(4) {
                    self.setpoint_ack = false;
                }
                let speed = od.profile_velocity().map_or(0, i64::from);
                self.velocity = match self.target {
                    Some(t) if enabled && !cw.bit(8) => (t - self.position).signum() * speed,
                    _ => 0,
                };
            }
            Some(ModeOfOperation::ProfileVelocity) if enabled && !cw.bit(8) => {
                self.velocity = od.target_velocity().map_or(0, i64::from);
            }
            Some(ModeOfOperation::Homing) => {
                if enabled && cw.bit(4) && !self.last.bit(4) {
                    self.start_homing(od);
                }
                if !cw.bit(4) && self.homing == Homing::Searching {
                    // Bit 4 cleared: homing interrupted.
                    self.homing = Homing::Idle;
                    self.target = None;
                }
                let speed = od.homing_speed().filter(|&s| s > 0).or(od.profile_velocity());
                let speed = speed.map_or(0, i64::from);
                self.velocity = match self.target {
                    Some(t) if enabled && !cw.bit(8) => (t - self.position).signum() * speed,
                    _ => 0,
                };
            }
            // Cyclic synchronous position: the set-point of the cycle, reached by its end
            // (an ideal position loop; the velocity is what it took).
            Some(ModeOfOperation::CyclicSyncPosition) if enabled => {
                self.target = od.target_position().map(i64::from);
                self.velocity = 0;
            }
            // Cyclic synchronous velocity: the target velocity at once (an ideal loop).
            Some(ModeOfOperation::CyclicSyncVelocity) if enabled => {
                self.velocity = od.target_velocity().map_or(0, i64::from);
            }
            // Cyclic synchronous torque: the target torque at once; the axis has no load
            // model, so it does not move.
            Some(ModeOfOperation::CyclicSyncTorque) if enabled => {
                self.torque = od.target_torque().unwrap_or(0);
                self.velocity = 0;
            }
            _ => self.velocity = 0,
        }
        if mode != Some(ModeOfOperation::CyclicSyncTorque) || !enabled {
            self.torque = 0;
        }
        self.following = enabled
            && matches!(
                mode,
                Some(
                    ModeOfOperation::CyclicSyncPosition
                        | ModeOfOperation::CyclicSyncVelocity
                        | ModeOfOperation::CyclicSyncTorque
                )
            );
        if !enabled {
            // Leaving "operation enabled" drops the set-point: no motion resumes on its own.
            self.velocity = 0;
            self.target = None;
            if self.homing == Homing::Searching {
                self.homing = Homing::Idle;
            }
        }
        self.last = cw;
    }

    /// Moves for `dt` at the commanded velocity (units/s; stopping at a profile position
    /// target).
    pub fn step(&mut self, dt: Duration) {
        let dt_us = i64::try_from(dt.as_micros()).unwrap_or(i64::MAX);
        let travel = self.velocity.saturating_mul(dt_us).saturating_add(self.carry);
        let mut delta = travel / 1_000_000;
        self.carry = travel % 1_000_000;
        let homing = self.homing == Homing::Searching;
        if (self.mode == Some(ModeOfOperation::ProfilePosition) || homing)
            && let Some(t) = self.target
        {
            let remaining = t - self.position;
            if delta.unsigned_abs() >= remaining.unsigned_abs() {
                delta = remaining;
                self.velocity = 0;
                self.carry = 0;
            }
        }
        self.position = self.position.saturating_add(delta);
        if homing && self.target == Some(self.position) {
            // At the home switch's edge (method 19).
            self.home();
            self.homing = Homing::Attained;
        }
        if self.mode == Some(ModeOfOperation::CyclicSyncPosition)
            && let Some(t) = self.target
        {
            self.position = t;
        }
    }

    /// Stops at once (quick stop and fault reaction: the axis has no ramps).
    pub fn stop(&mut self) {
        self.velocity = 0;
        self.carry = 0;
    }

    /// `sw` with the mode bits of the axis: target reached (10) and, in profile position,
    /// set-point acknowledge (12), in profile velocity "speed" (12, velocity zero), in homing
    /// "homing attained" (12) and "homing error" (13), in the cyclic synchronous modes
    /// "following the command value" (12).
    pub fn statusword(&self, sw: Statusword) -> Statusword {
        let halted = self.last.bit(8) && self.velocity == 0;
        let reached = match self.mode {
            Some(ModeOfOperation::ProfilePosition) => {
                self.target.is_none_or(|t| t == self.position) || halted
            }
            Some(ModeOfOperation::Homing) => self.homing != Homing::Searching || halted,
            _ => true,
        };
        let bit12 = match self.mode {
            Some(ModeOfOperation::ProfilePosition) => self.setpoint_ack,
            Some(ModeOfOperation::ProfileVelocity) => self.velocity == 0,
            Some(ModeOfOperation::Homing) => self.homing == Homing::Attained,
            Some(
                ModeOfOperation::CyclicSyncPosition
                | ModeOfOperation::CyclicSyncVelocity
                | ModeOfOperation::CyclicSyncTorque,
            ) => self.following,
            _ => false,
        };
        let homing_error =
            self.mode == Some(ModeOfOperation::Homing) && self.homing == Homing::Error;
        sw.with_target_reached(reached).with_setpoint_ack(bit12).with_bit(13, homing_error)
    }
}

/// A simulated CiA 402 drive: the state machine and the axis over a dictionary's
/// [`DriveObjects`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg(feature = "cia402")]
pub struct Drive {
    control: DeviceControl,
    axis: Axis,
    /// The torque actual value last written (0x6077): written again only when it changes,
    /// as the other modes leave it at 0 (one dictionary write less per frame).
    torque_shown: Option<i16>,
}

#[cfg(feature = "cia402")]
impl Drive {
    /// A drive in "not ready to switch on", the axis at 0.
    pub const fn new() -> Self {
        Self { control: DeviceControl::new(), axis: Axis::new(), torque_shown: None }
    }

    /// The same drive with another state machine (say, another quick stop option code).
    pub const fn with_control(mut self, control: DeviceControl) -> Self {
        self.control = control;
        self
    }

    /// The state machine.
    pub const fn control(&self) -> &DeviceControl {
        &self.control
    }

    /// The axis.
    pub const fn axis(&self) -> &Axis {
        &self.axis
    }

    /// Initialisation done (transition 1); publishes the statusword.
    pub fn start<D: DriveObjects + ?Sized>(&mut self, od: &mut D) {
        self.control.initialised();
        self.publish(od);
    }

    /// Reads the commands from `od` (call it after every received frame: an SDO or RPDO may
    /// have written them), takes the transition the controlword commands, and publishes.
    /// Returns the transition number taken.
    pub fn update<D: DriveObjects + ?Sized>(&mut self, od: &mut D) -> Option<u8> {
        let taken = self.control.controlword(od.controlword());
        self.axis.command(od, self.control.state());
        self.publish(od);
        taken
    }

    /// `dt` of motion; a quick stop or fault reaction completes here (the axis stops at
    /// once). Returns the transition number taken, if any.
    pub fn step<D: DriveObjects + ?Sized>(&mut self, od: &mut D, dt: Duration) -> Option<u8> {
        let taken = if self.control.stopping() {
            self.axis.stop();
            self.control.stopped()
        } else {
            self.axis.step(dt);
            None
        };
        self.axis.command(od, self.control.state());
        self.publish(od);
        taken
    }

    /// A fault (transition 13); the next [`Drive::step`] ends the reaction in "fault".
    pub fn fault<D: DriveObjects + ?Sized>(&mut self, od: &mut D) -> Option<u8> {
        let taken = self.control.fault();
        self.axis.stop();
        self.publish(od);
        taken
    }

    /// The connection to the master was lost: what the abort connection option `code`
    /// (0x6007) commands, as [`DeviceControl::connection_lost`]; a quick stop completes in
    /// the next [`Drive::step`].
    pub fn connection_lost<D: DriveObjects + ?Sized>(
        &mut self,
        od: &mut D,
        code: i16,
    ) -> Option<u8> {
        if code == 1 {
            return self.fault(od);
        }
        let taken = self.control.connection_lost(code);
        self.axis.command(od, self.control.state());
        self.publish(od);
        taken
    }

    fn publish<D: DriveObjects + ?Sized>(&mut self, od: &mut D) {
        od.set_statusword(self.axis.statusword(self.control.statusword()));
        if let Some(mode) = od.modes_of_operation() {
            od.set_modes_of_operation_display(mode);
        }
        let clamp = |v: i64| i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX });
        od.set_position_actual_value(clamp(self.axis.position()));
        od.set_velocity_actual_value(clamp(self.axis.velocity()));
        let torque = self.axis.torque();
        if self.torque_shown != Some(torque) {
            od.set_torque_actual_value(torque);
            self.torque_shown = Some(torque);
        }
    }
}

#[cfg(test)]
#[path = "device_tests.rs"]
#[cfg(feature = "cia402")]
mod tests;
