//! ETG.2010's layout of a category's data, to say where a category the ESI gives does not
//! follow it (it is written as given all the same).

use crate::category;

/// What in `data`, the data of a category of type `kind`, does not follow ETG.2010's layout
/// for that type; `None` when it does or the type has no fixed layout.
pub(crate) fn odd(kind: u16, data: &[u8]) -> Option<String> {
    let records = |size: usize, what: &str| {
        (!data.len().is_multiple_of(size))
            .then(|| format!("{} bytes are not whole {size}-byte {what} records", data.len()))
    };
    match kind {
        category::STRINGS => strings(data),
        category::GENERAL => (data.len() < GENERAL_LEN).then(|| {
            format!("{} bytes, where ETG.2010's General category has {GENERAL_LEN}", data.len())
        }),
        category::SYNC_MANAGER => records(8, "sync manager"),
        category::DC => records(24, "DC op mode"),
        category::TX_PDO | category::RX_PDO => pdos(data),
        _ => None,
    }
}

/// The General category's length in bytes (ETG.2010).
const GENERAL_LEN: usize = 32;

/// A count byte, then each string as a length byte and its bytes.
fn strings(data: &[u8]) -> Option<String> {
    let count = usize::from(*data.first()?);
    let mut at = 1;
    for n in 1..=count {
        let len = usize::from(*data.get(at)?);
        if at + 1 + len > data.len() {
            return Some(format!("string {n} of {count} runs past the category's end"));
        }
        at += 1 + len;
    }
    None
}

/// 8-byte PDO headers (entry count in byte 2), each followed by its 8-byte entries.
fn pdos(data: &[u8]) -> Option<String> {
    let mut at = 0;
    while at < data.len() {
        let n = match data.get(at..at + 8) {
            Some(header) => usize::from(header[2]),
            None => return Some(format!("the PDO header at byte {at} runs past the category")),
        };
        if at + 8 + 8 * n > data.len() {
            return Some(format!("the {n} entries of the PDO at byte {at} run past the category"));
        }
        at += 8 + 8 * n;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts() {
        assert_eq!(odd(category::SYNC_MANAGER, &[0; 16]), None);
        assert!(odd(category::SYNC_MANAGER, &[0; 9]).unwrap_or_default().contains("9 bytes"));
        assert!(odd(category::GENERAL, b"BootCfg").is_some());
        assert_eq!(odd(category::GENERAL, &[0; 32]), None);
        assert_eq!(odd(category::STRINGS, &[2, 1, b'a', 2, b'b', b'c']), None);
        assert!(odd(category::STRINGS, &[2, 1, b'a', 3, b'b', b'c']).is_some());
        // One PDO with one entry: 16 bytes; a count of 2 runs past them.
        let mut pdo = [0u8; 16];
        pdo[2] = 1;
        assert_eq!(odd(category::TX_PDO, &pdo), None);
        pdo[2] = 2;
        assert!(odd(category::RX_PDO, &pdo).is_some());
        assert_eq!(odd(1, &[1, 2, 3]), None);
    }
}
