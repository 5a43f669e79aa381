//! A value error allowed at the gate (`F108` at level allow) is left out of generated code:
//! `fixtures/bad-values.eds` has `HighLimit=65536` on an UNSIGNED16 and
//! `DefaultValue=0xDEADBEEF` on an INTEGER16. The crate compiling is half the test; the
//! descriptors show what was kept.

use odc::DefaultValue;
use odc_tests_generated::bad_values::{od, slave};

#[test]
fn the_unfit_limit_and_default_are_left_out_and_the_rest_is_kept() {
    // 0x2001: the low limit and the default that read are kept, the high limit is not.
    assert_eq!(od::SPEED_LIMIT.low, Some(0u16));
    assert_eq!(od::SPEED_LIMIT.high, None);
    assert!(matches!(od::SPEED_LIMIT.default, Some(DefaultValue::Value(3000))));
    // 0x2002: no default; the dictionary starts it at zero.
    assert!(od::OFFSET.default.is_none());
    let mut dict = slave::Dictionary::new(odc::node_id!(3));
    let mut buf = [0u8; 4];
    let read = odc::slave::ObjectDictionary::read(&dict, 0x2002, 0, &mut buf);
    assert_eq!(read, Ok(2));
    assert_eq!(buf[..2], [0, 0]);
    // Without the high limit, a write of the largest UNSIGNED16 is accepted.
    assert_eq!(odc::slave::ObjectDictionary::write(&mut dict, 0x2001, 0, &[0xFF, 0xFF]), Ok(()));
}
