#[derive(odc::Pdo)]
#[pdo(byts = 8)]
struct Unknown {
    #[pdo(indx = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x6060, bitz = 8)]
    mode: i8,
}

fn main() {}
