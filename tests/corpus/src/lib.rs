//! The real-world corpus for the tests of this crate: its directory and the files of
//! `MANIFEST.tsv` by kind.
//!
//! The corpus (`ODC_CORPUS`, else `../shared/corpus` beside the repository) is found when the
//! crate is built (`build.rs`). Where there is none, every test is marked ignored with
//! [`NO_CORPUS`]'s reason, written out at each test as
//! `#[cfg_attr(odc_no_corpus, ignore = "...")]` (an attribute takes a literal only).

// Test support: a corpus that cannot be read fails the test that asked for it.
#![allow(clippy::panic)]

use std::path::{Path, PathBuf};

/// Why the tests did not run where there is no corpus: the text of their `ignore` attribute.
pub const NO_CORPUS: &str =
    "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)";

/// The corpus directory found at build time.
///
/// # Panics
///
/// When there was none: the tests that call this are ignored then, so running one anyway
/// (`--ignored`) says why it cannot.
pub fn dir() -> &'static Path {
    let dir = env!("ODC_TESTS_CORPUS");
    assert!(!dir.is_empty(), "{NO_CORPUS}");
    Path::new(dir)
}

/// The files of `MANIFEST.tsv` of the given kinds (`eds`, `dcf`, `esi`, `xdd`), as written
/// there (relative to [`dir`]), in its order.
///
/// # Panics
///
/// When the manifest cannot be read.
pub fn files(kinds: &[&str]) -> Vec<String> {
    let path = dir().join("MANIFEST.tsv");
    let manifest = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    manifest
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut cols = l.split('\t');
            let file = cols.next()?;
            kinds.contains(&cols.next()?).then(|| file.to_owned())
        })
        .collect()
}

/// A file of the corpus by its manifest name.
pub fn path(file: &str) -> PathBuf {
    dir().join(file)
}
