//! The server side of socketcand's protocol for the [`VirtualBus`](crate::VirtualBus): one
//! [`Session`] per client, fed the client's elements, saying what to answer and which frames
//! the client put on the bus. The codec is the runtime's ([`odc::transport::socketcand`]).
//!
//! What it serves, as socketcand's `state_nobus.c` and `state_raw.c` do: `< hi >` at
//! connection; `< open CHANNEL >` for the one bus it serves (another name: `< error could not
//! open bus >` and the connection ends); `< rawmode >` and `< bcmmode >`; `< send … >` in
//! either mode; `< echo >`. The broadcast manager's commands (`add`, `subscribe`, `filter`, …),
//! ISO-TP and control mode are not served: `< error unknown command >`. Only raw-mode clients
//! receive frames.

use std::time::{Duration, Instant};

use odc::can::CanFrame;
use odc::transport::socketcand::{Element, parse};

/// How long after its `< ok >` to `< rawmode >` a client that sends nothing starts receiving
/// frames: python-can reads that `< ok >` with one `recv` and compares the whole read with it,
/// so a frame sent right behind it would fail the client's handshake. Frames of that time are
/// held, then sent; a client that sends an element has read its `< ok >`, and takes frames
/// from then on (a master's first request is answered at once).
pub const RAW_HOLD: Duration = Duration::from_millis(50);

/// The socketcand state of a client.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// Connected, no bus opened yet.
    NoBus,
    /// A bus opened (broadcast manager mode, socketcand's default): it may send, receives
    /// nothing.
    Bcm,
    /// Raw mode: every frame on the bus, from this instant on; `true` once the client sent an
    /// element in raw mode (so it has read the `< ok >`).
    Raw(Instant, bool),
}

/// What to do after a client's element.
#[derive(Debug, PartialEq, Eq)]
pub enum Action {
    /// Nothing.
    None,
    /// Send this element to the client.
    Reply(&'static str),
    /// Send this element, then close the connection.
    ReplyAndClose(&'static str),
    /// The client put this frame on the bus.
    Frame(CanFrame),
    /// A malformed element: socketcand logs it and answers nothing; so does this server.
    Log(String),
}

/// One client's session.
#[derive(Debug)]
pub struct Session {
    mode: Mode,
}

impl Session {
    /// A new connection (the server greets it with [`Session::GREETING`]).
    pub fn new() -> Self {
        Self { mode: Mode::NoBus }
    }

    /// What the server says first.
    pub const GREETING: &'static str = "< hi >";

    /// Whether the client takes frames now (raw mode, past [`RAW_HOLD`]); `Some(false)`: in
    /// raw mode but within the hold (hold them), `None`: not in raw mode (drop them).
    pub fn takes_frames(&self, now: Instant) -> Option<bool> {
        match self.mode {
            Mode::Raw(since, spoke) => Some(spoke || now >= since + RAW_HOLD),
            Mode::NoBus | Mode::Bcm => None,
        }
    }

    /// The client's element `text`, on a server of bus `channel`.
    pub fn on_element(&mut self, text: &str, channel: &str, now: Instant) -> Action {
        const UNKNOWN: &str = "< error unknown command >";
        if let Mode::Raw(since, _) = self.mode {
            self.mode = Mode::Raw(since, true);
        }
        let element = match parse(text) {
            Ok(e) => e,
            Err(e) => return Action::Log(format!("`{text}`: {e}")),
        };
        match (self.mode, element) {
            (_, Element::Echo) => Action::Reply("< echo >"),
            (Mode::NoBus, Element::Open(name)) if name == channel => {
                self.mode = Mode::Bcm;
                Action::Reply("< ok >")
            }
            (Mode::NoBus, Element::Open(_)) => {
                Action::ReplyAndClose("< error could not open bus >")
            }
            (Mode::NoBus, _) => Action::Reply(UNKNOWN),
            (_, Element::Send(frame)) => Action::Frame(frame),
            (Mode::Bcm, Element::RawMode) => {
                self.mode = Mode::Raw(now, false);
                Action::Reply("< ok >")
            }
            (Mode::Raw(..), Element::BcmMode) => {
                self.mode = Mode::Bcm;
                Action::Reply("< ok >")
            }
            _ => Action::Reply(UNKNOWN),
        }
    }
}

impl Default for Session {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn python_can_handshake_then_frames() {
        // python-can 4.6 SocketCanDaemonBus.__init__: expects "< hi >", sends "< open CH >",
        // expects "< ok >", sends "< rawmode >", expects "< ok >".
        let t0 = Instant::now();
        let mut s = Session::new();
        assert_eq!(s.takes_frames(t0), None);
        assert_eq!(
            s.on_element("< send 123 0 >", "can0", t0),
            Action::Reply("< error unknown command >")
        );
        assert_eq!(s.on_element("< open can0 >", "can0", t0), Action::Reply("< ok >"));
        assert_eq!(s.takes_frames(t0), None, "BCM mode receives nothing unasked");
        let sent = CanFrame::from_slice(0x123, &[]).unwrap();
        assert_eq!(s.on_element("< send 123 0 >", "can0", t0), Action::Frame(sent));
        assert_eq!(s.on_element("< rawmode >", "can0", t0), Action::Reply("< ok >"));
        assert_eq!(s.takes_frames(t0), Some(false));
        assert_eq!(s.takes_frames(t0 + RAW_HOLD), Some(true));
        assert_eq!(s.on_element("< echo >", "can0", t0), Action::Reply("< echo >"));
        assert_eq!(s.takes_frames(t0), Some(true), "a client that spoke has read its ok");
        assert_eq!(
            s.on_element("< subscribe 0 0 123 >", "can0", t0),
            Action::Reply("< error unknown command >")
        );
        assert!(matches!(s.on_element("< send 123 9 >", "can0", t0), Action::Log(_)));
        assert_eq!(s.on_element("< bcmmode >", "can0", t0), Action::Reply("< ok >"));
        assert_eq!(s.takes_frames(t0 + RAW_HOLD), None);
    }

    #[test]
    fn another_bus_is_refused_and_closed() {
        let mut s = Session::new();
        assert_eq!(
            s.on_element("< open vcan1 >", "can0", Instant::now()),
            Action::ReplyAndClose("< error could not open bus >")
        );
    }
}
