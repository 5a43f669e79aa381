//! Unit tests of the 402 vocabulary.

use super::*;
use crate::{DataType, ObjValue, PdoValue, ValueError};

#[test]
fn commands_and_bits() {
    assert_eq!(Controlword::ENABLE_OPERATION.with_new_setpoint(true).bits(), 0x001F);
    assert_eq!(
        Controlword::ENABLE_OPERATION.with_change_set_immediately(true).with_relative(true).bits(),
        0x006F
    );
    assert_eq!(
        Controlword::ENABLE_OPERATION.with_halt(true).with_halt(false),
        Controlword::ENABLE_OPERATION
    );
    assert_eq!(Controlword::SHUTDOWN.with_change_on_setpoint(true).bits(), 0x0206);
    assert_eq!(Controlword::DISABLE_VOLTAGE.with_fault_reset(true), Controlword::FAULT_RESET);
    assert!(Controlword::ENABLE_OPERATION.with_homing_start(true).bit(4));
    assert!(!Controlword::SHUTDOWN.bit(16));
}

#[test]
fn state_decode() {
    let cases = [
        (0x0000, State::NotReadyToSwitchOn),
        (0x0250, State::SwitchOnDisabled),
        (0x0231, State::ReadyToSwitchOn),
        (0x0233, State::SwitchedOn),
        (0x0237, State::OperationEnabled),
        (0x1637, State::OperationEnabled),
        (0x0217, State::QuickStopActive),
        (0x021F, State::FaultReactionActive),
        (0x0218, State::Fault),
    ];
    for (w, s) in cases {
        assert_eq!(Statusword(w).state(), Some(s), "{w:#06x}");
    }
    assert_eq!(Statusword(0x0001).state(), None);
    let sw = Statusword(0x3637 | 0x0880);
    assert!(sw.target_reached() && sw.setpoint_ack() && sw.following_error());
    assert!(
        sw.voltage_enabled()
            && sw.quick_stop()
            && sw.remote()
            && sw.warning()
            && sw.internal_limit()
    );
    assert!(!sw.fault());
}

#[test]
fn walk_to_enabled() {
    // A toy drive that follows the CiA 402 transitions.
    fn step(s: State, c: Controlword) -> State {
        match (s, c.bits() & 0x8F) {
            (State::SwitchOnDisabled, 0x06) => State::ReadyToSwitchOn,
            (State::ReadyToSwitchOn, 0x07) => State::SwitchedOn,
            (State::SwitchedOn, 0x0F) => State::OperationEnabled,
            (State::Fault, 0x80) => State::SwitchOnDisabled,
            (State::QuickStopActive, 0x00) => State::SwitchOnDisabled,
            (s, _) => s,
        }
    }
    for start in [State::Fault, State::SwitchOnDisabled, State::QuickStopActive] {
        let mut s = start;
        for _ in 0..5 {
            s = step(s, s.next_command_towards_enabled().unwrap());
        }
        assert_eq!(s, State::OperationEnabled);
    }
    assert_eq!(State::FaultReactionActive.next_command_towards_enabled(), None);
}

