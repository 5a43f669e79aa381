//! [`VirtualBus`]: a CAN bus over TCP. Every connected client is a node on the same bus; a
//! frame from one client goes to the simulated device and to every other client, the device's
//! frames go to every client (a CAN controller does not receive its own frames, so nobody
//! gets its own back). Frames are the 16-byte records of [`odc::transport::tcp`].

use std::collections::BTreeMap;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread;
use std::time::{Duration, Instant};

use odc::can::CanFrame;
use odc::transport::tcp::{DecodeError, Decoder, encode};

use crate::SimDevice;

/// The device's timer tick.
pub const TICK: Duration = Duration::from_millis(10);

enum Event {
    Connected(usize, TcpStream, SocketAddr),
    Frame(usize, CanFrame),
    Bad(usize, DecodeError),
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

/// A TCP listener that is a CAN bus with one simulated device on it.
#[derive(Debug)]
pub struct VirtualBus {
    addr: SocketAddr,
    events: Receiver<Event>,
    sender: Sender<Event>,
}

impl VirtualBus {
    /// Listens on `addr` (port 0: a free port) and accepts clients from now on.
    ///
    /// # Errors
    ///
    /// The listener's.
    pub fn bind(addr: impl std::net::ToSocketAddrs) -> io::Result<Self> {
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        let (sender, events) = mpsc::channel();
        let accept = sender.clone();
        thread::spawn(move || accept_loop(&listener, &accept));
        Ok(Self { addr, events, sender })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// A handle that stops [`VirtualBus::run`].
    pub fn stop_handle(&self) -> StopHandle {
        StopHandle(self.sender.clone())
    }

    /// Runs `device` on the bus until stopped: its boot-up, then frames in and out and a
    /// timer tick every [`TICK`]. Client events (connected, closed, a record that is no
    /// frame) are reported through `log`.
    pub fn run(self, device: &mut SimDevice, log: &mut impl FnMut(&str)) {
        self.run_with(Some(device), log);
    }

    /// The bus alone, without a device of its own: a hub for the clients (a python-canopen
    /// node, `odc sdo`, `odc monitor`, …), until stopped.
    pub fn run_hub(self, log: &mut impl FnMut(&str)) {
        self.run_with(None, log);
    }

    fn run_with(self, mut device: Option<&mut SimDevice>, log: &mut impl FnMut(&str)) {
        let start = Instant::now();
        let now_ms = || u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX);
        let mut clients: BTreeMap<usize, TcpStream> = BTreeMap::new();
        let mut out = Vec::new();
        if let Some(device) = device.as_deref_mut() {
            device.start(now_ms(), &mut |f| out.push(f));
        }
        // No client is on the bus yet: like a device that boots alone on its bus, the boot-up
        // reaches nobody. A master that wants to see one resets the node (NMT 0x81).
        for f in &out {
            log(&format!("sent 0x{:03X} {:02X?} before any client connected", f.id(), f.bytes()));
        }
        out.clear();
        let mut next_tick = Instant::now() + TICK;
        loop {
            let wait = next_tick.saturating_duration_since(Instant::now());
            match self.events.recv_timeout(wait) {
                Ok(Event::Connected(id, stream, peer)) => {
                    log(&format!("client {id} connected from {peer}"));
                    clients.insert(id, stream);
                }
                Ok(Event::Frame(id, frame)) => {
                    broadcast(&mut clients, Some(id), &[frame], log);
                    if let Some(device) = device.as_deref_mut() {
                        device.handle(&frame, now_ms(), &mut |f| out.push(f));
                    }
                }
                Ok(Event::Bad(id, e)) => log(&format!("client {id}: {e}; record skipped")),
                Ok(Event::Closed(id)) => {
                    if clients.remove(&id).is_some() {
                        log(&format!("client {id} disconnected"));
                    }
                }
                Ok(Event::Stop) | Err(RecvTimeoutError::Disconnected) => return,
                Err(RecvTimeoutError::Timeout) => {}
            }
            if Instant::now() >= next_tick {
                if let Some(device) = device.as_deref_mut() {
                    device.poll(now_ms(), &mut |f| out.push(f));
                }
                next_tick += TICK;
                if next_tick < Instant::now() {
                    next_tick = Instant::now() + TICK;
                }
            }
            broadcast(&mut clients, None, &out, log);
            out.clear();
        }
    }
}

/// Sends `frames` to every client but `except`; a client that cannot take them is dropped.
fn broadcast(
    clients: &mut BTreeMap<usize, TcpStream>,
    except: Option<usize>,
    frames: &[CanFrame],
    log: &mut impl FnMut(&str),
) {
    if frames.is_empty() {
        return;
    }
    let bytes: Vec<u8> = frames.iter().flat_map(encode).collect();
    clients.retain(|&id, stream| {
        if Some(id) == except {
            return true;
        }
        match stream.write_all(&bytes) {
            Ok(()) => true,
            Err(e) => {
                log(&format!("client {id} dropped: {e}"));
                false
            }
        }
    });
}

fn accept_loop(listener: &TcpListener, events: &Sender<Event>) {
    for (id, stream) in listener.incoming().enumerate() {
        let Ok(stream) = stream else { continue };
        let (Ok(reader), Ok(peer)) = (stream.try_clone(), stream.peer_addr()) else { continue };
        let _ = stream.set_nodelay(true);
        if events.send(Event::Connected(id, stream, peer)).is_err() {
            return;
        }
        let events = events.clone();
        thread::spawn(move || read_loop(id, reader, &events));
    }
}

fn read_loop(id: usize, mut stream: TcpStream, events: &Sender<Event>) {
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 1024];
    loop {
        let n = match stream.read(&mut buf) {
            Ok(0) | Err(_) => {
                let _ = events.send(Event::Closed(id));
                return;
            }
            Ok(n) => n,
        };
        decoder.push(buf.get(..n).unwrap_or(&[]));
        while let Some(frame) = decoder.next_frame() {
            let event = match frame {
                Ok(f) => Event::Frame(id, f),
                Err(e) => Event::Bad(id, e),
            };
            if events.send(event).is_err() {
                return;
            }
        }
    }
}
