//! `one-pass eds|esi LIST`: one odc parse of each file of LIST, nothing else, for profilers
//! that run a program once (valgrind's dhat, heaptrack): where odc allocates, and how much.
#![allow(clippy::unwrap_used, clippy::expect_used)]

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (kind, list) = (&args[1], std::fs::read_to_string(&args[2]).expect("LIST"));
    let files: Vec<(String, Vec<u8>)> = list
        .lines()
        .filter(|l| !l.is_empty())
        .map(|p| (p.to_owned(), std::fs::read(p).expect("file")))
        .collect();
    for (name, bytes) in &files {
        let mut s = odc_model::Sources::new();
        match kind.as_str() {
            "eds" => drop(std::hint::black_box(odc_eds::parse(&mut s, name, bytes))),
            _ => drop(std::hint::black_box(odc_esi::parse(&mut s, name, bytes))),
        }
    }
}
