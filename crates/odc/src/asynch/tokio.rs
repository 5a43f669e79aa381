//! tokio adapters of the async master: its [`Clock`] ([`TokioClock`], which follows tokio's
//! paused test clock too), the TCP virtual bus of `odc simulate --tcp` ([`tcp`]), a socketcand
//! server (`odc simulate --socketcand`, socketcand on a Linux machine: [`socketcand`]) and, with
//! the `socketcan` feature on Linux, a SocketCAN interface ([`socketcan`]).

use std::future::Future;

use super::{CanRx, CanTx, Clock};
use crate::can::CanFrame;
use crate::time::{Duration, Instant};

/// tokio's clock: [`Instant`]s count from its creation.
#[derive(Clone, Copy, Debug)]
pub struct TokioClock {
    epoch: ::tokio::time::Instant,
}

impl TokioClock {
    /// A clock whose zero is now.
    pub fn new() -> Self {
        Self { epoch: ::tokio::time::Instant::now() }
    }

    /// The tokio instant of `t`.
    pub fn to_tokio(&self, t: Instant) -> ::tokio::time::Instant {
        self.epoch + std::time::Duration::from_micros(t.as_micros())
    }
}

impl Default for TokioClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for TokioClock {
    fn now(&self) -> Instant {
        let us = self.epoch.elapsed().as_micros();
        Instant::from_micros(u64::try_from(us).unwrap_or(u64::MAX))
    }

    fn sleep_until(&self, deadline: Instant) -> impl Future<Output = ()> {
        ::tokio::time::sleep_until(self.to_tokio(deadline))
    }

    /// tokio's timer wheel counts whole milliseconds, rounding a deadline up.
    fn resolution(&self) -> Duration {
        Duration::from_millis(1)
    }
}

/// A clock on `CLOCK_MONOTONIC` whose timer is a Linux timerfd on tokio's reactor: it wakes
/// within microseconds of a deadline (plus the scheduler's latency), where tokio's own timer
/// rounds every deadline up to its next millisecond and oversleeps each by about a tenth of
/// one (`cargo run --example async_three_drives` shows both). For a 1 kHz cycle.
///
/// A sleep that cannot get its timerfd (descriptors exhausted) falls back to tokio's timer.
#[cfg(target_os = "linux")]
#[derive(Clone, Copy, Debug)]
pub struct TimerfdClock {
    epoch: rustix::time::Timespec,
    tokio: TokioClock,
}

#[cfg(target_os = "linux")]
impl TimerfdClock {
    /// A clock whose zero is now.
    pub fn new() -> Self {
        let epoch = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
        Self { epoch, tokio: TokioClock::new() }
    }

    /// The `CLOCK_MONOTONIC` time of `t`.
    // `tv_nsec` is `i64` here, narrower on some targets: the conversion is not useless there.
    #[allow(clippy::useless_conversion)]
    fn timespec(&self, t: Instant) -> rustix::time::Timespec {
        let ns = i64::from(self.epoch.tv_nsec) + (t.as_micros() % 1_000_000) as i64 * 1000;
        rustix::time::Timespec {
            tv_sec: self.epoch.tv_sec + (t.as_micros() / 1_000_000) as i64 + ns / 1_000_000_000,
            tv_nsec: (ns % 1_000_000_000) as _,
        }
    }

    async fn timerfd(&self, deadline: Instant) -> std::io::Result<()> {
        use rustix::time::{Itimerspec, TimerfdClockId, TimerfdFlags, TimerfdTimerFlags};
        let fd = rustix::time::timerfd_create(
            TimerfdClockId::Monotonic,
            TimerfdFlags::NONBLOCK | TimerfdFlags::CLOEXEC,
        )?;
        let zero = rustix::time::Timespec { tv_sec: 0, tv_nsec: 0 };
        // Absolute: a deadline already past fires at once (its time is never zero, which
        // would disarm the timer: the epoch is after boot).
        let spec = Itimerspec { it_interval: zero, it_value: self.timespec(deadline) };
        rustix::time::timerfd_settime(&fd, TimerfdTimerFlags::ABSTIME, &spec)?;
        // The descriptor is owned by the `AsyncFd` for as long as it is registered (see
        // `socketcan::open`).
        #[allow(deprecated)]
        let fd = ::tokio::io::unix::AsyncFd::with_interest(fd, ::tokio::io::Interest::READABLE)?;
        let _ready = fd.readable().await?;
        Ok(())
    }
}

