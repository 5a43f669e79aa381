//! [`VirtualBus`]: a CAN bus over TCP. Every connected client is a node on the same bus, and so
//! is each simulated device on it: a frame from one client goes to the devices and to every
//! other client, a device's frames go to the other devices and to every client (a CAN
//! controller does not receive its own frames, so nobody gets its own back).
//!
//! Clients speak one of two wires, chosen when the bus is bound: the 16-byte records of
//! [`odc::transport::tcp`] ([`VirtualBus::bind`], `odc simulate --tcp`), or socketcand's ASCII
//! protocol in raw mode ([`VirtualBus::bind_socketcand`], `odc simulate --socketcand`), so
//! python-can's `socketcand` interface attaches unchanged.

use std::collections::BTreeMap;
use std::io::{self, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread;
use std::time::{Duration, Instant, SystemTime};

use odc::can::CanFrame;
use odc::transport::socketcand::{Splitter, format_frame};
use odc::transport::tcp::{Decoder, encode};

use crate::SimDevice;
use crate::nodes::{self, Routed};
use crate::socketcand::{Action, Session};

/// The device's timer tick.
pub const TICK: Duration = Duration::from_millis(10);

/// Frames held for a socketcand client during its [`RAW_HOLD`](crate::socketcand::RAW_HOLD),
/// at most (the rest are dropped, as a client that is not yet on the bus misses them).
const MAX_HELD: usize = 1024;

/// What the clients speak.
#[derive(Clone, Debug)]
enum Wire {
    /// The 16-byte records of [`odc::transport::tcp`].
    Records,
    /// socketcand's protocol, serving the bus of this name.
    Socketcand(String),
}

enum Event {
    Connected(usize, TcpStream, SocketAddr),
    Frame(usize, CanFrame),
    /// A socketcand element.
    Element(usize, String),
    Bad(usize, String),
    Closed(usize),
    Stop,
}

/// Ends a running [`VirtualBus::run`] from another thread.
#[derive(Clone, Debug)]
pub struct StopHandle(Sender<Event>);

impl std::fmt::Debug for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Event")
    }
}

impl StopHandle {
    /// Stops the bus; its `run` returns after the frame it is handling.
    pub fn stop(&self) {
        let _ = self.0.send(Event::Stop);
    }
}

/// A TCP listener that is a CAN bus, with simulated devices on it.
#[derive(Debug)]
pub struct VirtualBus {
    addr: SocketAddr,
    wire: Wire,
    events: Receiver<Event>,
    sender: Sender<Event>,
}

impl VirtualBus {
    /// Listens on `addr` (port 0: a free port) for clients of the 16-byte records of
    /// [`odc::transport::tcp`], and accepts them from now on.
    ///
    /// # Errors
    ///
    /// The listener's.
    pub fn bind(addr: impl std::net::ToSocketAddrs) -> io::Result<Self> {
        Self::listen(addr, Wire::Records)
    }

    /// Listens on `addr` (port 0: a free port) as a socketcand server of one bus, `channel`
    /// (what clients name in `< open CHANNEL >`), and accepts clients from now on.
    ///
    /// # Errors
    ///
    /// The listener's; `InvalidInput` for a bus name socketcand would not take (1 to 16
    /// characters, no spaces or angle brackets).
    pub fn bind_socketcand(addr: impl std::net::ToSocketAddrs, channel: &str) -> io::Result<Self> {
        let max = odc::transport::socketcand::MAX_CHANNEL;
        if channel.is_empty()
            || channel.len() > max
            || channel.contains(|c: char| c.is_whitespace() || c == '<' || c == '>')
        {
            let why = format!("`{channel}` is no socketcand bus name (1 to {max} characters)");
            return Err(io::Error::new(io::ErrorKind::InvalidInput, why));
        }
        Self::listen(addr, Wire::Socketcand(channel.to_owned()))
    }

