mod device {
    odc_macros::include_device!("eds/no-such-file.eds");
}

fn main() {}