#[test]
fn device_side_transitions() {
    use State::*;
    let cw = Controlword;
    // Every state's statusword decodes back to it.
    for s in [
        NotReadyToSwitchOn,
        SwitchOnDisabled,
        ReadyToSwitchOn,
        SwitchedOn,
        OperationEnabled,
        QuickStopActive,
        FaultReactionActive,
        Fault,
    ] {
        assert_eq!(s.statusword().state(), Some(s), "{s}");
        assert_eq!(s.statusword().with_voltage_enabled(true).state(), Some(s), "{s}");
    }
    assert_eq!(SwitchOnDisabled.after(Controlword::SHUTDOWN, false), ReadyToSwitchOn);
    assert_eq!(ReadyToSwitchOn.after(Controlword::SWITCH_ON, false), SwitchedOn);
    assert_eq!(ReadyToSwitchOn.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
    assert_eq!(SwitchedOn.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
    // Mode bits do not change the command: 0x1F is enable operation + new set-point.
    assert_eq!(OperationEnabled.after(cw(0x1F), false), OperationEnabled);
    assert_eq!(OperationEnabled.after(Controlword::DISABLE_OPERATION, false), SwitchedOn);
    assert_eq!(OperationEnabled.after(Controlword::SHUTDOWN, false), ReadyToSwitchOn);
    assert_eq!(OperationEnabled.after(Controlword::DISABLE_VOLTAGE, false), SwitchOnDisabled);
    // 0x000B (bits 0, 1, 3; bit 2 clear) is quick stop, as the LXM23A examples send it.
    assert_eq!(OperationEnabled.after(cw(0x0B), false), QuickStopActive);
    assert_eq!(QuickStopActive.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
    assert_eq!(QuickStopActive.after(Controlword::DISABLE_VOLTAGE, false), SwitchOnDisabled);
    assert_eq!(SwitchOnDisabled.after(Controlword::ENABLE_OPERATION, false), SwitchOnDisabled);
    assert_eq!(Fault.after(Controlword::FAULT_RESET, false), Fault);
    assert_eq!(Fault.after(Controlword::FAULT_RESET, true), SwitchOnDisabled);
    assert_eq!(Fault.after(Controlword::SHUTDOWN, true), Fault);
    // The manual drive's walk reaches "operation enabled" by the host's own commands.
    let mut s = SwitchOnDisabled;
    while let Some(c) = s.next_command_towards_enabled().filter(|_| s != OperationEnabled) {
        s = s.after(c, true);
    }
    assert_eq!(s, OperationEnabled);
}

#[test]
fn statusword_builders() {
    let sw = State::OperationEnabled
        .statusword()
        .with_voltage_enabled(true)
        .with_remote(true)
        .with_target_reached(true)
        .with_setpoint_ack(true)
        .with_bit(14, true);
    assert_eq!(sw.bits(), 0x5637);
    assert_eq!(sw.with_state(State::SwitchOnDisabled).bits(), 0x5650);
    assert_eq!(sw.with_bit(16, true), sw);
    assert_eq!(sw.with_following_error(true).bits(), 0x7637);
    assert!(sw.with_warning(true).warning());
    assert!(sw.with_internal_limit(true).internal_limit());
    assert_eq!(Controlword(0x0B).command(), Command::QuickStop);
    assert_eq!(Controlword(0x80).command(), Command::DisableVoltage);
    assert_eq!(Controlword(0x0E).command(), Command::Shutdown);
}

#[test]
fn modes() {
    for v in i8::MIN..=i8::MAX {
        assert_eq!(ModeOfOperation::from_i8(v).to_i8(), v);
    }
    assert_eq!(ModeOfOperation::from_i8(8), ModeOfOperation::CyclicSyncPosition);
    assert!(ModeOfOperation::from_i8(-3).is_manufacturer_specific());
    assert_eq!(ModeOfOperation::from_i8(5), ModeOfOperation::Other(5));
    let s = SupportedModes(0x0001_03A1);
    let listed: [Option<ModeOfOperation>; 5] = {
        let mut it = s.iter();
        [it.next(), it.next(), it.next(), it.next(), it.next()]
    };
    assert_eq!(
        listed,
        [
            Some(ModeOfOperation::ProfilePosition),
            Some(ModeOfOperation::Homing),
            Some(ModeOfOperation::CyclicSyncPosition),
            Some(ModeOfOperation::CyclicSyncVelocity),
            Some(ModeOfOperation::CyclicSyncTorque),
        ]
    );
    assert!(!s.supports(ModeOfOperation::Other(-1)));
    assert_eq!(s.manufacturer_bits(), 1);
    assert_eq!(ModeOfOperation::from_raw(0xF8, 8), Some(ModeOfOperation::Other(-8)));
    assert_eq!(ModeOfOperation::Other(-8).to_raw() & 0xFF, 0xF8);
}

#[test]
fn words_convert_and_order_by_raw_value() {
    let raw: u16 = Controlword::SHUTDOWN.into();
    assert_eq!(raw, 0x0006);
    assert_eq!(Controlword::from(0x000F), Controlword::ENABLE_OPERATION);
    assert_eq!(u16::from(Statusword(0x0237)), 0x0237);
    assert_eq!(Statusword::from(0x0250).state(), Some(State::SwitchOnDisabled));
    assert!(Controlword::SHUTDOWN < Controlword::ENABLE_OPERATION);
    assert!(Statusword(0x8000) > Statusword(0x7FFF));
}

#[test]
fn sdo_encodings() {
    let mut b = [0u8; 4];
    assert_eq!(Controlword::SHUTDOWN.encode(&mut b), Ok(2));
    assert_eq!(&b[..2], &[0x06, 0x00]);
    assert_eq!(Statusword::decode(&[0x37, 0x02]), Ok(Statusword(0x0237)));
    assert_eq!(ModeOfOperation::decode(&[0xFE]), Ok(ModeOfOperation::Other(-2)));
    assert_eq!(ModeOfOperation::Homing.encode(&mut b), Ok(1));
    assert_eq!(b[0], 6);
    assert_eq!(SupportedModes::decode(&[0x81, 0, 0, 0]), Ok(SupportedModes(0x81)));
    assert_eq!(Controlword::decode(&[1]), Err(ValueError::TooShort));
    assert_eq!(<ModeOfOperation as ObjValue>::DATA_TYPE, DataType::Integer8);
}
