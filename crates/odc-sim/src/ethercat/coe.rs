//! CoE SDO server (ETG.1000.6 §5.6.2) over the [`ModelDictionary`]: expedited, normal and
//! segmented upload and download, complete access where the ESI allows it, and aborts with
//! the dictionary's codes.
//!
//! The CoE header is 2 bytes: number (bits 0–8) and service (bits 12–15: 2 SDO request, 3
//! SDO response). The SDO header follows CiA 301's command byte (command specifier in bits
//! 5–7, bit 4 complete access for the initiate commands, toggle for segments), index,
//! sub-index and 4 bytes of data or size. Unlike CAN, a normal transfer carries as much data
//! as the mailbox holds, and segments are as long as the mailbox allows.

use odc::SdoAbort;
use odc::slave::ObjectDictionary;
use odc_model::Device;
use odc_model::ethercat::CoE;

use super::info::SdoInfo;
use super::mailbox::error;
use crate::ModelDictionary;

/// Service of an SDO request in the CoE header.
const SDO_REQUEST: u8 = 2;
/// Service of SDO Information in the CoE header.
const SDO_INFO: u8 = 8;
/// The CoE header of an SDO response (number 0, service 3).
const SDO_RESPONSE: [u8; 2] = [0x00, 0x30];
/// The CoE header of an abort from the device: service 2, SDO request (ETG.1000.6, Abort SDO
/// Transfer Request; SOES sends it so, and SOEM takes an abort under service 3 for a malformed
/// response).
const SDO_ABORT: [u8; 2] = [0x00, 0x20];
/// The largest value moved in one transfer (as the CANopen simulation's SDO buffer).
const MAX_VALUE: usize = crate::SDO_BUFFER;

/// One mailbox's CoE data, and how much room the reply has (the read mailbox, less its
/// header).
pub struct Request<'a> {
    /// The CoE data (CoE header first).
    pub data: &'a [u8],
    /// Bytes the reply may take.
    pub room: usize,
}

#[derive(Debug)]
enum Transfer {
    None,
    Upload { index: u16, sub: u8, data: Vec<u8>, at: usize, toggle: bool },
    Download { index: u16, sub: u8, ca: bool, size: usize, data: Vec<u8>, toggle: bool },
}

/// The SDO server of one device.
#[derive(Debug)]
pub struct CoeServer {
    complete_access: bool,
    info: Option<SdoInfo>,
    transfer: Transfer,
}

impl CoeServer {
    /// The server for `device`, whose ESI says `coe`.
    pub fn new(device: &Device, coe: &CoE) -> Self {
        let info = coe.sdo_info.then(|| SdoInfo::new(device));
        Self { complete_access: coe.complete_access, info, transfer: Transfer::None }
    }

    /// Forgets a transfer under way.
    pub fn reset(&mut self) {
        self.transfer = Transfer::None;
    }

    /// The replies' CoE data (none, one, or the fragments of an SDO Information reply);
    /// `Err` a mailbox error detail.
    pub fn handle(
        &mut self,
        req: Request<'_>,
        od: &mut ModelDictionary,
        writable: &dyn Fn(u16) -> bool,
    ) -> Result<Vec<Vec<u8>>, u16> {
        let Some((&[_, service], sdo)) = req.data.split_first_chunk::<2>() else {
            return Err(error::SIZE_TOO_SHORT);
        };
        if let (SDO_INFO, Some(info)) = (service >> 4, &self.info) {
            return Ok(info.handle(sdo, req.room));
        }
        Ok(self.sdo(service, sdo, req.room, od, writable)?.into_iter().collect())
    }

    fn sdo(
        &mut self,
        service: u8,
        sdo: &[u8],
        room: usize,
        od: &mut ModelDictionary,
        writable: &dyn Fn(u16) -> bool,
    ) -> Result<Option<Vec<u8>>, u16> {
        if service >> 4 != SDO_REQUEST {
            // Emergency, TxPDO, RxPDO, remote requests and SDO information are not served.
            return Err(error::UNSUPPORTED_PROTOCOL);
        }
        let Some(&command) = sdo.first() else { return Err(error::SIZE_TOO_SHORT) };
        let addr = match sdo.get(1..4) {
            Some(&[lo, hi, sub]) => Some((u16::from_le_bytes([lo, hi]), sub)),
            _ => None,
        };
        let reply = match (command >> 5, addr) {
            (1, Some((index, sub))) => self.download(command, index, sub, sdo, od, writable),
            (0, _) => self.download_segment(command, sdo, od, writable),
            (2, Some((index, sub))) => self.upload(command, index, sub, room, od),
            (3, _) => self.upload_segment(command, room),
            // Abort from the master: the transfer ends, no reply.
            (4, _) => {
                self.transfer = Transfer::None;
                return Ok(None);
            }
            (_, a) => Err((a.unwrap_or((0, 0)), SdoAbort::InvalidCommand)),
        };
        Ok(Some(reply.unwrap_or_else(|((index, sub), abort)| {
            self.transfer = Transfer::None;
            let mut r = SDO_ABORT.to_vec();
            r.push(0x80);
            r.extend_from_slice(&index.to_le_bytes());
            r.push(sub);
            r.extend_from_slice(&abort.to_u32().to_le_bytes());
            r
        })))
    }

