mod device {
    odc_macros::include_device!("../../../../tests/macros/tests/ui/bad_value.eds");
}

fn main() {}
