mod device {
    odc_macros::include_device!("fixtures/bad_value.eds");
}

fn main() {}
