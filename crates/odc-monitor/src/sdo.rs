//! SDO frames in words, and transfers put back together: expedited values at once, segmented
//! and block transfers when their last frame passes (CiA 301 7.2.4.3).

use std::collections::BTreeMap;

/// A transfer under way between a client and one node's server.
#[derive(Clone, Debug, Default)]
pub(crate) struct Transfer {
    pub index: u16,
    pub sub: u8,
    /// Data so far.
    pub data: Vec<u8>,
    /// Download (client → server data) or upload.
    pub download: bool,
    /// A block transfer: segments carry a sequence number and 7 bytes.
    pub block: bool,
    /// Segments flow: a block download after the server accepted it, a block upload after the
    /// client's start.
    pub started: bool,
    /// The last segment has passed (a segmented download's confirmation, or a block
    /// transfer's end, comes next).
    pub last: bool,
}

/// What a frame was, and when a transfer completes, its address and data.
pub(crate) struct Said {
    pub text: String,
    pub done: Option<(u16, u8, Vec<u8>, bool)>,
    pub addr: Option<(u16, u8)>,
}

fn addr(b: &[u8]) -> (u16, u8) {
    let i = u16::from_le_bytes([b.first().copied().unwrap_or(0), b.get(1).copied().unwrap_or(0)]);
    (i, b.get(2).copied().unwrap_or(0))
}

/// The SDO layer of a node: the transfer in progress.
#[derive(Default)]
pub(crate) struct Sdo {
    transfers: BTreeMap<u8, Transfer>,
}

