#[derive(odc::Pdo)]
struct Mismatch {
    #[pdo(index = 0x2000, bits = 9)]
    small: u8,
    #[pdo(index = 0x2001, bits = 16)]
    real: f32,
}

fn main() {}
