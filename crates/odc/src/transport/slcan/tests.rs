//! The codec against the examples of the protocol's documents: the LAWICEL CANUSB manual
//! ("ASCII Command Set") and the compatible EasySYNC USB2-F-7x01 user guide (ES_000005,
//! §4.1.5 `Z`, §4.1.10 `t`) and Titan USB-2CAN manual (§8.3.5 `t`, §8.3.6 `r`).

use super::*;
use std::vec;
use std::vec::Vec;

fn decode_all(bytes: &[u8]) -> Vec<Result<Message, DecodeError>> {
    let mut d = Decoder::new();
    bytes.iter().filter_map(|&b| d.push(b)).collect()
}

fn data(id: u32, bytes: &[u8]) -> Message {
    Message::Frame { frame: CanFrame::from_slice(id, bytes).unwrap(), timestamp: None }
}

#[test]
fn the_manuals_examples_decode() {
    // EasySYNC §4.1.10: "t34580123456789ABCDEF": ID 0x345, 8 bytes 01 23 45 67 89 AB CD EF.
    assert_eq!(
        Message::decode(b"t34580123456789ABCDEF"),
        Ok(data(0x345, &[0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF]))
    );
    // EasySYNC §4.1.10: "t4560": ID 0x456, no data.
    assert_eq!(Message::decode(b"t4560"), Ok(data(0x456, &[])));
    // Lawicel: "t1002AA33": ID 0x100, two bytes AA 33.
    assert_eq!(Message::decode(b"t1002AA33"), Ok(data(0x100, &[0xAA, 0x33])));
    // Titan §8.3.5: "t00231199FF": ID 0x002, 11 99 FF.
    assert_eq!(Message::decode(b"t00231199FF"), Ok(data(0x002, &[0x11, 0x99, 0xFF])));
    // Titan §8.3.6: "r0023": a remote frame on 0x002 asking for 3 bytes.
    let rtr = CanFrame::remote(0x002, 3).unwrap();
    assert_eq!(Message::decode(b"r0023"), Ok(Message::Frame { frame: rtr, timestamp: None }));
    // Lawicel: "T12ABCDEF2A1A2": 29-bit ID 0x12ABCDEF, A1 A2.
    let ext = CanFrame::extended(0x12AB_CDEF, &[0xA1, 0xA2]).unwrap();
    assert_eq!(
        Message::decode(b"T12ABCDEF2A1A2"),
        Ok(Message::Frame { frame: ext, timestamp: None })
    );
    // Lawicel: "R12ABCDEF2": a 29-bit remote frame asking for 2 bytes.
    let ext_rtr = CanFrame::remote_extended(0x12AB_CDEF, 2).unwrap();
    assert_eq!(
        Message::decode(b"R12ABCDEF2"),
        Ok(Message::Frame { frame: ext_rtr, timestamp: None })
    );
    // The commands.
    assert_eq!(Message::decode(b"O"), Ok(Message::Open));
    assert_eq!(Message::decode(b"L"), Ok(Message::ListenOnly));
    assert_eq!(Message::decode(b"C"), Ok(Message::Close));
    assert_eq!(Message::decode(b"S6"), Ok(Message::Bitrate(Bitrate::K500)));
    assert_eq!(Message::decode(b"Z1"), Ok(Message::Timestamps(true)));
    assert_eq!(Message::decode(b"V1013"), Ok(Message::VersionIs(*b"1013")));
    assert_eq!(Message::decode(b"NA123"), Ok(Message::SerialNumberIs(*b"A123")));
    assert_eq!(Message::decode(b"F00"), Ok(Message::StatusIs(0)));
    assert_eq!(Message::decode(b"z"), Ok(Message::Sent { extended: false }));
    assert_eq!(Message::decode(b"Z"), Ok(Message::Sent { extended: true }));
}

#[test]
fn time_stamps_are_four_more_digits() {
    // EasySYNC §4.1.5: with Z1, 4 hex digits of milliseconds (0x0000-0xEA5F) follow the data.
    let f = CanFrame::from_slice(0x705, &[0x05]).unwrap();
    assert_eq!(
        Message::decode(b"t705105EA5F"),
        Ok(Message::Frame { frame: f, timestamp: Some(0xEA5F) })
    );
    let line = Message::Frame { frame: f, timestamp: Some(1234) }.encode();
    assert_eq!(line.as_bytes(), b"t70510504D2\r");
    // A remote frame has its time stamp right after the length.
    let rtr = CanFrame::remote(0x705, 1).unwrap();
    assert_eq!(
        Message::decode(b"r70510010"),
        Ok(Message::Frame { frame: rtr, timestamp: Some(0x10) })
    );
    // A time stamp wraps each minute when written.
    let line = Message::Frame { frame: f, timestamp: Some(60_001) }.encode();
    assert_eq!(line.as_bytes(), b"t7051050001\r");
}