    fn check_ca(&self, command: u8, index: u16, sub: u8) -> Result<bool, Abort> {
        let ca = command & 0x10 != 0;
        if ca && (!self.complete_access || sub > 1) {
            return Err(((index, sub), SdoAbort::UnsupportedAccess));
        }
        Ok(ca)
    }

    fn upload(
        &mut self,
        command: u8,
        index: u16,
        sub: u8,
        room: usize,
        od: &ModelDictionary,
    ) -> Reply {
        let at = (index, sub);
        let ca = self.check_ca(command, index, sub)?;
        let data = match ca {
            true => read_complete(od, index, sub).map_err(|e| (at, e))?,
            false => {
                let mut buf = vec![0u8; MAX_VALUE];
                let n = od.read(index, sub, &mut buf).map_err(|e| (at, e))?;
                buf.truncate(n);
                buf
            }
        };
        let ca_bit = if ca { 0x10 } else { 0 };
        let mut r = SDO_RESPONSE.to_vec();
        if data.len() <= 4 && !data.is_empty() {
            // Expedited: e = 1, s = 1, n = bytes of the 4 without data.
            let n = (4 - data.len()) as u8;
            r.push(0x43 | n << 2 | ca_bit);
            push_addr(&mut r, index, sub);
            r.extend_from_slice(&data);
            r.resize(2 + 8, 0);
            self.transfer = Transfer::None;
            return Ok(r);
        }
        // Normal: the size, then as much data as the mailbox holds.
        r.push(0x41 | ca_bit);
        push_addr(&mut r, index, sub);
        r.extend_from_slice(&u32::try_from(data.len()).unwrap_or(u32::MAX).to_le_bytes());
        let first = data.len().min(room.saturating_sub(r.len()));
        r.extend_from_slice(data.get(..first).unwrap_or(&[]));
        self.transfer = match first < data.len() {
            true => Transfer::Upload { index, sub, data, at: first, toggle: false },
            false => Transfer::None,
        };
        Ok(r)
    }

    fn upload_segment(&mut self, command: u8, room: usize) -> Reply {
        let Transfer::Upload { index, sub, data, at, toggle } = &mut self.transfer else {
            return Err(((0, 0), SdoAbort::InvalidCommand));
        };
        let addr = (*index, *sub);
        let t = command & 0x10 != 0;
        if t != *toggle {
            return Err((addr, SdoAbort::ToggleBit));
        }
        let rest = data.get(*at..).unwrap_or(&[]);
        let n = rest.len().min(room.saturating_sub(3));
        let last = n == rest.len();
        let mut r = SDO_RESPONSE.to_vec();
        // A segment shorter than 7 bytes is padded to 7 and says how many are unused.
        let unused = 7usize.saturating_sub(n) as u8;
        r.push(u8::from(t) << 4 | unused << 1 | u8::from(last));
        r.extend_from_slice(rest.get(..n).unwrap_or(&[]));
        r.resize(r.len().max(3 + 7), 0);
        *at += n;
        *toggle = !*toggle;
        if last {
            self.transfer = Transfer::None;
        }
        Ok(r)
    }

    fn download(
        &mut self,
        command: u8,
        index: u16,
        sub: u8,
        sdo: &[u8],
        od: &mut ModelDictionary,
        writable: &dyn Fn(u16) -> bool,
    ) -> Reply {
        let at = (index, sub);
        let ca = self.check_ca(command, index, sub)?;
        let payload = sdo.get(4..).unwrap_or(&[]);
        if command & 0x02 != 0 {
            // Expedited: the size indicator says how many of the 4 bytes are data.
            let n = if command & 0x01 != 0 { 4 - usize::from(command >> 2 & 0x03) } else { 4 };
            let data = payload.get(..n).ok_or((at, SdoAbort::TooShort))?;
            write(od, index, sub, ca, data, writable).map_err(|e| (at, e))?;
            return Ok(download_response(index, sub));
        }
        let size = match payload.get(..4) {
            Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]) as usize,
            _ => return Err((at, SdoAbort::TooShort)),
        };
        if size > MAX_VALUE {
            return Err((at, SdoAbort::OutOfMemory));
        }
        let data = payload.get(4..).unwrap_or(&[]);
        if data.len() >= size {
            write(od, index, sub, ca, data.get(..size).unwrap_or(&[]), writable)
                .map_err(|e| (at, e))?;
            self.transfer = Transfer::None;
        } else {
            self.transfer =
                Transfer::Download { index, sub, ca, size, data: data.to_vec(), toggle: false };
        }
        Ok(download_response(index, sub))
    }

    fn download_segment(
        &mut self,
        command: u8,
        sdo: &[u8],
        od: &mut ModelDictionary,
        writable: &dyn Fn(u16) -> bool,
    ) -> Reply {
        let Transfer::Download { index, sub, ca, size, data, toggle } = &mut self.transfer else {
            return Err(((0, 0), SdoAbort::InvalidCommand));
        };
        let at = (*index, *sub);
        let t = command & 0x10 != 0;
        if t != *toggle {
            return Err((at, SdoAbort::ToggleBit));
        }
        let mut seg = sdo.get(1..).unwrap_or(&[]);
        if seg.len() == 7 {
            let unused = usize::from(command >> 1 & 0x07);
            seg = seg.get(..7 - unused).unwrap_or(&[]);
        }
        data.extend_from_slice(seg);
        if data.len() > *size {
            return Err((at, SdoAbort::TooLong));
        }
        let reply_cmd = 0x20 | u8::from(t) << 4;
        *toggle = !*toggle;
        if command & 0x01 != 0 {
            let (index, sub, ca, size) = (*index, *sub, *ca, *size);
            let value = core::mem::take(data);
            self.transfer = Transfer::None;
            if value.len() != size {
                return Err((at, SdoAbort::TooShort));
            }
            write(od, index, sub, ca, &value, writable).map_err(|e| (at, e))?;
        }
        let mut r = SDO_RESPONSE.to_vec();
        r.push(reply_cmd);
        r.resize(2 + 8, 0);
        Ok(r)
    }
}

