#[derive(odc::Pdo)]
#[pdo(bytes = 2)]
struct Declared {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x6060)]
    mode: i8,
}

fn main() {}
