//! Homing (CiA 402-2 homing mode, mode 6) on the simulated [`Axis`](super::Axis): what each
//! method does where an axis has no hardware but a home switch at a known place.

/// Where the simulated axis's home switch is: active at and above this position of the
/// mechanics (the position actual value the drive powers on with is 0 of the mechanics,
/// below the switch).
pub const HOME_SWITCH: i64 = 1000;

/// The homing of the axis, for the statusword (bits 10, 12, 13).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Homing {
    /// Not started, or interrupted (controlword bit 4 cleared).
    #[default]
    Idle,
    /// Moving towards the home position.
    Searching,
    /// Done: the position actual value is the home offset (0x607C) there.
    Attained,
    /// A method the axis cannot perform, or no speed to search with.
    Error,
}

/// What the axis does for homing method `method` (0x6098).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Method {
    /// 35 and 37 (CiA 402-2 "homing on current position"): the current position is the
    /// home position.
    Here,
    /// 19: the positive home switch, no index pulse. The initial direction follows the
    /// switch (inactive: positive, active: negative); home is where it changes state.
    HomeSwitch,
    /// Any other: limit switches and index pulses the simulated axis does not have.
    Unsupported,
}

impl Method {
    pub(super) const fn of(method: Option<i8>) -> Method {
        match method {
            Some(35 | 37) => Method::Here,
            Some(19) => Method::HomeSwitch,
            _ => Method::Unsupported,
        }
    }
}
