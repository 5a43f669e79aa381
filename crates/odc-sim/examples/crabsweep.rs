//! The ethercrab sweep of the corpus (#31), run by hand:
//!
//! ```text
//! cargo run --release -p odc-sim --example crabsweep -- [--sample N] [--file SUBSTR] [--out DIR]
//! ```
//!
//! Every ESI device of `$ODC_CORPUS` (default `../shared/corpus`) with a mailbox or process
//! data is simulated and brought up by ethercrab to OP for 1,000 cycles (`tests/crabsweep`);
//! `--sample N` takes N of them spread over the corpus, `--file` those of matching files.
//! Writes `DIR/crabsweep.tsv` (one row a device, default DIR `target/crabsweep`) and prints a
//! summary; the classification of the failures is tests/ethercat-sweep/ethercrab.md.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../tests/crabsweep/mod.rs"]
mod crabsweep;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

fn main() {
    let mut sample = None;
    let mut only = None;
    let mut out = PathBuf::from("target/crabsweep");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--sample" => sample = args.next().and_then(|n| n.parse::<usize>().ok()),
            "--file" => only = args.next(),
            "--out" => out = args.next().map(PathBuf::from).unwrap_or(out),
            _ => {
                eprintln!("usage: crabsweep [--sample N] [--file SUBSTR] [--out DIR]");
                std::process::exit(2);
            }
        }
    }
    let corpus = std::env::var_os("ODC_CORPUS").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
    });
    let all = crabsweep::corpus_devices(&corpus);
    let total = all.len();
    let eligible: Vec<_> = all
        .into_iter()
        .filter(|(f, _, d)| crabsweep::eligible(d) && only.as_ref().is_none_or(|o| f.contains(o)))
        .collect();
    let count = eligible.len();
    let chosen = crabsweep::spread(eligible, sample.unwrap_or(usize::MAX));
    eprintln!(
        "{total} ESI devices, {count} with a mailbox or process data, {} to run",
        chosen.len()
    );
    crabsweep::catch_panics();
    std::fs::create_dir_all(&out).unwrap();
    let path = out.join("crabsweep.tsv");
    let mut tsv = std::fs::File::create(&path).unwrap();
    writeln!(tsv, "{}", crabsweep::Row::HEADER).unwrap();
    let mut rows = Vec::new();
    for (n, (file, index, device)) in chosen.iter().enumerate() {
        let mut row = crabsweep::run(file, *index, device);
        if row.stage != crabsweep::Stage::Done && crabsweep::timed_out(&row) {
            // Once more: the link's thread may not have had a core for 500 ms.
            row = crabsweep::run(file, *index, device);
        }
        writeln!(tsv, "{}", row.tsv()).unwrap();
        if row.stage != crabsweep::Stage::Done {
            eprintln!("[{}/{}] {}", n + 1, chosen.len(), row.tsv());
        }
        rows.push(row);
    }
    let op = rows.iter().filter(|r| r.reached_op()).count();
    let done = rows.iter().filter(|r| r.stage == crabsweep::Stage::Done).count();
    let mut stages = BTreeMap::<String, usize>::new();
    let mut classes = BTreeMap::<&str, usize>::new();
    for r in rows.iter().filter(|r| r.stage != crabsweep::Stage::Done) {
        let error = r.error.split([' ', '(', '{', ':']).next().unwrap_or("");
        *stages.entry(format!("{} AL {:#06x} {error}", r.stage.name(), r.al_code)).or_default() +=
            1;
        *classes.entry(&r.class).or_default() += 1;
    }
    println!("corpus ESI devices: {total}");
    println!("with a mailbox or process data: {count}");
    println!("swept: {}", rows.len());
    println!("reached OP: {op}");
    println!("ran {} cycles at the expected working counter: {done}", crabsweep::CYCLES);
    println!("failures by stage, AL status code and error:");
    for (stage, n) in &stages {
        println!("  {n:5}  {stage}");
    }
    println!("failures by class (tests/ethercat-sweep/ethercrab.md):");
    let mut by_count: Vec<_> = classes.into_iter().collect();
    by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    for (class, n) in by_count {
        println!("  {n:5}  {class}");
    }
    println!("rows: {}", path.display());
}
