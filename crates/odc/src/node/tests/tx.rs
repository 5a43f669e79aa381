//! Transmit back-pressure: a sender that refuses frames (a full transmit mailbox). The node
//! keeps them in order, offers them again first, and counts what does not fit.

use super::*;
use crate::time::Instant;

fn at(us: u64) -> Instant {
    Instant::from_micros(us)
}

/// A transmit mailbox that takes frames only while `open`.
#[derive(Default)]
struct Mailbox {
    open: bool,
    got: Vec<CanFrame>,
}

impl Mailbox {
    fn send(&mut self, f: CanFrame) -> Result<(), &'static str> {
        if !self.open {
            return Err("mailbox full");
        }
        self.got.push(f);
        Ok(())
    }
}

/// An expedited upload request of 0x1000:0 to the bench's node.
fn read_1000() -> CanFrame {
    data(0x605, &[0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])
}

/// The node's expedited answer of 0x1000:0.
fn answer_1000(d: &Dict) -> CanFrame {
    let mut v = [0u8; 4];
    v.copy_from_slice(&d.get(0x1000, 0)[..4]);
    data(0x585, &[0x43, 0x00, 0x10, 0x00, v[0], v[1], v[2], v[3]])
}

#[test]
fn refused_frames_are_kept_in_order_and_sent_first() {
    let (mut node, mut dict): (Node<32, 4, 4>, _) = (Node::new(NODE), Dict::new());
    let mut mb = Mailbox::default();
    node.start(&mut dict, at(0), &mut |f| mb.send(f));
    assert_eq!((mb.got.len(), node.tx_pending(), node.tx_lost()), (0, 1, 0));
    // An SDO request while the boot-up still waits: the answer queues behind it.
    node.handle(&mut dict, &read_1000(), at(MS), &mut |f| mb.send(f));
    assert_eq!((node.tx_pending(), node.tx_lost()), (2, 0));
    // The mailbox has room again: the next call sends the kept frames first, in order.
    mb.open = true;
    node.poll(&mut dict, at(2 * MS), &mut |f| mb.send(f));
    assert_eq!(mb.got, [data(0x705, &[0x00]), answer_1000(&dict)]);
    assert_eq!((node.tx_pending(), node.tx_lost()), (0, 0));
}

#[test]
fn frames_past_the_queue_are_counted_not_dropped_unseen() {
    let (mut node, mut dict): (Node<32, 4, 4>, _) = (Node::new(NODE), Dict::new());
    let mut mb = Mailbox::default();
    node.start(&mut dict, at(0), &mut |f| mb.send(f));
    for _ in 0..6 {
        node.handle(&mut dict, &read_1000(), at(MS), &mut |f| mb.send(f));
    }
    // 7 frames (boot-up and 6 answers): TX_QUEUE kept, the rest counted.
    assert_eq!(node.tx_pending(), TX_QUEUE);
    assert_eq!(node.tx_lost(), 7 - TX_QUEUE as u32);
    mb.open = true;
    node.poll(&mut dict, at(2 * MS), &mut |f| mb.send(f));
    let answer = answer_1000(&dict);
    assert_eq!(mb.got, [data(0x705, &[0x00]), answer, answer, answer]);
    assert_eq!(node.tx_pending(), 0);
}

#[test]
fn a_sender_that_takes_part_keeps_the_rest() {
    // Room for one frame per call: the queue drains one frame at a time.
    let (mut node, mut dict): (Node<32, 4, 4>, _) = (Node::new(NODE), Dict::new());
    let mut refuse = |_: CanFrame| Err::<(), ()>(());
    node.start(&mut dict, at(0), &mut refuse);
    node.handle(&mut dict, &read_1000(), at(MS), &mut refuse);
    let mut got = Vec::new();
    let mut one = |f: CanFrame| {
        if got.is_empty() {
            got.push(f);
            Ok(())
        } else {
            Err(())
        }
    };
    node.poll(&mut dict, at(2 * MS), &mut one);
    assert_eq!(got, [data(0x705, &[0x00])]);
    assert_eq!(node.tx_pending(), 1);
    // An infallible sender (a `Vec`) takes the rest.
    let mut rest = Vec::new();
    node.poll(&mut dict, at(3 * MS), &mut |f| rest.push(f));
    assert_eq!(rest, [answer_1000(&dict)]);
    assert_eq!((node.tx_pending(), node.tx_lost()), (0, 0));
}
