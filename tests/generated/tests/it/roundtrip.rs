//! pack → unpack is the identity for generated PDO structs.

use odc::Pdo;
use odc_tests_generated::{lxm23a, mini_drive};
use proptest::prelude::*;

proptest! {
    #[test]
    fn mini_drive_rpdo1(controlword: u16, target_position: i32) {
        let v = mini_drive::pdo::Rpdo1 { controlword: controlword.into(), target_position };
        let bytes = v.pack().map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(mini_drive::pdo::Rpdo1::unpack(bytes.as_ref()), Ok(v));
    }

    #[test]
    fn mini_drive_tpdo1(statusword: u16, mode: i8, position: i32) {
        let v = mini_drive::pdo::Tpdo1 { statusword: statusword.into(), modes_of_operation_display: mode, position_actual_value: position };
        let bytes = v.pack().map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(mini_drive::pdo::Tpdo1::unpack(bytes.as_ref()), Ok(v));
    }

    #[test]
    fn lxm23a_rpdo2(controlword: u16, target_position: i32) {
        let v = lxm23a::pdo::Rpdo2 { controlword: controlword.into(), target_position };
        let bytes = v.pack().map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(lxm23a::pdo::Rpdo2::unpack(bytes.as_ref()), Ok(v));
    }

    #[test]
    fn unpack_pack_keeps_mapped_bits(bytes: [u8; 7]) {
        // Every mapped bit of the 7-byte TPDO survives; there is no gap in it.
        let v = mini_drive::pdo::Tpdo1::unpack(&bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let again = v.pack().map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(again.as_ref(), &bytes[..]);
    }
}
