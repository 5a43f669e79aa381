//! The corpus files of the parse benches: every file of `$ODC_CORPUS/MANIFEST.tsv` (default
//! `../shared` beside the repository) whose kind is one of `kinds`, with its bytes. Empty when
//! there is no corpus: the benches then say so and measure nothing.

use std::path::PathBuf;

pub fn corpus(kinds: &[&str]) -> Vec<(String, Vec<u8>)> {
    let dir = std::env::var_os("ODC_CORPUS").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus"))
    });
    let Ok(manifest) = std::fs::read_to_string(dir.join("MANIFEST.tsv")) else {
        return Vec::new();
    };
    manifest
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut cols = l.split('\t');
            let (file, kind) = (cols.next()?, cols.next()?);
            if !kinds.contains(&kind) {
                return None;
            }
            Some((file.to_owned(), std::fs::read(dir.join(file)).ok()?))
        })
        .collect()
}
