#[derive(odc::Pdo)]
struct TooBig {
    #[pdo(index = 0x607A)]
    target_position: i32,
    #[pdo(index = 0x60FF)]
    target_velocity: i32,
    #[pdo(index = 0x6040)]
    controlword: u16,
}

fn main() {}