impl Sdo {
    /// A frame from the client (`request`) or the server of `node`.
    pub fn frame(&mut self, node: u8, request: bool, b: &[u8]) -> Said {
        let Some(&cmd) = b.first() else {
            return Said { text: "SDO frame without data".into(), done: None, addr: None };
        };
        let idx = b.get(1..4).map(addr);
        let say = |text: String| Said { text, done: None, addr: None };
        // A block transfer's segments come without a command specifier.
        // The data sender's frames between the start and the last segment are segments
        // (their first byte is a sequence number, which can look like any command).
        if let Some(t) = self.transfers.get_mut(&node)
            && t.block
            && t.started
            && !t.last
            && request == t.download
            && b.len() == 8
        {
            let seq = cmd & 0x7F;
            t.data.extend_from_slice(b.get(1..8).unwrap_or(&[]));
            t.last = cmd & 0x80 != 0;
            let last = if t.last { ", last" } else { "" };
            return say(format!("block segment {seq}{last}"));
        }
        let cs = cmd >> 5;
        if cmd == 0x80 {
            let code = u32::from_le_bytes([
                b.get(4).copied().unwrap_or(0),
                b.get(5).copied().unwrap_or(0),
                b.get(6).copied().unwrap_or(0),
                b.get(7).copied().unwrap_or(0),
            ]);
            self.transfers.remove(&node);
            let meaning =
                odc::SdoAbort::from_u32(code).description().unwrap_or("unknown abort code");
            let (i, s) = idx.unwrap_or((0, 0));
            return Said {
                text: format!("abort 0x{code:08X}: {meaning}"),
                done: None,
                addr: Some((i, s)),
            };
        }
        match (request, cs) {
            // Initiate download.
            (true, 1) => {
                let (i, s) = idx.unwrap_or((0, 0));
                let expedited = cmd & 0x02 != 0;
                if expedited {
                    let n = if cmd & 0x01 != 0 { 4 - usize::from((cmd >> 2) & 3) } else { 4 };
                    let data = b.get(4..4 + n).unwrap_or(&[]).to_vec();
                    self.begin(node, (i, s), true, false, data);
                    Said { text: "write".into(), done: None, addr: Some((i, s)) }
                } else {
                    self.begin(node, (i, s), true, false, Vec::new());
                    let size = size(b).map_or(String::new(), |n| format!(", {n} bytes"));
                    Said {
                        text: format!("write (segmented{size})"),
                        done: None,
                        addr: Some((i, s)),
                    }
                }
            }
            // Initiate download response: an expedited write is done.
            (false, 3) => {
                let (i, s) = idx.unwrap_or((0, 0));
                let done = match self.transfers.get(&node) {
                    Some(t) if t.index == i && t.sub == s && !t.data.is_empty() && !t.block => {
                        self.transfers.remove(&node).map(|t| (t.index, t.sub, t.data, true))
                    }
                    _ => None,
                };
                Said { text: "write confirmed".into(), done, addr: Some((i, s)) }
            }
            // Download segment (client) / its confirmation (server).
            (true, 0) => {
                let n = 7 - usize::from((cmd >> 1) & 7);
                let last = cmd & 0x01 != 0;
                if let Some(t) = self.transfers.get_mut(&node) {
                    t.data.extend_from_slice(b.get(1..1 + n).unwrap_or(&[]));
                    t.last = last;
                }
                say(format!("write segment{}", if last { ", last" } else { "" }))
            }
            (false, 1) => {
                // The confirmation of the last segment ends the transfer.
                if self.transfers.get(&node).is_some_and(|t| t.download && !t.block && t.last) {
                    return self.finish(node, "write segment confirmed, done", true);
                }
                say("segment confirmed".into())
            }
            // Initiate upload request / response.
            (true, 2) => {
                let (i, s) = idx.unwrap_or((0, 0));
                self.begin(node, (i, s), false, false, Vec::new());
                Said { text: "read".into(), done: None, addr: Some((i, s)) }
            }
            (false, 2) => {
                let (i, s) = idx.unwrap_or((0, 0));
                if cmd & 0x02 != 0 {
                    let n = if cmd & 0x01 != 0 { 4 - usize::from((cmd >> 2) & 3) } else { 4 };
                    let data = b.get(4..4 + n).unwrap_or(&[]).to_vec();
                    self.transfers.remove(&node);
                    Said {
                        text: "read answer".into(),
                        done: Some((i, s, data, false)),
                        addr: Some((i, s)),
                    }
                } else {
                    let size = size(b).map_or(String::new(), |n| format!(", {n} bytes"));
                    Said {
                        text: format!("read answer (segmented{size})"),
                        done: None,
                        addr: Some((i, s)),
                    }
                }
            }
            // Upload segment request (client) / segment (server).
            (true, 3) => say("next segment, please".into()),
            (false, 0) => {
                let n = 7 - usize::from((cmd >> 1) & 7);
                let last = cmd & 0x01 != 0;
                if let Some(t) = self.transfers.get_mut(&node) {
                    t.data.extend_from_slice(b.get(1..1 + n).unwrap_or(&[]));
                }
                if last && self.transfers.contains_key(&node) {
                    return self.finish(node, "read segment, last", false);
                }
                say("read segment".into())
            }
            // Block download: client cs 6, server scs 5.
            (true, 6) => match cmd & 1 {
                0 => {
                    let (i, s) = idx.unwrap_or((0, 0));
                    self.begin(node, (i, s), true, true, Vec::new());
                    let size = size(b).map_or(String::new(), |n| format!(", {n} bytes"));
                    Said { text: format!("block write{size}"), done: None, addr: Some((i, s)) }
                }
                _ => {
                    self.block_end(node, cmd);
                    say("block write end".into())
                }
            },
            (false, 5) => match cmd & 3 {
                0 => {
                    if let Some(t) = self.transfers.get_mut(&node) {
                        t.started = true;
                    }
                    say("block write accepted".into())
                }
                2 => say(format!(
                    "block acknowledged up to segment {}",
                    b.get(1).copied().unwrap_or(0)
                )),
                _ => self.finish(node, "block write done", true),
            },
            // Block upload: client cs 5, server scs 6.
            (true, 5) => match cmd & 3 {
                0 => {
                    let (i, s) = idx.unwrap_or((0, 0));
                    self.begin(node, (i, s), false, true, Vec::new());
                    Said { text: "block read".into(), done: None, addr: Some((i, s)) }
                }
                3 => {
                    if let Some(t) = self.transfers.get_mut(&node) {
                        t.started = true;
                    }
                    say("block read start".into())
                }
                2 => say(format!(
                    "block acknowledged up to segment {}",
                    b.get(1).copied().unwrap_or(0)
                )),
                _ => self.finish(node, "block read done", false),
            },
            (false, 6) => match cmd & 1 {
                0 => {
                    let size = size(b).map_or(String::new(), |n| format!(", {n} bytes"));
                    Said { text: format!("block read answer{size}"), done: None, addr: idx }
                }
                _ => {
                    self.block_end(node, cmd);
                    say("block read end".into())
                }
            },
            _ => say(format!("SDO command 0x{cmd:02X}")),
        }
    }
}

impl Sdo {
    /// A transfer of `addr` starts (`download`: the client's data; `block`: a block transfer).
    fn begin(&mut self, node: u8, addr: (u16, u8), download: bool, block: bool, data: Vec<u8>) {
        let (index, sub) = addr;
        self.transfers
            .insert(node, Transfer { index, sub, data, download, block, ..Transfer::default() });
    }

    /// The transfer ends with its data: a frame that says `text` and carries the value.
    fn finish(&mut self, node: u8, text: &str, download: bool) -> Said {
        let done = self.transfers.remove(&node).map(|t| (t.index, t.sub, t.data, download));
        let addr = done.as_ref().map(|d| (d.0, d.1));
        Said { text: text.into(), done, addr }
    }

    /// A block transfer's end: the last segment's unused bytes (n, bits 4..2) are dropped.
    fn block_end(&mut self, node: u8, cmd: u8) {
        let unused = usize::from((cmd >> 2) & 7);
        if let Some(t) = self.transfers.get_mut(&node) {
            let keep = t.data.len().saturating_sub(unused);
            t.data.truncate(keep);
        }
    }
}

/// The size indicated in an initiate frame (bytes 4..8), when the s bit says there is one.
fn size(b: &[u8]) -> Option<u32> {
    let cmd = *b.first()?;
    let n = u32::from_le_bytes(b.get(4..8)?.try_into().ok()?);
    (cmd & 0x01 != 0 || cmd >> 5 >= 5).then_some(n)
}
