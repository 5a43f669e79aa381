//! `ModelDictionary` against the `slave::Dictionary` odc generates from the same file, for
//! every CANopen file of `eds/`: the same entries (address, access, type), and for each entry
//! the same upload bytes or abort, and the same answer and stored value for a set of
//! downloads (the value it holds, zeros, all ones, the limits and one past them, one byte too
//! few and too many), on two node-IDs ($NODEID defaults).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::slave::{ObjectDictionary, Row};
use odc_model::{Device, Value};
use odc_sim::ModelDictionary;

mod lxm23a {
    odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave");
}
mod lexium_mdrive {
    odc_macros::include_device!("../../eds/lexium-mdrive.eds", role = "slave");
}
mod servoone {
    odc_macros::include_device!("../../eds/servoone.eds", role = "slave");
}
mod lenze {
    odc_macros::include_device!("../../eds/lenze-e94aycca.eds", role = "slave");
}
mod linmot {
    odc_macros::include_device!("../../eds/linmot-e1200.eds", role = "slave");
}

type Make = fn(odc::cob::NodeId) -> Box<dyn ObjectDictionary>;

fn load(file: &str) -> Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds").join(file);
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

/// `v` as `len` little-endian bytes (two's complement), if it is an integer.
fn int_bytes(v: &Value, delta: i128, len: usize) -> Option<Vec<u8>> {
    let n = match *v {
        Value::Unsigned(u) => i128::from(u),
        Value::Signed(i) => i128::from(i),
        _ => return None,
    } + delta;
    (len <= 8).then(|| n.to_le_bytes()[..len].to_vec())
}

/// Compares the two dictionaries; returns (entries, reads, writes) compared.
fn compare(file: &str, rows: &[Row], generated: Make) -> (usize, usize, usize) {
    let device = load(file);
    let (mut reads, mut writes) = (0, 0);
    for node in [odc::node_id!(5), odc::node_id!(0x41)] {
        let model = ModelDictionary::new(&device, node);
        let ours: Vec<_> = model.entries().collect();
        let theirs: Vec<_> = rows.iter().map(|r| (r.addr(), r.access(), r.data_type())).collect();
        assert_eq!(ours, theirs, "{file}: entries");
        let mut model = model;
        let mut generated = generated(node);
        let mut buf_m = vec![0u8; 4096];
        let mut buf_g = vec![0u8; 4096];
        let mut read_both = |m: &ModelDictionary, g: &dyn ObjectDictionary, i, s, len: usize| {
            let a = m.read(i, s, &mut buf_m[..len]).map(|n| buf_m[..n].to_vec());
            let b = g.read(i, s, &mut buf_g[..len]).map(|n| buf_g[..n].to_vec());
            assert_eq!(a, b, "{file} node {node}: read {i:04X}:{s:02X} into {len} bytes");
            a
        };
        for row in rows {
            let a = row.addr();
            let value = read_both(&model, generated.as_ref(), a.index, a.sub, 4096);
            reads += 1;
            if let Ok(v) = &value
                && !v.is_empty()
            {
                let _ = read_both(&model, generated.as_ref(), a.index, a.sub, v.len() - 1);
                reads += 1;
            }
            // Where the table has no entry: past the sub-index, and the next index.
            for (i, s) in [(a.index, a.sub.wrapping_add(1)), (a.index.wrapping_add(1), 0)] {
                let _ = read_both(&model, generated.as_ref(), i, s, 4096);
                reads += 1;
            }
            let len = value.as_ref().map_or(4, |v| v.len().max(1));
            let sub = device.sub(a.index, a.sub).unwrap();
            let mut candidates = vec![
                value.clone().unwrap_or_default(),
                vec![0; len],
                vec![0xFF; len],
                vec![0x7F; len],
                vec![0x41; len + 1],
                vec![0x20; len - 1],
            ];
            for (limit, delta) in [
                (&sub.low_limit, -1),
                (&sub.low_limit, 0),
                (&sub.high_limit, 0),
                (&sub.high_limit, 1),
            ] {
                if let Some(v) = limit.as_deref().and_then(|l| int_bytes(&l.value, delta, len)) {
                    candidates.push(v);
                }
            }
            for data in candidates {
                let x = model.write(a.index, a.sub, &data);
                let y = generated.write(a.index, a.sub, &data);
                assert_eq!(x, y, "{file} node {node}: write {data:02X?} to {a}");
                writes += 1;
                let _ = read_both(&model, generated.as_ref(), a.index, a.sub, 4096);
                reads += 1;
            }
        }
    }
    (rows.len(), reads, writes)
}

#[test]
fn model_dictionary_agrees_with_the_generated_one() {
    let devices: [(&str, &[Row], Make); 5] = [
        ("lxm23a.eds", lxm23a::slave::TABLE.rows(), |n| {
            Box::new(lxm23a::slave::Dictionary::new(n))
        }),
        ("lexium-mdrive.eds", lexium_mdrive::slave::TABLE.rows(), |n| {
            Box::new(lexium_mdrive::slave::Dictionary::new(n))
        }),
        ("servoone.eds", servoone::slave::TABLE.rows(), |n| {
            Box::new(servoone::slave::Dictionary::new(n))
        }),
        ("lenze-e94aycca.eds", lenze::slave::TABLE.rows(), |n| {
            Box::new(lenze::slave::Dictionary::new(n))
        }),
        ("linmot-e1200.eds", linmot::slave::TABLE.rows(), |n| {
            Box::new(linmot::slave::Dictionary::new(n))
        }),
    ];
    for (file, rows, make) in devices {
        let (entries, reads, writes) = compare(file, rows, make);
        println!("{file}: {entries} entries, {reads} reads and {writes} writes agree (2 node-IDs)");
        assert!(entries > 50, "{file}: {entries} entries");
    }
}