#[cfg(target_os = "linux")]
impl Default for TimerfdClock {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(target_os = "linux")]
impl Clock for TimerfdClock {
    // As in `timespec`.
    #[allow(clippy::useless_conversion)]
    fn now(&self) -> Instant {
        let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
        let ns = i128::from(t.tv_sec - self.epoch.tv_sec) * 1_000_000_000
            + (i128::from(t.tv_nsec) - i128::from(self.epoch.tv_nsec));
        Instant::from_micros(u64::try_from(ns / 1000).unwrap_or(0))
    }

    fn sleep_until(&self, deadline: Instant) -> impl Future<Output = ()> {
        let clock = *self;
        async move {
            if clock.timerfd(deadline).await.is_err() {
                clock.tokio.sleep_until(deadline).await;
            }
        }
    }
}

/// The TCP virtual bus (`odc simulate --tcp`, [`crate::transport::tcp`]'s 16-byte records)
/// as the two halves of an async bus.
pub mod tcp {
    use std::io;

    use ::tokio::io::{AsyncReadExt, AsyncWriteExt};
    use ::tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
    use ::tokio::net::{TcpStream, ToSocketAddrs};

    use super::{CanFrame, CanRx, CanTx};
    use crate::transport::tcp::{Decoder, encode};

    /// The sending half.
    #[derive(Debug)]
    pub struct Tx(OwnedWriteHalf);

    /// The receiving half.
    #[derive(Debug)]
    pub struct Rx {
        stream: OwnedReadHalf,
        decoder: Decoder,
        /// Records that were no frame (an 11-bit identifier over 0x7FF, a length over 8):
        /// skipped, counted.
        pub skipped: u64,
    }

    /// Connects to a virtual bus at `addr`.
    ///
    /// # Errors
    ///
    /// The connection's.
    pub async fn connect(addr: impl ToSocketAddrs) -> io::Result<(Tx, Rx)> {
        let stream = TcpStream::connect(addr).await?;
        stream.set_nodelay(true)?;
        Ok(split(stream))
    }

    /// The halves of a connected stream.
    pub fn split(stream: TcpStream) -> (Tx, Rx) {
        let (r, w) = stream.into_split();
        (Tx(w), Rx { stream: r, decoder: Decoder::new(), skipped: 0 })
    }

    impl CanTx for Tx {
        type Error = io::Error;

        async fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
            self.0.write_all(&encode(frame)).await
        }
    }

    impl CanRx for Rx {
        type Error = io::Error;

        async fn recv(&mut self) -> io::Result<CanFrame> {
            let mut buf = [0u8; 256];
            loop {
                while let Some(r) = self.decoder.next_frame() {
                    match r {
                        Ok(f) => return Ok(f),
                        Err(_) => self.skipped += 1,
                    }
                }
                let n = self.stream.read(&mut buf).await?;
                if n == 0 {
                    return Err(io::ErrorKind::UnexpectedEof.into());
                }
                self.decoder.push(buf.get(..n).unwrap_or(&[]));
            }
        }
    }
}

/// A Linux SocketCAN interface (`can0`, `vcan0`) as the two halves of an async bus, on
/// tokio's reactor. CAN error frames are skipped.
#[cfg(all(feature = "socketcan", target_os = "linux"))]
pub mod socketcan {
    use std::io;
    use std::sync::Arc;

    use ::socketcan::{CanSocket, Socket};
    use ::tokio::io::Interest;
    use ::tokio::io::unix::AsyncFd;

    use super::{CanFrame, CanRx, CanTx};

    /// The sending half.
    #[derive(Debug, Clone)]
    pub struct Tx(Arc<AsyncFd<CanSocket>>);

    /// The receiving half.
    #[derive(Debug, Clone)]
    pub struct Rx(Arc<AsyncFd<CanSocket>>);

    /// Opens interface `ifname`, non-blocking, on tokio's reactor.
    ///
    /// # Errors
    ///
    /// When the interface does not exist or the socket cannot be opened.
    pub fn open(ifname: &str) -> io::Result<(Tx, Rx)> {
        let socket = CanSocket::open(ifname)?;
        socket.set_nonblocking(true)?;
        // `AsyncFd::new` is deprecated for sources whose descriptor may be closed while still
        // registered; this one owns its socket, which lives exactly as long as the
        // registration (its replacement, `register`, is `unsafe`, which this crate forbids).
        #[allow(deprecated)]
        let fd = Arc::new(AsyncFd::new(socket)?);
        Ok((Tx(fd.clone()), Rx(fd)))
    }

    impl CanTx for Tx {
        type Error = io::Error;

        async fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
            let f: ::socketcan::CanFrame = frame.to_frame().ok_or_else(|| {
                io::Error::new(io::ErrorKind::InvalidInput, "CAN id too wide for its frame format")
            })?;
            self.0.async_io(Interest::WRITABLE, |s| s.write_frame(&f)).await
        }
    }

    impl CanRx for Rx {
        type Error = io::Error;

        async fn recv(&mut self) -> io::Result<CanFrame> {
            loop {
                match self.0.async_io(Interest::READABLE, |s| s.read_frame()).await? {
                    ::socketcan::CanFrame::Error(_) => {}
                    f => return Ok(CanFrame::from_frame(&f)),
                }
            }
        }
    }
}

