#[derive(odc::Pdo)]
struct Overlap {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x6060, offset = 8)]
    mode: i8,
}

fn main() {}
