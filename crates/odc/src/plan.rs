//! Configuration plans: SDO writes as plain data, for any SDO client to execute in order.
//!
//! Generated `master` modules build them (the CiA 301 PDO mapping procedure, [`PdoConfig`],
//! the one implementation of it; the EtherCAT 0x1C12/0x1C13 assignment, [`PlanBuilder`]);
//! [`sdo::Client::execute`](crate::sdo::Client::execute) runs one over a bus. A plan is data, so any client can run it, or a test can apply it to a dictionary:
//!
//! ```
//! use odc::plan::SdoWrite;
//!
//! // RPDO1 maps the controlword (CiA 301 §7.5.2.36: disable, clear, map, count, enable).
//! let plan = [
//!     SdoWrite::u32(0x1400, 1, 0x8000_0205), // COB-ID, bit 31: PDO invalid
//!     SdoWrite::u8(0x1600, 0, 0),            // no entries while mapping
//!     SdoWrite::u32(0x1600, 1, 0x6040_0010), // 0x6040:00, 16 bits
//!     SdoWrite::u8(0x1600, 0, 1),            // one entry
//!     SdoWrite::u32(0x1400, 1, 0x0000_0205), // valid again
//! ];
//! let mut frames = Vec::new();
//! for w in &plan {
//!     let (bytes, n) = w.to_le_bytes(); // the data of one expedited download
//!     frames.push((w.index, w.sub, bytes[..n].to_vec()));
//! }
//! assert_eq!(frames[2], (0x1600, 1, vec![0x10, 0x00, 0x40, 0x60]));
//! assert_eq!(frames[3], (0x1600, 0, vec![1]));
//! ```

/// One expedited SDO download: `size` bytes (1, 2 or 4) of `value`, little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SdoWrite {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The value, zero-extended.
    pub value: u32,
    /// Size in bytes: 1, 2 or 4.
    pub size: u8,
}

impl SdoWrite {
    /// An UNSIGNED8 write.
    pub const fn u8(index: u16, sub: u8, value: u8) -> Self {
        Self { index, sub, value: value as u32, size: 1 }
    }

    /// An UNSIGNED16 write.
    pub const fn u16(index: u16, sub: u8, value: u16) -> Self {
        Self { index, sub, value: value as u32, size: 2 }
    }

    /// An UNSIGNED32 write.
    pub const fn u32(index: u16, sub: u8, value: u32) -> Self {
        Self { index, sub, value, size: 4 }
    }

    /// The little-endian bytes of the value and how many of them to send.
    pub const fn to_le_bytes(self) -> ([u8; 4], usize) {
        (self.value.to_le_bytes(), self.size as usize)
    }
}

/// A PDO as the CiA 301 mapping procedure (7.5.2.35–36) configures it: its mapping object
/// and entries, and its communication parameters when it has them.
///
/// This is the one implementation of the procedure: generated `master` modules describe each
/// PDO of the default mapping as a `PdoConfig` and call [`PdoConfig::writes`] and [`plan`];
/// `master::mapping_plan` (feature `std`) builds one from a [`Pdo`](crate::Pdo) struct.
/// The writes, in order:
/// 1. the COB-ID with bit 31 set (PDO invalid), when [`PdoConfig::sets_cob_id`];
/// 2. the mapping count 0, when there are entries to write;
/// 3. each mapping entry (sub-index 1..);
/// 4. the mapping count;
/// 5. the transmission type, inhibit time, event timer and SYNC start value that are given;
/// 6. the COB-ID with bit 31 clear (valid again), when [`PdoConfig::sets_cob_id`].
///
/// ```
/// use odc::plan::{PdoConfig, SdoWrite};
///
/// const RPDO1: PdoConfig<'static> =
///     PdoConfig::new(0x1600, &[0x6040_0010]).with_comm(0x1400, true).with_transmission_type(255);
/// let writes: [SdoWrite; RPDO1.len()] = RPDO1.writes(0x205);
/// assert_eq!(writes[0], SdoWrite::u32(0x1400, 1, 0x8000_0205));
/// assert_eq!(writes[2], SdoWrite::u32(0x1600, 1, 0x6040_0010));
/// assert_eq!(writes[5], SdoWrite::u32(0x1400, 1, 0x205));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PdoConfig<'a> {
    /// The mapping object (0x1600.., 0x1A00..).
    pub mapping_index: u16,
    /// The mapping entries (`index << 16 | sub << 8 | bits`), in wire order.
    pub mapping: &'a [u32],
    /// The communication parameter object (0x1400.., 0x1800..), if the PDO has one.
    pub comm_index: Option<u16>,
    /// Whether the procedure invalidates the COB-ID first and validates it last (the PDO has
    /// a communication object and a COB-ID).
    pub sets_cob_id: bool,
    /// Transmission type (communication sub-index 2).
    pub transmission_type: Option<u8>,
    /// Inhibit time in 100 µs (sub-index 3; transmit PDOs).
    pub inhibit_time: Option<u16>,
    /// Event timer in ms (sub-index 5).
    pub event_timer: Option<u16>,
    /// SYNC start value (sub-index 6; transmit PDOs).
    pub sync_start: Option<u8>,
}

