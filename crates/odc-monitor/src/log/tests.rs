//! The readers on lines written by hand after each format's writer; the files other tools
//! write are read in `tests/logs.rs`.

use super::*;

fn can(id: u32, data: &[u8]) -> Frame {
    Frame::Can(CanFrame::from_slice(id, data).unwrap())
}

#[test]
fn formats_are_detected_from_content() {
    assert_eq!(detect(b"(1700000000.000000) can0 185#4006\n"), Some(Format::Candump));
    assert_eq!(detect(b"  can0  185   [2]  40 06\n"), Some(Format::Candump));
    assert_eq!(
        detect(b"date Tue Nov 14 22:13:20 2023\nbase hex  timestamps absolute\n"),
        Some(Format::Asc)
    );
    assert_eq!(detect(b"LOGG\x90\0\0\0"), Some(Format::Blf));
    assert_eq!(detect(&[0xD4, 0xC3, 0xB2, 0xA1, 2, 0]), Some(Format::Pcap));
    assert_eq!(detect(&[0x0A, 0x0D, 0x0D, 0x0A]), Some(Format::Pcap));
    assert_eq!(detect(b"hello world\n"), None);
    assert_eq!(detect(b""), Some(Format::Candump), "an empty log");
    assert_eq!(detect(b"\n\n"), Some(Format::Candump), "an empty log");
}

#[test]
fn candump_lines_of_both_shapes() {
    // log2long's output (can-utils) for `(1700000000.000000) can0 185#4006` and friends.
    let text = "(1700000000.000000)  can0       185   [2]  40 06                     '@.'\n\
                (1700000000.100000)  can0       701   [0]  remote request\n\
                (1700000000.200000)  can0  12345678   [2]  01 02                     '..'\n\
                (1700000000.300000)  can0       123  [12]  11 22 33 44 55 66 77 88 99 AA BB CC\n\
                  can0  TX - -  7FF   [0]  ''\n\
                (1700000000.5) can0 185##3AABB\n";
    let log = read(text.as_bytes(), Format::Candump);
    assert_eq!(log.problems, []);
    let frames: Vec<_> = log.entries.iter().map(|e| e.frame.clone()).collect();
    assert_eq!(frames[0], can(0x185, &[0x40, 0x06]));
    assert_eq!(frames[1], Frame::Can(CanFrame::remote(0x701, 0).unwrap()));
    assert_eq!(frames[2], Frame::Can(CanFrame::extended(0x1234_5678, &[1, 2]).unwrap()));
    let Frame::Fd(f) = &frames[3] else { panic!("{:?}", frames[3]) };
    assert_eq!((f.id, f.data.len(), f.data[11]), (0x123, 12, 0xCC));
    assert_eq!(frames[4], can(0x7FF, &[]));
    assert_eq!(log.entries[4].time, None);
    assert_eq!(
        frames[5],
        Frame::Fd(FdFrame {
            id: 0x185,
            extended: false,
            brs: true,
            esi: true,
            data: vec![0xAA, 0xBB]
        })
    );
    assert_eq!(log.entries[0].time, Some(1_700_000_000.0));
}

#[test]
fn asc_lines_of_python_can_and_log2asc() {
    let text = "date Tue Nov 14 22:13:20 2023\n\
                base hex  timestamps absolute\n\
                no internal events logged\n\
                Begin Triggerblock Tue Nov 14 22:13:20.000 2023\n   0.000000 Start of measurement\n\
                   0.000000 1  185             Rx   d 2 40 06\n\
                   0.100000 1  701             Rx   r 0\n\
                   0.150000 1  701             Rx   r\n\
                   0.200000 1  12345678x       Rx   d 2 01 02\n\
                   0.300000 CANFD   1 Rx        123                                   1 0 9 12 11 22 33 44 55 66 77 88 99 AA BB CC   130000  130     3000 0 0 0 0 0\n\
                   0.350000 CANFD   1 Tx        124  SomeName  0 1 2 2 01 02   0  0  1000 0 0 0 0 0\n\
                   0.400000 1  ErrorFrame\n\
                   0.500000 1  7FF             Tx   d 0\n\
                End TriggerBlock\n";
    let log = read(text.as_bytes(), Format::Asc);
    assert_eq!(log.problems, []);
    let got: Vec<_> = log.entries.iter().map(|e| (e.time.unwrap(), e.frame.clone())).collect();
    assert_eq!(got.len(), 7, "{got:?}");
    assert_eq!(got[0], (0.0, can(0x185, &[0x40, 0x06])));
    assert_eq!(got[1].1, Frame::Can(CanFrame::remote(0x701, 0).unwrap()));
    assert_eq!(got[2].1, Frame::Can(CanFrame::remote(0x701, 0).unwrap()));
    assert_eq!(got[3].1, Frame::Can(CanFrame::extended(0x1234_5678, &[1, 2]).unwrap()));
    let Frame::Fd(f) = &got[4].1 else { panic!() };
    assert_eq!((f.id, f.brs, f.data.len()), (0x123, true, 12));
    let Frame::Fd(f) = &got[5].1 else { panic!() };
    assert_eq!((f.id, f.esi, &f.data[..]), (0x124, true, &[1u8, 2][..]));
    assert_eq!(got[6], (0.5, can(0x7FF, &[])));
    // `base dec`: identifiers and bytes in decimal.
    let log = read(b"base dec\n 1.0 1  389  Rx d 2 64 6\n", Format::Asc);
    assert_eq!(log.entries[0].frame, can(389, &[64, 6]));
}

#[test]
fn bad_records_are_problems_not_panics() {
    let log =
        read(b"(1.0) can0 185#4\n(1.0) can0 185##\n  can0  185   [3]  40 06\n", Format::Candump);
    assert_eq!(log.entries, []);
    let lines: Vec<_> = log.problems.iter().map(|p| p.at).collect();
    assert_eq!(lines, [Location::Line(1), Location::Line(2), Location::Line(3)]);
    let log = read(
        b" 1.0 1  800  Rx d 1 01\n 1.0 1  185  Rx d 9 01\n 1.0 CANFD 1 Rx 123 1 0 f 64 01\n",
        Format::Asc,
    );
    assert_eq!(log.entries, []);
    assert_eq!(log.problems.len(), 3, "{:?}", log.problems);
    let log = read(b"LOGG\x10\0\0\0junkjunk", Format::Blf);
    assert_eq!(log.problems.len(), 1);
    let log = read(b"LOG", Format::Blf);
    assert_eq!(log.problems.len(), 1);
    let log = read(&[0xD4, 0xC3, 0xB2, 0xA1, 2, 0], Format::Pcap);
    assert_eq!(log.problems.len(), 1);
    // Every prefix of a BLF header and object decodes or fails without a panic.
    let mut blf = b"LOGG".to_vec();
    blf.extend_from_slice(&144u32.to_le_bytes());
    blf.resize(144, 0);
    blf.extend_from_slice(b"LOBJ\x10\0\x01\0\x30\0\0\0\x0a\0\0\0");
    blf.resize(200, 0xFF);
    for n in 0..blf.len() {
        let _ = read(&blf[..n], Format::Blf);
    }
}
