//! The expansion must not depend on the prelude or on names in scope.
#![no_implicit_prelude]

#[derive(::odc::PdoValue)]
#[repr(u8)]
enum Flag {
    Off = 0,
    On = 1,
    #[pdo(other)]
    Other(u8),
}

#[derive(::odc::Pdo)]
#[pdo(bytes = 4)]
struct Rx {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x2000, bits = 8)]
    flag: Flag,
}

#[derive(::odc::Pdo)]
#[pdo(max_bits = 128, crate = "::odc")]
struct Wide {
    #[pdo(index = 0x2001)]
    a: u64,
    #[pdo(index = 0x2002, bits = 12, pad_bits = 3)]
    b: u16,
}

fn main() {
    let _ = <Rx as ::odc::Pdo>::LEN;
    let _ = <Wide as ::odc::Pdo>::LEN;
    let _ = (Flag::Off, Flag::On, Flag::Other(2));
}
