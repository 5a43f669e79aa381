//! Bit-level little-endian access (LSB0), shared by derived and generated PDO code.
//!
//! Everything is `#[inline(always)]` and branch-light so that, with the constant offsets a
//! derive emits, the compiler folds each access to the shift-and-mask a human would write.
//! Out-of-range bits read as zero and writes past the end are dropped: these helpers never
//! panic, and callers check the buffer length once up front.

/// Mask of the low `bits` bits (`bits ≥ 64` gives all ones).
#[inline(always)]
pub const fn mask(bits: u32) -> u64 {
    if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 }
}

/// Sign-extend the low `bits` bits of `raw` to an `i64`.
#[inline(always)]
pub const fn sign_extend(raw: u64, bits: u32) -> i64 {
    if bits == 0 || bits >= 64 {
        return raw as i64;
    }
    let shift = 64 - bits;
    ((raw << shift) as i64) >> shift
}

/// Whether a raw value (zero-extended if unsigned, sign-extended if signed) survives a
/// round trip through `bits` bits.
#[inline(always)]
pub const fn fits(raw: u64, bits: u32, signed: bool) -> bool {
    if bits >= 64 {
        return true;
    }
    if signed { sign_extend(raw & mask(bits), bits) as u64 == raw } else { raw >> bits == 0 }
}

