//! The no_std library's dictionary answers like the EDS says.

#[test]
fn reads_the_device_type() {
    let mut buf = [0u8; 4];
    assert_eq!(odc_tests_no_std::device_type(odc::node_id!(1), &mut buf), Ok(4));
    assert_eq!(u32::from_le_bytes(buf), 0x0402_0192); // the manual's object 1000h
    let mut small = [0u8; 2];
    assert!(odc_tests_no_std::device_type(odc::node_id!(1), &mut small).is_err());
}
