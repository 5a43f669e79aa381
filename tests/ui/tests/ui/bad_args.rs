mod a {
    odc_macros::include_device!("fixtures/lxm23a.eds", role = "controller");
}

mod b {
    odc_macros::include_device!("fixtures/lxm23a.eds", node = 3);
}

mod c {
    odc_macros::include_device!("fixtures/servoone.xml", device = 7);
}

fn main() {}
