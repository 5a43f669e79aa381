//! Rust identifiers from the names a device file gives its objects.
//!
//! A name is split into words (at non-alphanumeric characters and at camel-case boundaries),
//! then joined in the case the item needs. Names that come out empty get a fallback built
//! from the index; Rust keywords get a trailing underscore; a leading digit gets a leading
//! underscore. Collisions are resolved by [`Namer`], deterministically.

use std::collections::{BTreeMap, BTreeSet};

pub use odc_analysis::names::{camel, screaming, snake, words};

/// Gives unique names to a set of items, in one namespace.
///
/// Every item proposes a base name, a disambiguating suffix (its index, its sub-index) and a
/// rank. When base names collide, the one item of highest rank keeps the plain name (a
/// standard object against a vendor object of the same name, see `standard::rank`); when
/// the highest rank is shared, all of them get their suffix, so a name never depends on
/// which item came first. If even that collides, a counter is appended.
pub struct Namer {
    proposals: Vec<(String, String, u8)>,
}

impl Namer {
    /// An empty namer.
    pub fn new() -> Self {
        Namer { proposals: Vec::new() }
    }

    /// Adds an item of rank 0; returns its position, for [`Namer::finish`].
    pub fn propose(&mut self, base: String, suffix: String) -> usize {
        self.propose_ranked(base, suffix, 0)
    }

    /// Adds an item; returns its position, for [`Namer::finish`].
    pub fn propose_ranked(&mut self, base: String, suffix: String, rank: u8) -> usize {
        self.proposals.push((base, suffix, rank));
        self.proposals.len() - 1
    }

