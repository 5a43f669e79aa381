//! A small dictionary for the SDO targets, written by hand so the harness knows every value:
//! fixed-size numbers (ro, rw, wo), a DOMAIN of any length up to 40 bytes (longer than the
//! server's buffer, so uploads and downloads of it can run out of memory) and a 30-byte
//! string. It counts the writes it took.

use odc::SdoAbort;
use odc::slave::ObjectDictionary;

pub struct Obj {
    pub index: u16,
    pub sub: u8,
    pub value: Vec<u8>,
    /// `None`: any length up to 40 (a DOMAIN); else the fixed length.
    pub fixed: Option<usize>,
    pub readable: bool,
    pub writable: bool,
}

pub struct Dict {
    pub objs: Vec<Obj>,
    pub writes: usize,
}

pub const DOMAIN: (u16, u8) = (0x2002, 0);
pub const STRING: (u16, u8) = (0x2003, 0);
pub const RW32: (u16, u8) = (0x2000, 0);

impl Dict {
    pub fn new() -> Self {
        let o = |index, sub, value: &[u8], fixed, readable, writable| Obj {
            index,
            sub,
            value: value.to_vec(),
            fixed,
            readable,
            writable,
        };
        Dict {
            objs: vec![
                o(0x1000, 0, &0x0002_0192u32.to_le_bytes(), Some(4), true, false),
                o(0x2000, 0, &[1, 2, 3, 4], Some(4), true, true),
                o(0x2001, 0, &[7], Some(1), true, true),
                o(0x2001, 1, &[8, 9], Some(2), true, true),
                o(0x2002, 0, &[0x5A; 20], None, true, true),
                o(0x2003, 0, b"odc fuzz: a 30-byte string ..", None, true, false),
                o(0x2004, 0, &[0, 0], Some(2), false, true),
            ],
            writes: 0,
        }
    }

    fn find(&self, index: u16, sub: u8) -> Result<&Obj, SdoAbort> {
        if !self.objs.iter().any(|o| o.index == index) {
            return Err(SdoAbort::NoSuchObject);
        }
        self.objs.iter().find(|o| o.index == index && o.sub == sub).ok_or(SdoAbort::NoSuchSub)
    }

    pub fn value(&self, index: u16, sub: u8) -> Option<Vec<u8>> {
        let mut buf = [0u8; 64];
        let n = self.read(index, sub, &mut buf).ok()?;
        Some(buf[..n].to_vec())
    }
}

impl ObjectDictionary for Dict {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let o = self.find(index, sub)?;
        if !o.readable {
            return Err(SdoAbort::ReadOfWriteOnly);
        }
        let dst = buf.get_mut(..o.value.len()).ok_or(SdoAbort::TooShort)?;
        dst.copy_from_slice(&o.value);
        Ok(o.value.len())
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let o = self.find(index, sub)?;
        if !o.writable {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        match o.fixed {
            Some(n) if data.len() > n => return Err(SdoAbort::TooLong),
            Some(n) if data.len() < n => return Err(SdoAbort::TooShort),
            None if data.len() > 40 => return Err(SdoAbort::TooLong),
            _ => {}
        }
        let i = self
            .objs
            .iter()
            .position(|o| o.index == index && o.sub == sub)
            .ok_or(SdoAbort::NoSuchSub)?;
        self.objs[i].value = data.to_vec();
        self.writes += 1;
        Ok(())
    }
}
