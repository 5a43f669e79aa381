//! CoE SDO server (ETG.1000.6 §5.6.2) over the dictionary: expedited, normal and segmented
//! upload and download, complete access where the ESI allows it, and aborts with the
//! dictionary's codes.
//!
//! The CoE header is 2 bytes: number (bits 0–8) and service (bits 12–15: 2 SDO request, 3
//! SDO response). The SDO header follows CiA 301's command byte (command specifier in bits
//! 5–7, bit 4 complete access for the initiate commands, toggle for segments), index,
//! sub-index and 4 bytes of data or size. Unlike CAN, a normal transfer carries as much data
//! as the mailbox holds, and segments are as long as the mailbox allows.

use super::pdo;
use crate::SdoAbort;
use crate::slave::Storage;

/// The CoE header of an SDO response (number 0, service 3).
const SDO_RESPONSE: [u8; 2] = [0x00, 0x30];
/// The CoE header of an abort from the device: service 2, SDO request (ETG.1000.6, Abort SDO
/// Transfer Request; SOES sends it so, and SOEM takes an abort under service 3 for a malformed
/// response).
const SDO_ABORT: [u8; 2] = [0x00, 0x20];

/// A transfer under way; its data is in the server's buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Transfer {
    #[default]
    None,
    Upload {
        index: u16,
        sub: u8,
        len: usize,
        at: usize,
        toggle: bool,
    },
    Download {
        index: u16,
        sub: u8,
        ca: bool,
        size: usize,
        got: usize,
        toggle: bool,
    },
}

/// A reply being written into a mailbox's data area.
pub(super) struct Out<'a> {
    pub(super) buf: &'a mut [u8],
    pub(super) len: usize,
}

impl Out<'_> {
    #[inline(never)]
    pub(super) fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if let Some(d) = self.buf.get_mut(self.len) {
                *d = b;
                self.len += 1;
            }
        }
    }
    fn pad_to(&mut self, len: usize) {
        while self.len < len && self.len < self.buf.len() {
            self.push(&[0]);
        }
    }
    fn room(&self) -> usize {
        self.buf.len().saturating_sub(self.len)
    }
}

/// The SDO server's state and value buffer.
pub(super) struct Server<'a> {
    pub(super) transfer: &'a mut Transfer,
    pub(super) buf: &'a mut [u8],
    pub(super) complete_access: bool,
    /// Whether PDO mapping and assignment objects may be written (PRE-OP only,
    /// ETG.1000.6 §5.6.7.4).
    pub(super) pdo_writable: bool,
}