/// Copies the first `min(dst.len(), src.len())` bytes of `src` into `dst`.
///
/// What `copy_from_slice` does for slices of one length, without its length check: that
/// check's panic path is not inlined at `opt-level = "s"` and links `core::fmt` into a
/// firmware image (3 KB) even where the lengths are equal by construction.
#[inline(always)]
pub(crate) fn copy_bytes(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// The first up-to-8 bytes of `buf` as a little-endian word, zero-extended.
///
/// The path of images of at most 8 bytes with a field off byte boundaries: one load, then
/// constant shifts.
#[inline(always)]
pub fn load_le_u64(buf: &[u8]) -> u64 {
    let mut b = [0u8; 8];
    let n = buf.len().min(8);
    if let (Some(dst), Some(src)) = (b.get_mut(..n), buf.get(..n)) {
        copy_bytes(dst, src);
    }
    u64::from_le_bytes(b)
}

/// Store the low `buf.len().min(8)` bytes of `word`, little-endian.
#[inline(always)]
pub fn store_le_u64(buf: &mut [u8], word: u64) {
    let b = word.to_le_bytes();
    let n = buf.len().min(8);
    if let (Some(dst), Some(src)) = (buf.get_mut(..n), b.get(..n)) {
        copy_bytes(dst, src);
    }
}

/// The `n` (≤ 8) bytes at byte `at` as a little-endian word, zero-extended; zero when they are
/// not all in `buf`.
///
/// The path of PDOs whose fields all start and end on byte boundaries: one load per field,
/// of the field's own width.
#[inline(always)]
pub fn get_le(buf: &[u8], at: usize, n: usize) -> u64 {
    let mut b = [0u8; 8];
    if let (Some(dst), Some(src)) = (b.get_mut(..n), buf.get(at..at.saturating_add(n))) {
        copy_bytes(dst, src);
    }
    u64::from_le_bytes(b)
}

/// Store the low `n` (≤ 8) bytes of `value` at byte `at`, little-endian; nothing when they
/// are not all in `buf`. The store of [`get_le`]'s path.
#[inline(always)]
pub fn put_le(buf: &mut [u8], at: usize, n: usize, value: u64) {
    let b = value.to_le_bytes();
    if let (Some(dst), Some(src)) = (buf.get_mut(at..at.saturating_add(n)), b.get(..n)) {
        copy_bytes(dst, src);
    }
}

/// Read `len` bits (≤ 64) starting at bit `offset`.
#[inline(always)]
pub fn read_bits(buf: &[u8], offset: usize, len: u32) -> u64 {
    if len == 0 {
        return 0;
    }
    let first = offset / 8;
    let shift = (offset % 8) as u32;
    if shift + len <= 64
        && let Some(Ok(chunk)) = buf.get(first..first.saturating_add(8)).map(<[u8; 8]>::try_from)
    {
        return (u64::from_le_bytes(chunk) >> shift) & mask(len);
    }
    let nbytes = (shift + len).div_ceil(8) as usize;
    let mut acc: u128 = 0;
    let mut i = 0;
    while i < nbytes {
        let byte = buf.get(first.saturating_add(i)).copied().unwrap_or(0);
        acc |= u128::from(byte) << (8 * i);
        i += 1;
    }
    ((acc >> shift) as u64) & mask(len)
}

/// Write the low `len` bits (≤ 64) of `value` at bit `offset`, leaving other bits as they were.
#[inline(always)]
pub fn write_bits(buf: &mut [u8], offset: usize, len: u32, value: u64) {
    if len == 0 {
        return;
    }
    let first = offset / 8;
    let shift = (offset % 8) as u32;
    let m = mask(len);
    let v = value & m;
    if shift + len <= 64
        && let Some(chunk) = buf.get_mut(first..first.saturating_add(8))
    {
        let mut word = [0u8; 8];
        copy_bytes(&mut word, chunk);
        let w = (u64::from_le_bytes(word) & !(m << shift)) | (v << shift);
        copy_bytes(chunk, &w.to_le_bytes());
        return;
    }
    let m = u128::from(m) << shift;
    let v = u128::from(v) << shift;
    let nbytes = (shift + len).div_ceil(8) as usize;
    let mut i = 0;
    while i < nbytes {
        if let Some(b) = buf.get_mut(first.saturating_add(i)) {
            let bm = (m >> (8 * i)) as u8;
            *b = (*b & !bm) | ((v >> (8 * i)) as u8 & bm);
        }
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_write_cross_bytes() {
        let mut buf = [0u8; 10];
        write_bits(&mut buf, 3, 16, 0xABCD);
        assert_eq!(read_bits(&buf, 3, 16), 0xABCD);
        assert_eq!(buf[0], 0xCD << 3);
        // near the end: takes the slow path
        write_bits(&mut buf, 70, 10, 0x3FF);
        assert_eq!(read_bits(&buf, 70, 10), 0x3FF);
        assert_eq!(buf[8] & 0xC0, 0xC0);
        assert_eq!(buf[9], 0xFF);
        // full 64-bit at an odd offset spans 9 bytes
        let mut big = [0u8; 10];
        write_bits(&mut big, 5, 64, 0x0123_4567_89AB_CDEF);
        assert_eq!(read_bits(&big, 5, 64), 0x0123_4567_89AB_CDEF);
    }

    #[test]
    fn write_keeps_neighbours() {
        let mut buf = [0xFFu8; 3];
        write_bits(&mut buf, 4, 8, 0);
        assert_eq!(buf, [0x0F, 0xF0, 0xFF]);
    }

    #[test]
    fn out_of_range_is_quiet() {
        let mut buf = [0u8; 2];
        write_bits(&mut buf, 12, 8, 0xFF);
        assert_eq!(buf, [0, 0xF0]);
        assert_eq!(read_bits(&buf, 12, 8), 0x0F);
        assert_eq!(read_bits(&buf, 100, 8), 0);
    }

    #[test]
    fn words() {
        assert_eq!(load_le_u64(&[1, 2, 3]), 0x03_02_01);
        let mut b = [0u8; 3];
        store_le_u64(&mut b, 0x0405_0607);
        assert_eq!(b, [7, 6, 5]);
    }

    #[test]
    fn signs() {
        assert_eq!(sign_extend(0xFF, 8), -1);
        assert_eq!(sign_extend(0x7F, 8), 127);
        assert_eq!(sign_extend(0x80_0000, 24), -0x80_0000);
        assert!(fits((-5i64) as u64, 4, true));
        assert!(!fits((-9i64) as u64, 4, true));
        assert!(fits(15, 4, false));
        assert!(!fits(16, 4, false));
        assert!(fits(u64::MAX, 64, false));
    }
}