/// The COB-ID's bit 31: the PDO does not exist (is invalid).
const COB_INVALID: u32 = 0x8000_0000;

impl<'a> PdoConfig<'a> {
    /// A PDO's mapping without communication parameters.
    pub const fn new(mapping_index: u16, mapping: &'a [u32]) -> Self {
        PdoConfig {
            mapping_index,
            mapping,
            comm_index: None,
            sets_cob_id: false,
            transmission_type: None,
            inhibit_time: None,
            event_timer: None,
            sync_start: None,
        }
    }

    /// With its communication object; `sets_cob_id` as the field.
    pub const fn with_comm(mut self, comm_index: u16, sets_cob_id: bool) -> Self {
        self.comm_index = Some(comm_index);
        self.sets_cob_id = sets_cob_id;
        self
    }

    /// With a transmission type to write.
    pub const fn with_transmission_type(mut self, t: u8) -> Self {
        self.transmission_type = Some(t);
        self
    }

    /// With an inhibit time to write (100 µs units).
    pub const fn with_inhibit_time(mut self, t: u16) -> Self {
        self.inhibit_time = Some(t);
        self
    }

    /// With an event timer to write (ms).
    pub const fn with_event_timer(mut self, t: u16) -> Self {
        self.event_timer = Some(t);
        self
    }

    /// With a SYNC start value to write.
    pub const fn with_sync_start(mut self, s: u8) -> Self {
        self.sync_start = Some(s);
        self
    }

    /// How many writes [`PdoConfig::writes`] gives.
    pub const fn len(&self) -> usize {
        self.write_into(0, &mut [], 0)
    }

    /// Whether the procedure writes nothing (never: the mapping count is always written).
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The writes of the procedure, with `cob_id` the PDO's COB-ID (bit 31 is set and
    /// cleared by the procedure; ignored unless [`PdoConfig::sets_cob_id`]). `N` is
    /// [`PdoConfig::len`]: a longer array ends in unused `0x0000:00` writes, a shorter one
    /// holds the first `N`.
    pub const fn writes<const N: usize>(&self, cob_id: u32) -> [SdoWrite; N] {
        let mut out = [SdoWrite::u8(0, 0, 0); N];
        self.write_into(cob_id, &mut out, 0);
        out
    }

    /// The writes of the procedure as a vector, for a PDO configured at run time.
    #[cfg(feature = "std")]
    pub fn to_vec(&self, cob_id: u32) -> std::vec::Vec<SdoWrite> {
        let mut out = std::vec![SdoWrite::u8(0, 0, 0); self.len()];
        self.write_into(cob_id, &mut out, 0);
        out
    }