impl Server<'_> {
    /// Answers the SDO request `sdo` (after the CoE header) into `out`; nothing for an abort
    /// from the master.
    pub(super) fn handle<D: Storage + ?Sized>(
        &mut self,
        sdo: &[u8],
        od: &mut D,
        out: &mut Out<'_>,
    ) {
        let command = sdo.first().copied().unwrap_or(0);
        let addr = match sdo.get(1..4) {
            Some(&[lo, hi, sub]) => Some((u16::from_le_bytes([lo, hi]), sub)),
            _ => None,
        };
        // The address an abort names: the request's, a segment's transfer's, else 0:0. The
        // steps answer only the abort code.
        let at = match (command >> 5, *self.transfer) {
            (0, Transfer::Download { index, sub, .. })
            | (3, Transfer::Upload { index, sub, .. }) => Some((index, sub)),
            (0 | 3, _) => None,
            _ => addr,
        };
        let reply = match (command >> 5, addr) {
            (1, Some((index, sub))) => self.download(command, index, sub, sdo, od, out),
            (0, _) => self.download_segment(command, sdo, od, out),
            (2, Some((index, sub))) => self.upload(command, index, sub, od, out),
            (3, _) => self.upload_segment(command, out),
            // Abort from the master: the transfer ends, no reply.
            (4, _) => {
                *self.transfer = Transfer::None;
                return;
            }
            _ => Err(SdoAbort::InvalidCommand),
        };
        if let Err(abort) = reply {
            let (index, sub) = at.unwrap_or((0, 0));
            *self.transfer = Transfer::None;
            out.len = 0;
            let [i0, i1] = index.to_le_bytes();
            let [a0, a1, a2, a3] = abort.to_u32().to_le_bytes();
            // One push of the whole frame: fewer call sites than one per field.
            out.push(&[SDO_ABORT[0], SDO_ABORT[1], 0x80, i0, i1, sub, a0, a1, a2, a3]);
        }
    }

    fn check_ca(&self, command: u8, sub: u8) -> Result<bool, SdoAbort> {
        let ca = command & 0x10 != 0;
        if ca && (!self.complete_access || sub > 1) {
            return Err(SdoAbort::UnsupportedAccess);
        }
        Ok(ca)
    }

    fn upload<D: Storage + ?Sized>(
        &mut self,
        command: u8,
        index: u16,
        sub: u8,
        od: &D,
        out: &mut Out<'_>,
    ) -> Result<(), SdoAbort> {
        let ca = self.check_ca(command, sub)?;
        let len = match ca {
            true => read_complete(od, index, sub, self.buf)?,
            false => od.read(index, sub, self.buf)?,
        };
        let data = self.buf.get(..len).unwrap_or(&[]);
        let ca_bit = if ca { 0x10 } else { 0 };
        let [i0, i1] = index.to_le_bytes();
        let [r0, r1] = SDO_RESPONSE;
        if len <= 4 && len > 0 {
            // Expedited: e = 1, s = 1, n = bytes of the 4 without data.
            let n = (4 - len) as u8;
            out.push(&[r0, r1, 0x43 | n << 2 | ca_bit, i0, i1, sub]);
            out.push(data);
            out.pad_to(2 + 8);
            *self.transfer = Transfer::None;
            return Ok(());
        }
        // Normal: the size, then as much data as the mailbox holds.
        let [l0, l1, l2, l3] = u32::try_from(len).unwrap_or(u32::MAX).to_le_bytes();
        out.push(&[r0, r1, 0x41 | ca_bit, i0, i1, sub, l0, l1, l2, l3]);
        let first = len.min(out.room());
        out.push(data.get(..first).unwrap_or(&[]));
        *self.transfer = match first < len {
            true => Transfer::Upload { index, sub, len, at: first, toggle: false },
            false => Transfer::None,
        };
        Ok(())
    }

    fn upload_segment(&mut self, command: u8, out: &mut Out<'_>) -> Result<(), SdoAbort> {
        let Transfer::Upload { len, at, toggle, .. } = &mut *self.transfer else {
            return Err(SdoAbort::InvalidCommand);
        };
        let t = command & 0x10 != 0;
        if t != *toggle {
            return Err(SdoAbort::ToggleBit);
        }
        let rest = self.buf.get(*at..*len).unwrap_or(&[]);
        let n = rest.len().min(out.room().saturating_sub(3));
        let last = n == rest.len();
        // A segment shorter than 7 bytes is padded to 7 and says how many are unused.
        let unused = 7usize.saturating_sub(n) as u8;
        let [r0, r1] = SDO_RESPONSE;
        out.push(&[r0, r1, u8::from(t) << 4 | unused << 1 | u8::from(last)]);
        out.push(rest.get(..n).unwrap_or(&[]));
        out.pad_to(3 + 7);
        *at += n;
        *toggle = !*toggle;
        if last {
            *self.transfer = Transfer::None;
        }
        Ok(())
    }

    fn download<D: Storage + ?Sized>(
        &mut self,
        command: u8,
        index: u16,
        sub: u8,
        sdo: &[u8],
        od: &mut D,
        out: &mut Out<'_>,
    ) -> Result<(), SdoAbort> {
        let ca = self.check_ca(command, sub)?;
        let payload = sdo.get(4..).unwrap_or(&[]);
        // The whole value when the request holds it: one write for both kinds.
        let data = if command & 0x02 != 0 {
            // Expedited: the size indicator says how many of the 4 bytes are data.
            let n = if command & 0x01 != 0 { 4 - usize::from(command >> 2 & 0x03) } else { 4 };
            payload.get(..n).ok_or(SdoAbort::TooShort)?
        } else {
            let size = match payload.get(..4) {
                Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]) as usize,
                _ => return Err(SdoAbort::TooShort),
            };
            if size > self.buf.len() {
                return Err(SdoAbort::OutOfMemory);
            }
            let data = payload.get(4..).unwrap_or(&[]);
            if data.len() < size {
                // Segments follow.
                let got = data.len();
                if let Some(dst) = self.buf.get_mut(..got) {
                    dst.copy_from_slice(data);
                }
                *self.transfer = Transfer::Download { index, sub, ca, size, got, toggle: false };
                download_response(out, index, sub);
                return Ok(());
            }
            *self.transfer = Transfer::None;
            data.get(..size).unwrap_or(&[])
        };
        self.write(od, index, sub, ca, data)?;
        download_response(out, index, sub);
        Ok(())
    }

    fn download_segment<D: Storage + ?Sized>(
        &mut self,
        command: u8,
        sdo: &[u8],
        od: &mut D,
        out: &mut Out<'_>,
    ) -> Result<(), SdoAbort> {
        let Transfer::Download { index, sub, ca, size, got, toggle } = *self.transfer else {
            return Err(SdoAbort::InvalidCommand);
        };
        let t = command & 0x10 != 0;
        if t != toggle {
            return Err(SdoAbort::ToggleBit);
        }
        let mut seg = sdo.get(1..).unwrap_or(&[]);
        if seg.len() == 7 {
            let unused = usize::from(command >> 1 & 0x07);
            seg = seg.get(..7 - unused).unwrap_or(&[]);
        }
        let now = got + seg.len();
        if now > size {
            return Err(SdoAbort::TooLong);
        }
        if let Some(dst) = self.buf.get_mut(got..now) {
            dst.copy_from_slice(seg);
        }
        *self.transfer = Transfer::Download { index, sub, ca, size, got: now, toggle: !toggle };
        if command & 0x01 != 0 {
            *self.transfer = Transfer::None;
            if now != size {
                return Err(SdoAbort::TooShort);
            }
            self.write_buffered(od, index, sub, ca, size)?;
        }
        let [r0, r1] = SDO_RESPONSE;
        out.push(&[r0, r1, 0x20 | u8::from(t) << 4]);
        out.pad_to(2 + 8);
        Ok(())
    }

    /// Writes the first `size` bytes of the buffer.
    fn write_buffered<D: Storage + ?Sized>(
        &mut self,
        od: &mut D,
        index: u16,
        sub: u8,
        ca: bool,
        size: usize,
    ) -> Result<(), SdoAbort> {
        let data = self.buf.get(..size).ok_or(SdoAbort::OutOfMemory)?;
        write(od, index, sub, ca, data, self.pdo_writable)
    }

    fn write<D: Storage + ?Sized>(
        &mut self,
        od: &mut D,
        index: u16,
        sub: u8,
        ca: bool,
        data: &[u8],
    ) -> Result<(), SdoAbort> {
        write(od, index, sub, ca, data, self.pdo_writable)
    }
}

