//! Every entry of a fresh generated dictionary reads back, and every writable one accepts the
//! value it starts with: a dictionary never starts with a value it would refuse by SDO (a
//! master that saves and restores the parameters must not get an abort), whatever mix of
//! fixed defaults, `$NODEID` defaults, missing defaults and limits its device file has.

use odc::{SdoAbort, slave::ObjectDictionary};
use odc_tests_generated::{lexium_mdrive, lxm23a, mini_drive, servoone};

/// `eds/lenze-e94aycca.eds`, slave side (generated for the benchmark): entries without default
/// whose limits exclude zero (0x27F1, 0x2BD9).
mod lenze_e94aycca {
    odc::include_od!("lenze_e94aycca");
}

fn read_back_all(name: &str, table: &[odc::slave::Row], dict: &mut impl ObjectDictionary) {
    let mut buf = [0u8; 1024];
    let mut written = 0;
    for e in table {
        let (i, s) = (e.addr().index, e.addr().sub);
        match dict.read(i, s, &mut buf) {
            Ok(n) => {
                if e.access().writable() {
                    let value = buf[..n].to_vec();
                    assert_eq!(dict.write(i, s, &value), Ok(()), "{name} {i:04X}:{s:02X}");
                    written += 1;
                }
            }
            Err(abort) => {
                assert_eq!(abort, SdoAbort::ReadOfWriteOnly, "{name} {i:04X}:{s:02X}");
                assert!(!e.access().readable());
            }
        }
    }
    assert!(written > 0, "{name}: no writable entry");
}

#[test]
fn initial_values_are_accepted_back() {
    for node in [odc::node_id!(1), odc::node_id!(5), odc::node_id!(127)] {
        read_back_all(
            "mini_drive",
            mini_drive::slave::TABLE.rows(),
            &mut mini_drive::slave::Dictionary::new(node),
        );
        read_back_all(
            "lxm23a",
            lxm23a::slave::TABLE.rows(),
            &mut lxm23a::slave::Dictionary::new(node),
        );
        read_back_all(
            "lexium_mdrive",
            lexium_mdrive::slave::TABLE.rows(),
            &mut lexium_mdrive::slave::Dictionary::new(node),
        );
        read_back_all(
            "servoone",
            servoone::slave::TABLE.rows(),
            &mut servoone::slave::Dictionary::new(node),
        );
        read_back_all(
            "lenze_e94aycca",
            lenze_e94aycca::slave::TABLE.rows(),
            &mut lenze_e94aycca::slave::Dictionary::new(node),
        );
    }
}

#[test]
fn rows_follow_the_descriptors() {
    let rows = lxm23a::slave::TABLE.rows();
    assert_eq!(rows.len(), lxm23a::slave::TABLE.len());
    assert!(rows.windows(2).all(|w| w[0].addr() < w[1].addr()));
    let row = rows.iter().find(|r| r.addr() == lxm23a::od::CONTROLWORD.addr).unwrap();
    assert_eq!(row.access(), lxm23a::od::CONTROLWORD.access);
    assert_eq!(row.data_type(), lxm23a::od::CONTROLWORD.data_type());
}