    fn listen(addr: impl std::net::ToSocketAddrs, wire: Wire) -> io::Result<Self> {
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        let (sender, events) = mpsc::channel();
        let accept = sender.clone();
        let socketcand = matches!(wire, Wire::Socketcand(_));
        thread::spawn(move || accept_loop(&listener, &accept, socketcand));
        Ok(Self { addr, wire, events, sender })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The bus a socketcand server serves (`None` for the records wire).
    pub fn channel(&self) -> Option<&str> {
        match &self.wire {
            Wire::Records => None,
            Wire::Socketcand(c) => Some(c),
        }
    }

    /// A handle that stops [`VirtualBus::run`].
    pub fn stop_handle(&self) -> StopHandle {
        StopHandle(self.sender.clone())
    }

    /// Runs `device` on the bus until stopped: its boot-up, then frames in and out and a
    /// timer tick every [`TICK`]. Client events (connected, closed, a record that is no
    /// frame) are reported through `log`.
    pub fn run(self, device: &mut SimDevice, log: &mut impl FnMut(&str)) {
        self.run_all(std::slice::from_mut(device), log);
    }

    /// The bus alone, without a device of its own: a hub for the clients (a python-canopen
    /// node, `odc sdo`, `odc monitor`, …), until stopped.
    pub fn run_hub(self, log: &mut impl FnMut(&str)) {
        self.run_all(&mut [], log);
    }

    /// Runs `devices` on the bus until stopped, as [`VirtualBus::run`] runs one: each
    /// receives the clients' frames and the other devices' (node-IDs are the caller's to
    /// keep apart).
    pub fn run_all(self, devices: &mut [SimDevice], log: &mut impl FnMut(&str)) {
        let start = Instant::now();
        let now_ms = || u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX);
        let channel = match &self.wire {
            Wire::Records => None,
            Wire::Socketcand(c) => Some(c.as_str()),
        };
        let mut clients = Clients::default();
        let mut out = Vec::new();
        let routed = nodes::start_all(devices, now_ms(), &mut |f| out.push(f));
        report(routed, log);
        // No client is on the bus yet: like a device that boots alone on its bus, the boot-up
        // reaches nobody. A master that wants to see one resets the node (NMT 0x81).
        for f in &out {
            log(&format!("sent 0x{:03X} {:02X?} before any client connected", f.id(), f.bytes()));
        }
        out.clear();
        let mut next_tick = Instant::now() + TICK;
        loop {
            let wait = next_tick.saturating_duration_since(Instant::now());
            let mut from_client =
                |id: usize, frame: CanFrame, clients: &mut Clients, out: &mut Vec<CanFrame>| {
                    clients.send(Some(id), &[frame], log);
                    let routed = nodes::handle_all(devices, &frame, now_ms(), &mut |f| out.push(f));
                    report(routed, log);
                };
            match self.events.recv_timeout(wait) {
                Ok(Event::Connected(id, mut stream, peer)) => {
                    log(&format!("client {id} connected from {peer}"));
                    let session = channel.map(|_| Session::new());
                    let greeted =
                        session.is_none() || stream.write_all(Session::GREETING.as_bytes()).is_ok();
                    if greeted {
                        clients.0.insert(id, Client { stream, session, held: Vec::new() });
                    }
                }
                Ok(Event::Frame(id, frame)) => from_client(id, frame, &mut clients, &mut out),
                Ok(Event::Element(id, text)) => {
                    let Some(client) = clients.0.get_mut(&id) else { continue };
                    let Some(session) = &mut client.session else { continue };
                    let action = session.on_element(&text, channel.unwrap_or(""), Instant::now());
                    match action {
                        Action::None => {}
                        Action::Reply(reply) => {
                            if let Err(e) = client.stream.write_all(reply.as_bytes()) {
                                log(&format!("client {id} dropped: {e}"));
                                clients.0.remove(&id);
                            }
                        }
                        Action::ReplyAndClose(reply) => {
                            let _ = client.stream.write_all(reply.as_bytes());
                            let _ = client.stream.shutdown(Shutdown::Both);
                            log(&format!("client {id}: `{text}` answered `{reply}`; closed"));
                            clients.0.remove(&id);
                        }
                        Action::Frame(frame) => from_client(id, frame, &mut clients, &mut out),
                        Action::Log(why) => log(&format!("client {id}: {why}; ignored")),
                    }
                }
                Ok(Event::Bad(id, e)) => log(&format!("client {id}: {e}; skipped")),
                Ok(Event::Closed(id)) => {
                    if clients.0.remove(&id).is_some() {
                        log(&format!("client {id} disconnected"));
                    }
                }
                Ok(Event::Stop) | Err(RecvTimeoutError::Disconnected) => return,
                Err(RecvTimeoutError::Timeout) => {}
            }
            if Instant::now() >= next_tick {
                let routed = nodes::poll_all(devices, now_ms(), &mut |f| out.push(f));
                report(routed, log);
                next_tick += TICK;
                if next_tick < Instant::now() {
                    next_tick = Instant::now() + TICK;
                }
            }
            clients.send(None, &out, log);
            out.clear();
        }
    }
}

