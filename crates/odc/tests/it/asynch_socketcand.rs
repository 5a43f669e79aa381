//! The async master's socketcand adapter against a server played by the test, line by line as
//! socketcand's `doc/protocol.md` writes the raw mode: the greeting `< hi >`, `< open can0 >`
//! answered `< ok >`, `< rawmode >` answered `< ok >`; then `< send ID DLC B0 B1 … >` from the
//! client (identifier in hex, the length, each byte in hex) and `< frame ID SECS.USECS DATA >`
//! from the server (the data as one hex string).

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use odc::asynch::tokio::socketcand;
use odc::asynch::{CanRx, CanTx};
use odc::can::CanFrame;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

/// Reads from `s` until `want` has come whole (the client may write it in pieces), within 5 s.
async fn read_exactly(s: &mut TcpStream, want: &str) {
    let mut got = vec![0u8; want.len()];
    let read = tokio::time::timeout(std::time::Duration::from_secs(5), s.read_exact(&mut got));
    read.await.expect("the client wrote it within 5 s").unwrap();
    assert_eq!(String::from_utf8_lossy(&got), want);
}

#[tokio::test]
async fn handshake_send_and_receive_as_the_protocol_writes_them() {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let server = tokio::spawn(async move {
        let (mut s, _) = listener.accept().await.unwrap();
        s.write_all(b"< hi >").await.unwrap();
        read_exactly(&mut s, "< open can0 >").await;
        s.write_all(b"< ok >").await.unwrap();
        read_exactly(&mut s, "< rawmode >").await;
        s.write_all(b"< ok >").await.unwrap();
        // An SDO upload request of 0x1000:00 to node 5, bytes in unpadded hex as the protocol's
        // example (`< send 1AAAAAAA 2 1 f1 >`) and python-can's client write them.
        read_exactly(&mut s, "< send 605 8 40 0 10 0 0 0 0 0 >").await;
        // An element that is no frame is skipped; then the device's heartbeat (pre-operational)
        // and a 29-bit frame.
        s.write_all(b"< error bus off >< frame 705 1700000000.000100 7F >").await.unwrap();
        s.write_all(b"< frame 1ABCDEF0 1700000000.000200 0102 >").await.unwrap();
    });
    let (mut tx, mut rx) = socketcand::connect(addr, "can0").await.unwrap();
    let request = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
    tx.send(&request).await.unwrap();
    assert_eq!(rx.recv().await.unwrap(), CanFrame::from_slice(0x705, &[0x7F]).unwrap());
    let extended = rx.recv().await.unwrap();
    assert_eq!((extended.id(), extended.is_extended()), (0x1ABC_DEF0, true));
    assert_eq!(extended.bytes(), [0x01, 0x02]);
    assert_eq!(rx.other, 1);
    server.await.unwrap();
    // The server closed the connection: the receiving half says so.
    assert_eq!(rx.recv().await.unwrap_err().kind(), std::io::ErrorKind::UnexpectedEof);
}

#[tokio::test]
async fn a_refused_bus_is_an_error_naming_the_answer() {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let server = tokio::spawn(async move {
        let (mut s, _) = listener.accept().await.unwrap();
        s.write_all(b"< hi >").await.unwrap();
        read_exactly(&mut s, "< open vcan9 >").await;
        s.write_all(b"< error could not open bus >").await.unwrap();
    });
    let e = socketcand::connect(addr, "vcan9").await.unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
    assert!(e.to_string().contains("< error could not open bus >"), "{e}");
    server.await.unwrap();
    let e = socketcand::connect(addr, "two words").await.unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
}