fn download_response(out: &mut Out<'_>, index: u16, sub: u8) {
    let [i0, i1] = index.to_le_bytes();
    let [r0, r1] = SDO_RESPONSE;
    out.push(&[r0, r1, 0x60, i0, i1, sub]);
    out.pad_to(2 + 8);
}

/// The sub-indices of `index` the dictionary has, in order, with their storage lengths.
fn subs<D: Storage + ?Sized>(od: &D, index: u16) -> impl Iterator<Item = (u8, usize)> + '_ {
    let first = od.position(index, 0);
    (first..)
        .map_while(move |p| od.entry_at(p).filter(|e| e.addr.index == index))
        .map(|e| (e.addr.sub, e.len))
}

/// Whether the dictionary has an entry of object `index`.
#[inline(never)]
fn has_object<D: Storage + ?Sized>(od: &D, index: u16) -> bool {
    subs(od, index).next().is_some()
}

/// A complete-access upload from `first` (0 or 1) into `buf`: sub-index 0 as 16 bits (its
/// byte and a padding byte, ETG.1000.6 §5.6.2.1.1), then sub-indices 1 to the value of
/// sub-index 0, each in its bytes. Returns the length.
fn read_complete<D: Storage + ?Sized>(
    od: &D,
    index: u16,
    first: u8,
    buf: &mut [u8],
) -> Result<usize, SdoAbort> {
    if !has_object(od, index) {
        return Err(SdoAbort::NoSuchObject);
    }
    let mut count = [0u8; 1];
    od.read(index, 0, &mut count)?;
    let mut at = 0;
    if first == 0 {
        let dst = buf.get_mut(..2).ok_or(SdoAbort::OutOfMemory)?;
        dst.copy_from_slice(&[count[0], 0]);
        at = 2;
    }
    for (sub, _) in subs(od, index).filter(|&(s, _)| s >= 1 && s <= count[0]) {
        let rest = buf.get_mut(at..).ok_or(SdoAbort::OutOfMemory)?;
        at += od.read(index, sub, rest)?;
    }
    Ok(at)
}

/// A download to `index:sub`, or a complete-access one from `sub` (0 or 1).
fn write<D: Storage + ?Sized>(
    od: &mut D,
    index: u16,
    sub: u8,
    ca: bool,
    data: &[u8],
    pdo_writable: bool,
) -> Result<(), SdoAbort> {
    let has_subs = has_object(od, index);
    if (!ca || !has_subs) && od.access(index, sub).is_none() {
        // No such object or sub-index: the dictionary's own answer.
        od.read(index, sub, &mut [])?;
    }
    if !pdo_writable && pdo::is_pdo_config(index) {
        return Err(SdoAbort::DeviceState);
    }
    if !ca {
        pdo::check_write(od, index, sub, data)?;
        return od.write(index, sub, data);
    }
    let (count, mut rest) = match sub {
        0 => match data {
            [n, _pad, rest @ ..] => (*n, rest),
            _ => return Err(SdoAbort::TooShort),
        },
        _ => {
            let mut c = [0u8; 1];
            od.read(index, 0, &mut c)?;
            (c[0], data)
        }
    };
    let sub0_writable = od.access(index, 0).is_some_and(|a| a.writable());
    if sub == 0 && sub0_writable {
        od.write(index, 0, &[0])?;
    }
    let mut pos = od.position(index, 1);
    while let Some(e) = od.entry_at(pos).filter(|e| e.addr.index == index) {
        pos += 1;
        let s = e.addr.sub;
        if s < 1 || s > count {
            continue;
        }
        // Each entry takes the bytes its value has in storage.
        let (value, tail) = rest.split_at_checked(e.len).ok_or(SdoAbort::TooShort)?;
        pdo::check_write(od, index, s, value)?;
        od.write(index, s, value)?;
        rest = tail;
    }
    if !rest.is_empty() {
        return Err(SdoAbort::TooLong);
    }
    if sub == 0 && sub0_writable {
        pdo::check_write(od, index, 0, &[count])?;
        od.write(index, 0, &[count])?;
    }
    Ok(())
}