type Abort = ((u16, u8), SdoAbort);
type Reply = Result<Vec<u8>, Abort>;

fn push_addr(r: &mut Vec<u8>, index: u16, sub: u8) {
    r.extend_from_slice(&index.to_le_bytes());
    r.push(sub);
}

fn download_response(index: u16, sub: u8) -> Vec<u8> {
    let mut r = SDO_RESPONSE.to_vec();
    r.push(0x60);
    push_addr(&mut r, index, sub);
    r.resize(2 + 8, 0);
    r
}

/// The sub-indices of `index` the dictionary has, in order.
fn subs(od: &ModelDictionary, index: u16) -> Vec<u8> {
    od.entries().filter(|(a, _, _)| a.index == index).map(|(a, _, _)| a.sub).collect()
}

/// A complete-access upload from `first` (0 or 1): sub-index 0 as 16 bits (its byte and a
/// padding byte, ETG.1000.6 §5.6.2.1.1), then sub-indices 1 to the value of sub-index 0, each
/// in its bytes.
fn read_complete(od: &ModelDictionary, index: u16, first: u8) -> Result<Vec<u8>, SdoAbort> {
    let present = subs(od, index);
    if present.is_empty() {
        return Err(SdoAbort::NoSuchObject);
    }
    let mut count = [0u8; 1];
    od.read(index, 0, &mut count)?;
    let mut out = Vec::new();
    if first == 0 {
        out.extend_from_slice(&[count[0], 0]);
    }
    let mut buf = vec![0u8; MAX_VALUE];
    for sub in present.into_iter().filter(|&s| s >= 1 && s <= count[0]) {
        let n = od.read(index, sub, &mut buf)?;
        out.extend_from_slice(buf.get(..n).unwrap_or(&[]));
    }
    Ok(out)
}

/// A download to `index:sub`, or a complete-access one from `sub` (0 or 1).
fn write(
    od: &mut ModelDictionary,
    index: u16,
    sub: u8,
    ca: bool,
    data: &[u8],
    writable: &dyn Fn(u16) -> bool,
) -> Result<(), SdoAbort> {
    if (!ca || subs(od, index).is_empty()) && od.access(index, sub).is_none() {
        // No such object or sub-index: the dictionary's own answer.
        od.read(index, sub, &mut [0u8; MAX_VALUE])?;
    }
    if !writable(index) {
        return Err(SdoAbort::DeviceState);
    }
    if !ca {
        super::pdo::check_write(od, index, sub, data)?;
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
    if sub == 0 && od.access(index, 0).is_some_and(|a| a.writable()) {
        od.write(index, 0, &[0])?;
    }
    let mut buf = vec![0u8; MAX_VALUE];
    for s in subs(od, index).into_iter().filter(|&s| s >= 1 && s <= count) {
        // Each entry takes the bytes its value has now (the dictionary's storage).
        let n = od.read(index, s, &mut buf).map(|_| entry_len(od, index, s))?;
        let (value, tail) = rest.split_at_checked(n).ok_or(SdoAbort::TooShort)?;
        super::pdo::check_write(od, index, s, value)?;
        od.write(index, s, value)?;
        rest = tail;
    }
    if !rest.is_empty() {
        return Err(SdoAbort::TooLong);
    }
    if sub == 0 && od.access(index, 0).is_some_and(|a| a.writable()) {
        super::pdo::check_write(od, index, 0, &[count])?;
        od.write(index, 0, &[count])?;
    }
    Ok(())
}

fn entry_len(od: &ModelDictionary, index: u16, sub: u8) -> usize {
    od.entry_len(index, sub).unwrap_or(0)
}