    /// The unique names, in proposal order. `join` is put between base and suffix.
    pub fn finish(self, join: &str, reserved: &[&str]) -> Vec<String> {
        // Per base name: how many propose it, and the highest rank with its holder count.
        let mut groups: BTreeMap<&str, (usize, u8, usize)> = BTreeMap::new();
        for (base, _, rank) in &self.proposals {
            let g = groups.entry(base.as_str()).or_insert((0, *rank, 0));
            g.0 += 1;
            if *rank > g.1 {
                (g.1, g.2) = (*rank, 0);
            }
            if *rank == g.1 {
                g.2 += 1;
            }
        }
        let reserved: BTreeSet<String> = reserved.iter().map(|s| s.to_string()).collect();
        let plain: Vec<bool> = self
            .proposals
            .iter()
            .map(|(base, _, rank)| {
                let g = groups.get(base.as_str()).copied().unwrap_or((0, 0, 0));
                !base.is_empty()
                    && !reserved.contains(base)
                    && (g.0 == 1 || (*rank == g.1 && g.2 == 1))
            })
            .collect();
        // The plain names first, so that a suffixed name cannot take one.
        let mut taken = reserved;
        taken.extend(
            self.proposals.iter().zip(&plain).filter(|(_, p)| **p).map(|((b, ..), _)| b.clone()),
        );
        let mut out = Vec::with_capacity(self.proposals.len());
        for ((base, suffix, _), plain) in self.proposals.iter().zip(plain) {
            if plain {
                out.push(base.clone());
                continue;
            }
            let mut name =
                if base.is_empty() { suffix.clone() } else { format!("{base}{join}{suffix}") };
            let stem = name.clone();
            let mut n = 2;
            while taken.contains(&name) {
                name = format!("{stem}{join}{n}");
                n += 1;
            }
            taken.insert(name.clone());
            out.push(name);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases() {
        assert_eq!(screaming("Controlword"), "CONTROLWORD");
        assert_eq!(screaming("COB-ID used by PDO"), "COB_ID_USED_BY_PDO");
        assert_eq!(screaming("ModesOfOperation"), "MODES_OF_OPERATION");
        assert_eq!(screaming("PDOMapping 1"), "PDO_MAPPING_1");
        assert_eq!(snake("Vendor ID"), "vendor_id");
        assert_eq!(snake("Type"), "type_");
        assert_eq!(snake("1st value"), "_1st_value");
        assert_eq!(camel("Receive PDO mapping"), "ReceivePdoMapping");
        assert_eq!(camel("self"), "Self_");
        assert_eq!(screaming("µ€"), "");
        assert_eq!(snake("Max. speed (rpm)"), "max_speed_rpm");
    }

    #[test]
    fn collisions_are_order_independent() {
        let mut n = Namer::new();
        n.propose("A".into(), "1400".into());
        n.propose("B".into(), "1401".into());
        n.propose("A".into(), "1402".into());
        n.propose(String::new(), "OBJ_2000".into());
        assert_eq!(n.finish("_", &[]), ["A_1400", "B", "A_1402", "OBJ_2000"]);
        // The item named `X_1` keeps its name, before or after the `X`s that would take it.
        let mut n = Namer::new();
        n.propose("X".into(), "1".into());
        n.propose("X_1".into(), "2".into());
        n.propose("X".into(), "1".into());
        assert_eq!(n.finish("_", &["TABLE"]), ["X_1_2", "X_1", "X_1_3"]);
        let mut n = Namer::new();
        n.propose("X_1".into(), "2".into());
        n.propose("X".into(), "1".into());
        n.propose("X".into(), "1".into());
        assert_eq!(n.finish("_", &["TABLE"]), ["X_1", "X_1_2", "X_1_3"]);
    }

    #[test]
    fn the_higher_rank_keeps_the_plain_name() {
        // A vendor object (rank 0) first, the standard one (rank 2) after: the standard one
        // keeps the name, whatever the order.
        for flip in [false, true] {
            let mut n = Namer::new();
            let mut items = [("2064", 0u8), ("6064", 2)];
            if flip {
                items.reverse();
            }
            let pos: Vec<_> = items
                .iter()
                .map(|(i, r)| {
                    n.propose_ranked("POSITION_ACTUAL_VALUE".into(), format!("OBJ_{i}"), *r)
                })
                .collect();
            let names = n.finish("_", &[]);
            let of = |index: &str| {
                let k = items.iter().position(|(i, _)| *i == index).unwrap();
                names[pos[k]].clone()
            };
            assert_eq!(of("6064"), "POSITION_ACTUAL_VALUE");
            assert_eq!(of("2064"), "POSITION_ACTUAL_VALUE_OBJ_2064");
        }
        // A shared highest rank: every one of them gets its suffix.
        let mut n = Namer::new();
        n.propose_ranked("A".into(), "1".into(), 1);
        n.propose_ranked("A".into(), "2".into(), 1);
        n.propose_ranked("A".into(), "3".into(), 0);
        assert_eq!(n.finish("_", &[]), ["A_1", "A_2", "A_3"]);
        // A reserved name stays reserved for every rank.
        let mut n = Namer::new();
        n.propose_ranked("TABLE".into(), "1".into(), 2);
        assert_eq!(n.finish("_", &["TABLE"]), ["TABLE_1"]);
    }

    #[test]
    fn trade_names_and_plural_acronyms_are_one_word() {
        // eds/lxm23a.eds 0x2301.
        assert_eq!(screaming("CANopen baud rate P3-01"), "CANOPEN_BAUD_RATE_P3_01");
        assert_eq!(screaming("CANopen address P3-05"), "CANOPEN_ADDRESS_P3_05");
        assert_eq!(snake("CANOpen Node ID"), "canopen_node_id");
        assert_eq!(snake("CANopenNodeId"), "canopen_node_id");
        assert_eq!(snake("EtherCAT State Machine"), "ethercat_state_machine");
        assert_eq!(snake("EtherCATStatus"), "ethercat_status");
        assert_eq!(snake("DCOM control"), "dcom_control");
        assert_eq!(snake("DCOMcontrol"), "dcom_control");
        assert_eq!(snake("DCOMopmode"), "dcom_opmode");
        assert_eq!(snake("EtherCATslave"), "ethercat_slave");
        assert_eq!(snake("FSoE Address"), "fsoe_address");
        // Corpus names: `Number of PDOs`, `Number of LEDs`.
        assert_eq!(snake("Number of PDOs"), "number_of_pdos");
        assert_eq!(snake("LEDs"), "leds");
        assert_eq!(snake("PDOsMapped"), "pdos_mapped");
        // The camel-case rule is unchanged where no term applies.
        assert_eq!(snake("PDOToggle"), "pdo_toggle");
        assert_eq!(snake("PDOMapping"), "pdo_mapping");
        assert_eq!(snake("NMTStartup"), "nmt_startup");
        assert_eq!(snake("RTDInputs"), "rtd_inputs");
        assert_eq!(snake("Scan openings"), "scan_openings");
        // Only at the start of a word: not inside `Widcom`, nor `canopen` in `canopener`.
        assert_eq!(snake("Widcom"), "widcom");
        assert_eq!(snake("canopener"), "canopener");
        assert_eq!(snake("xCANopen"), "x_canopen");
    }
}
