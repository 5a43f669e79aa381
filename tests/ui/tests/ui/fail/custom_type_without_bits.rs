#[derive(Clone, Copy, odc::PdoValue)]
#[repr(i8)]
enum Mode {
    ProfilePosition = 1,
}

#[derive(odc::Pdo)]
struct NoWidth {
    #[pdo(index = 0x6060)]
    mode: Mode,
}

fn main() {}