/// A socketcand server in raw mode (`odc simulate --socketcand`, socketcand beside a real
/// adapter) as the two halves of an async bus, on the codec of
/// [`crate::transport::socketcand`] (the blocking client's). Raw mode has no syntax for a
/// remote frame: sending one is `InvalidInput`.
#[cfg(feature = "transport-socketcand")]
pub mod socketcand {
    use std::format;
    use std::io;
    use std::string::String;

    use ::tokio::io::{AsyncReadExt, AsyncWriteExt};
    use ::tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
    use ::tokio::net::{TcpStream, ToSocketAddrs};

    use super::{CanFrame, CanRx, CanTx};
    use crate::transport::socketcand::{Element, Splitter, check_channel, format_send, parse};

    /// The sending half.
    #[derive(Debug)]
    pub struct Tx(OwnedWriteHalf);

    /// The receiving half.
    #[derive(Debug)]
    pub struct Rx {
        stream: OwnedReadHalf,
        splitter: Splitter,
        /// Elements received that were no frame (errors, error frames, unknown ones): skipped,
        /// counted.
        pub other: u64,
    }

    /// How long each step of the handshake may take.
    const HANDSHAKE: std::time::Duration = std::time::Duration::from_secs(5);

    /// Connects to `addr`, opens bus `channel` and switches to raw mode (`< hi >`,
    /// `< open CHANNEL >`, `< ok >`, `< rawmode >`, `< ok >`).
    ///
    /// # Errors
    ///
    /// The connection's; `InvalidInput` for a bus name socketcand refuses, `InvalidData` when
    /// the server answers other than the protocol says (its answer in the message),
    /// `TimedOut` when it does not answer within 5 s.
    pub async fn connect(addr: impl ToSocketAddrs, channel: &str) -> io::Result<(Tx, Rx)> {
        check_channel(channel)?;
        let stream = TcpStream::connect(addr).await?;
        stream.set_nodelay(true)?;
        let (r, w) = stream.into_split();
        let (mut tx, mut rx) = (Tx(w), Rx { stream: r, splitter: Splitter::new(), other: 0 });
        rx.expect(&Element::Hi, "the greeting").await?;
        tx.0.write_all(format!("< open {channel} >").as_bytes()).await?;
        rx.expect(&Element::Ok, &format!("< open {channel} >")).await?;
        tx.0.write_all(b"< rawmode >").await?;
        rx.expect(&Element::Ok, "< rawmode >").await?;
        Ok((tx, rx))
    }

    impl Rx {
        /// The next element, as text.
        async fn element(&mut self) -> io::Result<String> {
            let mut buf = [0u8; 1024];
            loop {
                if let Some(e) = self.splitter.next_element() {
                    return e.map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e));
                }
                let n = self.stream.read(&mut buf).await?;
                if n == 0 {
                    return Err(io::ErrorKind::UnexpectedEof.into());
                }
                self.splitter.push(buf.get(..n).unwrap_or(&[]));
            }
        }

        /// Reads the next element and fails unless it is `want`.
        async fn expect(&mut self, want: &Element, after: &str) -> io::Result<()> {
            let element =
                ::tokio::time::timeout(HANDSHAKE, self.element()).await.map_err(|_| {
                    let why = format!("socketcand did not answer {after} within 5 s");
                    io::Error::new(io::ErrorKind::TimedOut, why)
                })??;
            match parse(&element) {
                Ok(e) if e == *want => Ok(()),
                _ => {
                    let why = format!("socketcand answered {after} with `{element}`");
                    Err(io::Error::new(io::ErrorKind::InvalidData, why))
                }
            }
        }
    }

    impl CanTx for Tx {
        type Error = io::Error;

        async fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
            let line =
                format_send(frame).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
            self.0.write_all(line.as_bytes()).await
        }
    }

    impl CanRx for Rx {
        type Error = io::Error;

        /// `Err(UnexpectedEof)` once the server closed the connection, `Err(InvalidData)` for
        /// a `< frame >` that is no frame.
        async fn recv(&mut self) -> io::Result<CanFrame> {
            loop {
                let element = self.element().await?;
                match parse(&element) {
                    Ok(Element::Frame { frame, .. }) => return Ok(frame),
                    Ok(_) => self.other += 1,
                    Err(e) => return Err(io::Error::new(io::ErrorKind::InvalidData, e)),
                }
            }
        }
    }
}
