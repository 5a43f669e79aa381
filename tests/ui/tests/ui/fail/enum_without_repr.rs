#[derive(odc::PdoValue)]
enum Mode {
    ProfilePosition = 1,
    CyclicSyncPosition = 8,
}

fn main() {}
