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

/// A pcap file written from the format's description (tcpdump.org, pcap(5)): the global
/// header (magic 0xA1B2C3D4 little-endian, version 2.4, snap length, link type 227), then per
/// packet seconds, microseconds, captured and original length, and the SocketCAN bytes.
fn pcap_by_hand() -> Vec<u8> {
    let mut f = Vec::new();
    f.extend_from_slice(&0xA1B2_C3D4u32.to_le_bytes());
    f.extend_from_slice(&2u16.to_le_bytes());
    f.extend_from_slice(&4u16.to_le_bytes());
    for word in [0u32, 0, 65_535, 227] {
        f.extend_from_slice(&word.to_le_bytes());
    }
    let packets: [(u32, &[u8]); 3] = [
        // 0x185, 2 bytes (ID in network byte order).
        (0x185, &[0x40, 0x06]),
        // 0x701 remote (bit 30), asking for 1 byte.
        (0x4000_0701, &[]),
        // 0x12345678 extended (bit 31).
        (0x9234_5678, &[1, 2]),
    ];
    for (i, (word, data)) in packets.iter().enumerate() {
        let mut p = word.to_be_bytes().to_vec();
        p.push(if *word == 0x4000_0701 { 1 } else { data.len() as u8 });
        p.extend_from_slice(&[0, 0, 0]);
        p.extend_from_slice(data);
        p.resize(16, 0);
        for v in [1_700_000_000u32, 100_000 * i as u32, p.len() as u32, p.len() as u32] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        f.extend_from_slice(&p);
    }
    f
}

/// A pcapng file written from its specification (section header, interface description
/// with link type 227 and no `if_tsresol`: microseconds, one enhanced packet block).
fn pcapng_by_hand() -> Vec<u8> {
    let block = |kind: u32, body: &[u8]| {
        let len = (12 + body.len()) as u32;
        let mut b = kind.to_le_bytes().to_vec();
        b.extend_from_slice(&len.to_le_bytes());
        b.extend_from_slice(body);
        b.extend_from_slice(&len.to_le_bytes());
        b
    };
    let mut shb = 0x1A2B_3C4Du32.to_le_bytes().to_vec();
    shb.extend_from_slice(&1u16.to_le_bytes());
    shb.extend_from_slice(&0u16.to_le_bytes());
    shb.extend_from_slice(&(-1i64).to_le_bytes());
    let mut idb = 227u16.to_le_bytes().to_vec();
    idb.extend_from_slice(&0u16.to_le_bytes());
    idb.extend_from_slice(&0u32.to_le_bytes());
    let mut packet = 0x185u32.to_be_bytes().to_vec();
    packet.extend_from_slice(&[2, 0, 0, 0, 0x40, 0x06, 0, 0, 0, 0, 0, 0]);
    let micros: u64 = 1_700_000_000_500_000;
    let mut epb = 0u32.to_le_bytes().to_vec();
    epb.extend_from_slice(&((micros >> 32) as u32).to_le_bytes());
    epb.extend_from_slice(&(micros as u32).to_le_bytes());
    epb.extend_from_slice(&(packet.len() as u32).to_le_bytes());
    epb.extend_from_slice(&(packet.len() as u32).to_le_bytes());
    epb.extend_from_slice(&packet);
    [block(0x0A0D_0D0A, &shb), block(1, &idb), block(6, &epb)].concat()
}

/// A BLF file after python-can's blf.py: the 144-byte header, one uncompressed container
/// holding one CAN_MESSAGE with a header of version 1 and a time in nanoseconds.
fn blf_by_hand() -> Vec<u8> {
    let mut f = b"LOGG".to_vec();
    f.extend_from_slice(&144u32.to_le_bytes());
    f.resize(40, 0);
    // Start: 2023-11-14 22:13:20.000 UTC (1 700 000 000 s), a SYSTEMTIME.
    for v in [2023u16, 11, 2, 14, 22, 13, 20, 0] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f.resize(144, 0);
    let mut inner = b"LOBJ".to_vec();
    inner.extend_from_slice(&32u16.to_le_bytes());
    inner.extend_from_slice(&1u16.to_le_bytes());
    inner.extend_from_slice(&48u32.to_le_bytes());
    inner.extend_from_slice(&1u32.to_le_bytes());
    inner.extend_from_slice(&2u32.to_le_bytes()); // times in ns
    inner.extend_from_slice(&[0, 0, 0, 0]);
    inner.extend_from_slice(&250_000_000u64.to_le_bytes());
    inner.extend_from_slice(&1u16.to_le_bytes()); // channel 1
    inner.extend_from_slice(&[0, 2]); // flags, DLC
    inner.extend_from_slice(&0x185u32.to_le_bytes());
    inner.extend_from_slice(&[0x40, 0x06, 0, 0, 0, 0, 0, 0]);
    let mut container = b"LOBJ".to_vec();
    container.extend_from_slice(&16u16.to_le_bytes());
    container.extend_from_slice(&1u16.to_le_bytes());
    container.extend_from_slice(&((32 + inner.len()) as u32).to_le_bytes());
    container.extend_from_slice(&10u32.to_le_bytes());
    container.extend_from_slice(&[0; 8]); // method 0, 6 bytes
    container.extend_from_slice(&(inner.len() as u32).to_le_bytes());
    container.extend_from_slice(&[0; 4]);
    container.extend_from_slice(&inner);
    f.extend_from_slice(&container);
    f
}

#[test]
fn binary_files_written_by_hand_from_their_specifications() {
    let pcap = read(&pcap_by_hand(), Format::Pcap);
    assert_eq!(pcap.problems, []);
    let got: Vec<_> = pcap.entries.iter().map(|e| (e.time.unwrap(), e.frame.clone())).collect();
    assert_eq!(
        got,
        [
            (1_700_000_000.0, can(0x185, &[0x40, 0x06])),
            (1_700_000_000.1, Frame::Can(CanFrame::remote(0x701, 1).unwrap())),
            (1_700_000_000.2, Frame::Can(CanFrame::extended(0x1234_5678, &[1, 2]).unwrap())),
        ]
    );
    let ng = read(&pcapng_by_hand(), Format::Pcap);
    assert_eq!(ng.problems, []);
    assert_eq!(
        ng.entries,
        [Entry { time: Some(1_700_000_000.5), frame: can(0x185, &[0x40, 0x06]) }]
    );
    let blf = read(&blf_by_hand(), Format::Blf);
    assert_eq!(blf.problems, []);
    assert_eq!(
        blf.entries,
        [Entry { time: Some(1_700_000_000.25), frame: can(0x185, &[0x40, 0x06]) }]
    );
    assert_eq!(detect(&blf_by_hand()), Some(Format::Blf));
    assert_eq!(detect(&pcapng_by_hand()), Some(Format::Pcap));
}

/// Every prefix of each file, and each file with any one byte changed to 0x00, 0xFF or 0x80,
/// reads without a panic (what a damaged download or a cut capture gives).
#[test]
fn damaged_binary_files_are_problems_not_panics() {
    for (file, format) in [
        (pcap_by_hand(), Format::Pcap),
        (pcapng_by_hand(), Format::Pcap),
        (blf_by_hand(), Format::Blf),
    ] {
        for n in 0..file.len() {
            let _ = read(&file[..n], format);
        }
        for i in 0..file.len() {
            for b in [0x00, 0xFF, 0x80] {
                let mut bad = file.clone();
                bad[i] = b;
                let _ = read(&bad, format);
            }
        }
    }
}