    /// Writes the procedure into `out` from position `at` (what does not fit is left out) and
    /// returns the position after it.
    const fn write_into(&self, cob_id: u32, out: &mut [SdoWrite], at: usize) -> usize {
        let mut at = at;
        let (comm, cob) = match self.comm_index {
            Some(c) => (c, self.sets_cob_id),
            None => (0, false),
        };
        if cob {
            at = put(out, at, SdoWrite::u32(comm, 1, cob_id | COB_INVALID));
        }
        let map = self.mapping_index;
        if !self.mapping.is_empty() {
            at = put(out, at, SdoWrite::u8(map, 0, 0));
        }
        let mut i = 0;
        while i < self.mapping.len() && i < u8::MAX as usize {
            at = put(out, at, SdoWrite::u32(map, i as u8 + 1, self.mapping[i]));
            i += 1;
        }
        at = put(out, at, SdoWrite::u8(map, 0, i as u8));
        if self.comm_index.is_some() {
            if let Some(t) = self.transmission_type {
                at = put(out, at, SdoWrite::u8(comm, 2, t));
            }
            if let Some(t) = self.inhibit_time {
                at = put(out, at, SdoWrite::u16(comm, 3, t));
            }
            if let Some(t) = self.event_timer {
                at = put(out, at, SdoWrite::u16(comm, 5, t));
            }
            if let Some(s) = self.sync_start {
                at = put(out, at, SdoWrite::u8(comm, 6, s));
            }
        }
        if cob {
            at = put(out, at, SdoWrite::u32(comm, 1, cob_id & !COB_INVALID));
        }
        at
    }
}

/// A plan built in a `const` context, for plans that interleave the PDO procedure with other
/// writes (the EtherCAT sync-manager assignment): writes are appended in order into `N`
/// slots, and [`PlanBuilder::len`] counts every write appended, so building it once with
/// `N = 0` gives the `N` to build it with:
///
/// ```
/// use odc::plan::{PdoConfig, PlanBuilder, SdoWrite};
///
/// const fn build<const N: usize>() -> PlanBuilder<N> {
///     PlanBuilder::new()
///         .push(SdoWrite::u8(0x1C12, 0, 0))
///         .pdo(&PdoConfig::new(0x1600, &[0x7000_0110]), 0)
///         .assign(0x1C12, &[0x1600])
/// }
/// const PLAN: [SdoWrite; build::<0>().len()] = build().finish();
/// assert_eq!(PLAN.len(), 6);
/// assert_eq!(PLAN[2], SdoWrite::u32(0x1600, 1, 0x7000_0110));
/// assert_eq!(PLAN[4..], [SdoWrite::u16(0x1C12, 1, 0x1600), SdoWrite::u8(0x1C12, 0, 1)]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PlanBuilder<const N: usize> {
    writes: [SdoWrite; N],
    len: usize,
}

impl<const N: usize> Default for PlanBuilder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> PlanBuilder<N> {
    /// No writes yet.
    pub const fn new() -> Self {
        PlanBuilder { writes: [SdoWrite::u8(0, 0, 0); N], len: 0 }
    }

    /// With one more write.
    pub const fn push(mut self, w: SdoWrite) -> Self {
        self.len = put(&mut self.writes, self.len, w);
        self
    }

    /// With the CiA 301 procedure of `pdo` ([`PdoConfig::writes`]) appended.
    pub const fn pdo(mut self, pdo: &PdoConfig<'_>, cob_id: u32) -> Self {
        self.len = pdo.write_into(cob_id, &mut self.writes, self.len);
        self
    }

    /// With an EtherCAT sync manager's PDO assignment (ETG.1000.6 0x1C10 + n): `pdos` (the
    /// mapping indexes) in sub-indexes 1.., then the count in sub-index 0. Clear the count
    /// first (`push(SdoWrite::u8(object, 0, 0))`) and write the mappings in between, as
    /// ETG.1000.6 orders a change of the assignment.
    pub const fn assign(mut self, object: u16, pdos: &[u16]) -> Self {
        let mut i = 0;
        while i < pdos.len() && i < u8::MAX as usize {
            self.len = put(&mut self.writes, self.len, SdoWrite::u16(object, i as u8 + 1, pdos[i]));
            i += 1;
        }
        self.len = put(&mut self.writes, self.len, SdoWrite::u8(object, 0, i as u8));
        self
    }

