//! The raw Ethernet endpoint on a veth pair this test makes (and removes): a frame sent on
//! one end as a master sends it comes back on that end worked on and marked, and the frames
//! the endpoint sends itself are not worked on again.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use odc_sim::EthernetEndpoint;
use pnet_datalink::{Channel, Config};

/// A veth pair, removed on drop.
struct Veth {
    a: String,
    b: String,
}

impl Veth {
    fn new(tag: &str) -> Veth {
        let id = std::process::id() % 100_000;
        let (a, b) = (format!("odc{tag}{id}a"), format!("odc{tag}{id}b"));
        ip(&["link", "add", &a, "type", "veth", "peer", "name", &b]);
        let veth = Veth { a, b };
        for end in [&veth.a, &veth.b] {
            ip(&["link", "set", end, "up"]);
        }
        veth
    }
}

impl Drop for Veth {
    fn drop(&mut self) {
        let _ = Command::new("ip").args(["link", "del", &self.a]).status();
    }
}

fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("ip (iproute2) runs");
    assert!(out.status.success(), "ip {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

fn frames_come_back_worked_on_and_marked() {
    let veth = Veth::new("e");
    let mut endpoint = EthernetEndpoint::open(&veth.a).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let stopped = Arc::clone(&stop);
    let server = std::thread::spawn(move || {
        // The "devices": each adds 1 to the working counter of the frame's one datagram.
        endpoint
            .serve(
                |f| {
                    f[28] += 1;
                    true
                },
                || stopped.load(Ordering::Relaxed),
            )
            .unwrap()
    });
    let iface = pnet_datalink::interfaces().into_iter().find(|i| i.name == veth.b).unwrap();
    let config = Config { read_timeout: Some(Duration::from_millis(50)), ..Config::default() };
    let Channel::Ethernet(mut tx, mut rx) = pnet_datalink::channel(&iface, config).unwrap() else {
        panic!("not an Ethernet channel")
    };
    // SOEM's frame: broadcast, source 01:01:01:01:01:01, EtherType 0x88A4, EtherCAT header
    // (length 12, type 1), BRD of 2 bytes at register 0x0000, working counter 0.
    let mut frame = vec![0xFF; 6];
    frame.extend([1, 1, 1, 1, 1, 1, 0x88, 0xA4, 0x0E, 0x10]);
    frame.extend([0x07, 0x2A, 0, 0, 0, 0, 0x02, 0x00, 0, 0, 0, 0, 0, 0]);
    let mut answers = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(5);
    // veth may drop what is sent before both ends are up: send again until answered.
    while answers.is_empty() && Instant::now() < deadline {
        tx.send_to(&frame, None).unwrap().unwrap();
        let until = Instant::now() + Duration::from_millis(200);
        while Instant::now() < until {
            if let Ok(got) = rx.next()
                && got[12..14] == [0x88, 0xA4]
                && got[6] & 0x02 != 0
            {
                answers.push(got.to_vec());
            }
        }
    }
    stop.store(true, Ordering::Relaxed);
    let served = server.join().unwrap();
    let answer = answers.first().expect("an answer within 5 s");
    assert_eq!(answer[6..12], [3, 1, 1, 1, 1, 1], "source MAC marked");
    for a in &answers {
        assert_eq!(a[28], 1, "worked on once, not again when the endpoint sees its own frame");
    }
    assert_eq!(answer[..6], frame[..6]);
    assert_eq!(answer[12..28], frame[12..28]);
    assert!(served.frames >= 1 && served.frames as usize <= answers.len() + 20, "{served:?}");
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[Test {
        name: "frames_come_back_worked_on_and_marked",
        run: frames_come_back_worked_on_and_marked,
        needs: &[Need::Netdevs],
    }])
}
