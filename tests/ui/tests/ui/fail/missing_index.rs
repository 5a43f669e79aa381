#[derive(odc::Pdo)]
struct Missing {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(sub = 1)]
    mode: i8,
}

// The fallback impl keeps this from adding "Pdo is not implemented" errors.
fn use_it() -> usize {
    <Missing as odc::Pdo>::LEN
}

fn main() {
    let _ = use_it();
}