#[test]
fn encoding_is_the_manuals_spelling() {
    let ext = CanFrame::extended(0x12AB_CDEF, &[0xA1, 0xA2]).unwrap();
    assert_eq!(
        Message::Frame { frame: ext, timestamp: None }.encode().as_bytes(),
        b"T12ABCDEF2A1A2\r"
    );
    let rtr = CanFrame::remote(0x002, 3).unwrap();
    assert_eq!(Message::Frame { frame: rtr, timestamp: None }.encode().as_bytes(), b"r0023\r");
    let longest = CanFrame::extended(0x1FFF_FFFF, &[0xFF; 8]).unwrap();
    let line = Message::Frame { frame: longest, timestamp: Some(0xEA5F) }.encode();
    assert_eq!(line.as_bytes().len(), MAX_LINE);
    assert_eq!(Message::Bitrate(Bitrate::K125).encode().as_bytes(), b"S4\r");
    assert_eq!(Message::Open.encode().as_bytes(), b"O\r");
    assert_eq!(Message::Close.encode().as_bytes(), b"C\r");
    assert_eq!(Message::Timestamps(false).encode().as_bytes(), b"Z0\r");
    assert_eq!(Message::Ok.encode().as_bytes(), b"\r");
    assert_eq!(Message::Sent { extended: false }.encode().as_bytes(), b"z\r");
    assert_eq!(Message::Error.encode().as_bytes(), b"\x07");
    assert_eq!(Message::StatusIs(0x08).encode().as_bytes(), b"F08\r");
    assert_eq!(Message::VersionIs(*b"1013").encode().as_bytes(), b"V1013\r");
}

#[test]
fn every_message_reads_back() {
    let messages = [
        data(0x000, &[0x01, 0x05]),
        data(0x7FF, &[]),
        Message::Frame { frame: CanFrame::extended(0, &[1; 8]).unwrap(), timestamp: Some(59_999) },
        Message::Frame { frame: CanFrame::remote_extended(0x1234, 8).unwrap(), timestamp: None },
        Message::Open,
        Message::ListenOnly,
        Message::Close,
        Message::Timestamps(true),
        Message::Version,
        Message::SerialNumber,
        Message::Status,
        Message::StatusIs(0xFF),
        Message::SerialNumberIs(*b"0DC1"),
        Message::Ok,
        Message::Sent { extended: true },
        Message::Error,
    ];
    let mut bytes = Vec::new();
    for m in &messages {
        bytes.extend_from_slice(m.encode().as_bytes());
    }
    for code in 0..=8 {
        let b = Bitrate::from_code(code).unwrap();
        assert_eq!(
            Message::decode(Message::Bitrate(b).encode().as_bytes().strip_suffix(b"\r").unwrap()),
            Ok(Message::Bitrate(b))
        );
    }
    let want: Vec<_> = messages.iter().copied().map(Ok).collect();
    assert_eq!(decode_all(&bytes), want);
}

#[test]
fn bit_rates_are_lawicels() {
    assert_eq!(Bitrate::from_bits_per_second(10_000), Some(Bitrate::K10));
    assert_eq!(Bitrate::from_bits_per_second(500_000).map(Bitrate::code), Some(6));
    assert_eq!(Bitrate::from_bits_per_second(800_000).map(Bitrate::code), Some(7));
    // python-can's name for S7.
    assert_eq!(Bitrate::from_bits_per_second(750_000).map(Bitrate::code), Some(7));
    assert_eq!(Bitrate::from_bits_per_second(1_000_000).map(Bitrate::code), Some(8));
    assert_eq!(Bitrate::from_bits_per_second(83_300), None);
    assert_eq!(Bitrate::from_code(9), None);
    assert_eq!(Bitrate::K250.bits_per_second(), 250_000);
}

#[test]
fn bad_lines_are_errors_not_panics() {
    assert_eq!(Message::decode(b"t80000"), Err(DecodeError::Syntax(b't')), "11-bit ID 0x800");
    assert_eq!(Message::decode(b"T200000000"), Err(DecodeError::Syntax(b'T')), "ID over 29 bits");
    assert_eq!(Message::decode(b"t1009"), Err(DecodeError::Syntax(b't')), "length 9");
    assert_eq!(Message::decode(b"t1002AA"), Err(DecodeError::Syntax(b't')), "one byte short");
    assert_eq!(Message::decode(b"t1002AA3"), Err(DecodeError::Syntax(b't')), "odd digits");
    assert_eq!(Message::decode(b"t1001GG"), Err(DecodeError::Syntax(b't')), "not hex");
    assert_eq!(Message::decode(b"t10"), Err(DecodeError::Syntax(b't')), "cut short");
    assert_eq!(Message::decode(b"t1001AAFFFFF"), Err(DecodeError::Syntax(b't')), "5-digit stamp");
    assert_eq!(Message::decode(b"t1000FFFF"), Err(DecodeError::Syntax(b't')), "stamp over 0xEA5F");
    assert_eq!(Message::decode(b"S9"), Err(DecodeError::Syntax(b'S')));
    assert_eq!(Message::decode(b"O1"), Err(DecodeError::Syntax(b'O')));
    assert_eq!(Message::decode(b"Z2"), Err(DecodeError::Syntax(b'Z')));
    assert_eq!(Message::decode(b"F1FF"), Err(DecodeError::Syntax(b'F')));
    assert_eq!(Message::decode(b"Q"), Err(DecodeError::Unknown(b'Q')));
    // Every byte string of up to 3 bytes from a small alphabet decodes or errs.
    let alphabet = b"tTrRSOLCZzVNF0189AFg";
    for &a in alphabet {
        for &b in alphabet {
            for &c in alphabet {
                let _ = Message::decode(&[a, b, c]);
            }
        }
    }
}

#[test]
fn the_decoder_splits_and_recovers() {
    // A line feed after the carriage return is skipped; BEL is a message of its own.
    let got = decode_all(b"t1000\r\n\x07z\r");
    assert_eq!(
        got,
        [Ok(data(0x100, &[])), Ok(Message::Error), Ok(Message::Sent { extended: false })]
    );
    // An overlong line is one error, and the next line decodes.
    let mut bytes = vec![b't'; 100];
    bytes.extend_from_slice(b"\rO\r");
    assert_eq!(decode_all(&bytes), [Err(DecodeError::TooLong), Ok(Message::Open)]);
}
