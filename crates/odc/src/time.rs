//! The runtime's one time type: an [`Instant`] on the caller's monotonic clock and a
//! [`Duration`] between two of them, both in microseconds.
//!
//! One unit everywhere, so nothing on the frame path converts (a 64-bit division costs a
//! library call on a Cortex-M); CiA 301's parameters in milliseconds (heartbeat, guarding)
//! and 100 µs (inhibit times) become durations by multiplication when the node reads them.
//! Arithmetic saturates: a clock near `u64::MAX` µs (584,000 years) does not wrap.

use core::ops::{Add, AddAssign, Sub};

/// A point on the caller's monotonic clock, in microseconds since any epoch (power-up, say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Instant(u64);

/// A span of time, in microseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Duration(u64);

impl Instant {
    /// The clock's epoch.
    pub const ZERO: Self = Self(0);

    /// The instant `us` microseconds after the epoch.
    pub const fn from_micros(us: u64) -> Self {
        Self(us)
    }

    /// The instant `ms` milliseconds after the epoch (saturating).
    pub const fn from_millis(ms: u64) -> Self {
        Self(ms.saturating_mul(1000))
    }

    /// Microseconds since the epoch.
    pub const fn as_micros(self) -> u64 {
        self.0
    }

    /// Whole milliseconds since the epoch (a division: for displays and hosts, not for the
    /// frame path).
    pub const fn as_millis(self) -> u64 {
        self.0 / 1000
    }

    /// `self + d`, at most the clock's last instant.
    pub const fn saturating_add(self, d: Duration) -> Self {
        Self(self.0.saturating_add(d.0))
    }

    /// `self - d`, at least the epoch.
    pub const fn saturating_sub(self, d: Duration) -> Self {
        Self(self.0.saturating_sub(d.0))
    }

    /// The time from `earlier` to `self`; zero when `earlier` is later.
    pub const fn saturating_duration_since(self, earlier: Self) -> Duration {
        Duration(self.0.saturating_sub(earlier.0))
    }
}

impl Duration {
    /// No time.
    pub const ZERO: Self = Self(0);
    /// One microsecond, the clock's resolution.
    pub const MICROSECOND: Self = Self(1);

    /// `us` microseconds.
    pub const fn from_micros(us: u64) -> Self {
        Self(us)
    }

    /// `ms` milliseconds (saturating).
    pub const fn from_millis(ms: u64) -> Self {
        Self(ms.saturating_mul(1000))
    }

    /// `s` seconds (saturating).
    pub const fn from_secs(s: u64) -> Self {
        Self(s.saturating_mul(1_000_000))
    }

    /// In microseconds.
    pub const fn as_micros(self) -> u64 {
        self.0
    }

    /// In whole milliseconds (a division: for displays and hosts, not for the frame path).
    pub const fn as_millis(self) -> u64 {
        self.0 / 1000
    }

    /// Whether it is no time at all (a timer that is off, in CiA 301's parameters).
    pub const fn is_zero(self) -> bool {
        self.0 == 0
    }

    /// `self × n` (saturating).
    pub const fn saturating_mul(self, n: u64) -> Self {
        Self(self.0.saturating_mul(n))
    }
}

#[cfg(feature = "std")]
impl Instant {
    /// The time since `epoch` on the host's monotonic clock, as an instant (saturating): how
    /// the `std` transports tell the time.
    pub fn since(epoch: std::time::Instant) -> Self {
        Self(u64::try_from(epoch.elapsed().as_micros()).unwrap_or(u64::MAX))
    }
}

impl core::fmt::Display for Duration {
    /// In the largest unit that keeps it whole: `1.5 s` is `1500 ms`, `250 µs` stays µs.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let us = self.0;
        if us == 0 {
            f.write_str("0 ms")
        } else if us.is_multiple_of(1_000_000) {
            write!(f, "{} s", us / 1_000_000)
        } else if us.is_multiple_of(1000) {
            write!(f, "{} ms", us / 1000)
        } else {
            write!(f, "{us} µs")
        }
    }
}

impl Add<Duration> for Instant {
    type Output = Instant;

    /// Saturating, as [`Instant::saturating_add`].
    fn add(self, d: Duration) -> Instant {
        self.saturating_add(d)
    }
}

impl AddAssign<Duration> for Instant {
    fn add_assign(&mut self, d: Duration) {
        *self = self.saturating_add(d);
    }
}

impl Sub for Instant {
    type Output = Duration;

    /// Saturating, as [`Instant::saturating_duration_since`].
    fn sub(self, earlier: Instant) -> Duration {
        self.saturating_duration_since(earlier)
    }
}

impl Add for Duration {
    type Output = Duration;

    /// Saturating.
    fn add(self, d: Duration) -> Duration {
        Self(self.0.saturating_add(d.0))
    }
}

impl From<core::time::Duration> for Duration {
    /// Whole microseconds, saturating.
    fn from(d: core::time::Duration) -> Self {
        Self(u64::try_from(d.as_micros()).unwrap_or(u64::MAX))
    }
}

impl From<Duration> for core::time::Duration {
    fn from(d: Duration) -> Self {
        core::time::Duration::from_micros(d.0)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn units_and_saturation() {
        assert_eq!(Duration::from_millis(3).as_micros(), 3000);
        assert_eq!(Duration::from_secs(2).as_micros(), 2_000_000);
        assert_eq!(Instant::from_millis(7).as_micros(), 7000);
        assert_eq!(Instant::from_micros(7999).as_millis(), 7);
        assert_eq!(
            Instant::from_micros(u64::MAX - 1) + Duration::from_micros(5),
            Instant::from_micros(u64::MAX)
        );
        assert_eq!(Instant::from_micros(10) - Instant::from_micros(30), Duration::ZERO);
        assert_eq!(
            Instant::from_micros(10).saturating_sub(Duration::from_micros(30)),
            Instant::ZERO
        );
        assert_eq!(
            Instant::from_micros(30).saturating_sub(Duration::from_micros(10)),
            Instant::from_micros(20)
        );
        assert_eq!(Instant::from_micros(30) - Instant::from_micros(10), Duration::from_micros(20));
        assert_eq!(
            Duration::from(core::time::Duration::from_nanos(2_500)),
            Duration::from_micros(2)
        );
        assert_eq!(core::time::Duration::from(Duration::from_micros(1500)).as_micros(), 1500);
        assert!(Duration::ZERO.is_zero() && !Duration::MICROSECOND.is_zero());
    }

    #[test]
    fn durations_print_in_their_largest_whole_unit() {
        use std::string::ToString;
        assert_eq!(Duration::from_secs(5).to_string(), "5 s");
        assert_eq!(Duration::from_millis(1500).to_string(), "1500 ms");
        assert_eq!(Duration::from_micros(250).to_string(), "250 µs");
        assert_eq!(Duration::ZERO.to_string(), "0 ms");
    }
}