    /// How many writes were appended (those beyond `N` included).
    pub const fn len(&self) -> usize {
        self.len
    }

    /// Whether none was.
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The writes: the first `N` appended (unused slots are `0x0000:00` writes).
    pub const fn finish(self) -> [SdoWrite; N] {
        self.writes
    }
}

/// `w` at `out[at]` when it fits; the position after it either way.
const fn put(out: &mut [SdoWrite], at: usize, w: SdoWrite) -> usize {
    if at < out.len() {
        out[at] = w;
    }
    at + 1
}

/// How many writes [`plan`] gives for `pdos`.
pub const fn plan_len(pdos: &[PdoConfig<'_>]) -> usize {
    plan_builder::<0>(pdos, &[]).len()
}

/// The procedure of each PDO of `pdos` in turn, with `cob_ids[i]` the COB-ID of `pdos[i]`
/// (0 when missing); `N` is [`plan_len`], as for [`PdoConfig::writes`].
pub const fn plan<const N: usize>(pdos: &[PdoConfig<'_>], cob_ids: &[u32]) -> [SdoWrite; N] {
    plan_builder(pdos, cob_ids).finish()
}

/// [`plan`] as a [`PlanBuilder`] (its `len` counts the writes whatever `N`).
const fn plan_builder<const N: usize>(pdos: &[PdoConfig<'_>], cob_ids: &[u32]) -> PlanBuilder<N> {
    let (mut b, mut i) = (PlanBuilder::new(), 0);
    while i < pdos.len() {
        let cob = if i < cob_ids.len() { cob_ids[i] } else { 0 };
        b = b.pdo(&pdos[i], cob);
        i += 1;
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_procedure_in_order() {
        // A TPDO with every communication parameter: CiA 301 7.5.2.35-36.
        const T: PdoConfig<'static> = PdoConfig::new(0x1A00, &[0x6041_0010, 0x6064_0020])
            .with_comm(0x1800, true)
            .with_transmission_type(1)
            .with_inhibit_time(100)
            .with_event_timer(0)
            .with_sync_start(2);
        let w: [SdoWrite; T.len()] = T.writes(0x181);
        assert_eq!(
            w,
            [
                SdoWrite::u32(0x1800, 1, 0x8000_0181),
                SdoWrite::u8(0x1A00, 0, 0),
                SdoWrite::u32(0x1A00, 1, 0x6041_0010),
                SdoWrite::u32(0x1A00, 2, 0x6064_0020),
                SdoWrite::u8(0x1A00, 0, 2),
                SdoWrite::u8(0x1800, 2, 1),
                SdoWrite::u16(0x1800, 3, 100),
                SdoWrite::u16(0x1800, 5, 0),
                SdoWrite::u8(0x1800, 6, 2),
                SdoWrite::u32(0x1800, 1, 0x181),
            ]
        );
        // No communication object, no entries: the count alone.
        let m = PdoConfig::new(0x1601, &[]);
        assert_eq!(m.writes::<1>(0), [SdoWrite::u8(0x1601, 0, 0)]);
        // A plan is the PDOs' procedures in turn; an array too short keeps the first writes.
        const P: [PdoConfig<'static>; 2] = [T, PdoConfig::new(0x1601, &[])];
        let p: [SdoWrite; plan_len(&P)] = plan(&P, &[0x181]);
        assert_eq!(p.len(), 11);
        assert_eq!(p[10], SdoWrite::u8(0x1601, 0, 0));
        assert_eq!(T.writes::<2>(0x181), [w[0], w[1]]);
    }
}
