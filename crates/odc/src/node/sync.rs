//! SYNC of a [`Node`](super::Node) (CiA 301 7.2.5): the consumer of the COB-ID in 0x1005
//! with the counter overflow of 0x1019 and, with the feature `sync-producer`, the producer
//! (0x1005 bit 30, period 0x1006 in µs).

use super::params::{get_u8, get_u32};
use crate::can::CanFrame;
use crate::slave::ObjectDictionary;
#[cfg(feature = "sync-producer")]
use crate::time::Duration;
use crate::time::Instant;

/// The SYNC parameters and, for a producer, its counter and timer.
#[derive(Clone, Debug)]
pub(super) struct Sync {
    cob_id: u32,
    overflow: u8,
    #[cfg(feature = "sync-producer")]
    producer: Producer,
}

#[cfg(feature = "sync-producer")]
#[derive(Clone, Copy, Debug)]
struct Producer {
    period: Duration,
    counter: u8,
    next: Instant,
}

impl Sync {
    pub(super) const fn new() -> Self {
        Self {
            cob_id: 0x80,
            overflow: 0,
            #[cfg(feature = "sync-producer")]
            producer: Producer { period: Duration::ZERO, counter: 0, next: Instant::ZERO },
        }
    }

    /// The first SYNC a producer sends is one period after the boot-up.
    #[cfg_attr(not(feature = "sync-producer"), allow(clippy::unused_self, unused_variables))]
    pub(super) fn start(&mut self, now: Instant) {
        #[cfg(feature = "sync-producer")]
        {
            self.producer.next = now.saturating_add(self.producer.period);
        }
    }

    /// Reads 0x1005, 0x1006 and 0x1019 again; a node that becomes producer starts counting
    /// from now.
    #[cfg_attr(not(feature = "sync-producer"), allow(unused_variables))]
    pub(super) fn load<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now: Instant) {
        #[cfg(feature = "sync-producer")]
        let was_producer = self.is_producer();
        self.cob_id = get_u32(dict, 0x1005, 0).unwrap_or(0x80);
        self.overflow = get_u8(dict, 0x1019, 0).unwrap_or(0);
        #[cfg(feature = "sync-producer")]
        {
            let period = u64::from(get_u32(dict, 0x1006, 0).unwrap_or(0));
            self.producer.period = Duration::from_micros(period);
            if !was_producer && self.is_producer() {
                self.producer.counter = 0;
                self.producer.next = now.saturating_add(self.producer.period);
            }
        }
    }

    fn id(&self) -> u32 {
        self.cob_id & 0x7FF
    }

    /// `Some(counter)` when `frame` is a SYNC this node consumes (11-bit COB-ID of 0x1005);
    /// the counter only when 0x1019 says SYNCs carry one.
    pub(super) fn received(&self, frame: &CanFrame) -> Option<Option<u8>> {
        (frame.is_data(self.id()) && self.cob_id & (1 << 29) == 0)
            .then(|| frame.bytes().first().copied().filter(|_| self.overflow > 1))
    }

    #[cfg(feature = "sync-producer")]
    fn is_producer(&self) -> bool {
        self.cob_id & (1 << 30) != 0 && !self.producer.period.is_zero()
    }

    /// A producer whose period has come sends the SYNC (with the counter when 0x1019 > 1)
    /// and returns `Some(counter)`, for the node to run its synchronous PDOs.
    #[cfg(feature = "sync-producer")]
    pub(super) fn produce(
        &mut self,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Option<Option<u8>> {
        if !self.is_producer() || now < self.producer.next {
            return None;
        }
        let p = &mut self.producer;
        let counter = (self.overflow > 1).then(|| {
            p.counter = if p.counter >= self.overflow { 1 } else { p.counter + 1 };
            p.counter
        });
        out(match counter {
            Some(c) => super::one_byte(crate::can::StdId::masked(self.cob_id), c),
            None => CanFrame::standard_len(crate::can::StdId::masked(self.cob_id), [0; 8], 0),
        });
        p.next = p.next.saturating_add(p.period).max(now);
        Some(counter)
    }

    /// When a producer sends its next SYNC.
    pub(super) fn next_deadline(&self) -> Option<Instant> {
        #[cfg(feature = "sync-producer")]
        if self.is_producer() {
            return Some(self.producer.next);
        }
        None
    }
}