/// Logs frames the devices sent past [`nodes::MAX_ROUTED`].
fn report(routed: Routed, log: &mut impl FnMut(&str)) {
    if routed.dropped > 0 {
        log(&format!(
            "{} frames between the simulated devices not delivered (more than {} for one event)",
            routed.dropped,
            nodes::MAX_ROUTED
        ));
    }
}

/// A connected client.
struct Client {
    stream: TcpStream,
    /// Its socketcand session (`None` on the records wire).
    session: Option<Session>,
    /// Frames held for a socketcand client that just entered raw mode.
    held: Vec<CanFrame>,
}

#[derive(Default)]
struct Clients(BTreeMap<usize, Client>);

impl Clients {
    /// Sends `frames` to every client but `except` that takes frames (and what was held for
    /// a socketcand client whose hold is over); a client that cannot take them is dropped.
    fn send(&mut self, except: Option<usize>, frames: &[CanFrame], log: &mut impl FnMut(&str)) {
        let now = Instant::now();
        let timestamp =
            SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
        let records: Vec<u8> = frames.iter().flat_map(encode).collect();
        self.0.retain(|&id, client| {
            let mine = Some(id) == except;
            let bytes = match &client.session {
                None if mine || frames.is_empty() => return true,
                None => records.clone(),
                Some(session) => match session.takes_frames(now) {
                    None => return true,
                    Some(false) => {
                        if !mine {
                            let room = MAX_HELD.saturating_sub(client.held.len());
                            client.held.extend(frames.iter().take(room));
                        }
                        return true;
                    }
                    Some(true) => {
                        let mut text = String::new();
                        let fresh = if mine { &[][..] } else { frames };
                        // Remote frames have no raw-mode syntax: socketcand drops them too.
                        for f in client.held.drain(..).chain(fresh.iter().copied()) {
                            if let Ok(line) = format_frame(&f, timestamp) {
                                text.push_str(&line);
                            }
                        }
                        if text.is_empty() {
                            return true;
                        }
                        text.into_bytes()
                    }
                },
            };
            match client.stream.write_all(&bytes) {
                Ok(()) => true,
                Err(e) => {
                    log(&format!("client {id} dropped: {e}"));
                    false
                }
            }
        });
    }
}

fn accept_loop(listener: &TcpListener, events: &Sender<Event>, socketcand: bool) {
    for (id, stream) in listener.incoming().enumerate() {
        let Ok(stream) = stream else { continue };
        let (Ok(reader), Ok(peer)) = (stream.try_clone(), stream.peer_addr()) else { continue };
        let _ = stream.set_nodelay(true);
        if events.send(Event::Connected(id, stream, peer)).is_err() {
            return;
        }
        let events = events.clone();
        if socketcand {
            thread::spawn(move || read_elements(id, reader, &events));
        } else {
            thread::spawn(move || read_records(id, reader, &events));
        }
    }
}

/// Reads from a client until it closes: its bytes through `split`, each piece an event.
fn read_loop(
    id: usize,
    mut stream: TcpStream,
    events: &Sender<Event>,
    mut split: impl FnMut(&[u8], &mut Vec<Event>),
) {
    let mut buf = [0u8; 1024];
    let mut batch = Vec::new();
    loop {
        let n = match stream.read(&mut buf) {
            Ok(0) | Err(_) => {
                let _ = events.send(Event::Closed(id));
                return;
            }
            Ok(n) => n,
        };
        split(buf.get(..n).unwrap_or(&[]), &mut batch);
        for event in batch.drain(..) {
            if events.send(event).is_err() {
                return;
            }
        }
    }
}

fn read_records(id: usize, stream: TcpStream, events: &Sender<Event>) {
    let mut decoder = Decoder::new();
    read_loop(id, stream, events, |bytes, batch| {
        decoder.push(bytes);
        while let Some(frame) = decoder.next_frame() {
            batch.push(match frame {
                Ok(f) => Event::Frame(id, f),
                Err(e) => Event::Bad(id, e.to_string()),
            });
        }
    });
}

fn read_elements(id: usize, stream: TcpStream, events: &Sender<Event>) {
    let mut splitter = Splitter::new();
    read_loop(id, stream, events, |bytes, batch| {
        splitter.push(bytes);
        while let Some(element) = splitter.next_element() {
            batch.push(match element {
                Ok(text) => Event::Element(id, text),
                Err(e) => Event::Bad(id, e.to_string()),
            });
        }
    });
}
