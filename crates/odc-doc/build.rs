//! Looks for a Chromium for the browser test (`tests/browser.rs`): `ODC_CHROMIUM`, else
//! `chromium`, `chromium-browser` or `google-chrome` on the PATH. Without one, and without
//! `ODC_BROWSER_REQUIRED` (which `.ci/run` sets after installing Debian's `chromium`), the
//! test is compiled with `cfg(odc_doc_no_browser)`: shown ignored, with the reason, by
//! `cargo test`. The EtherCAT page comes from the corpus (`cfg(odc_doc_no_corpus)` likewise).

use std::process::{Command, Stdio};

include!("../../build-support/probes.rs");

fn main() {
    find_corpus("odc_doc");
    println!("cargo::rustc-check-cfg=cfg(odc_doc_no_browser)");
    println!("cargo:rerun-if-env-changed=ODC_CHROMIUM");
    println!("cargo:rerun-if-env-changed=ODC_BROWSER_REQUIRED");
    println!("cargo:rerun-if-env-changed=PATH");
    let candidates: Vec<String> = match std::env::var("ODC_CHROMIUM") {
        Ok(c) => vec![c],
        Err(_) => ["chromium", "chromium-browser", "google-chrome"].map(String::from).to_vec(),
    };
    let found = candidates.into_iter().find(|c| {
        Command::new(c)
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    });
    match found {
        Some(c) => println!("cargo:rustc-env=ODC_DOC_CHROMIUM={c}"),
        None if std::env::var_os("ODC_BROWSER_REQUIRED").is_some() => {
            // The test runs and fails, naming what is missing.
            println!("cargo:rustc-env=ODC_DOC_CHROMIUM=chromium");
        }
        None => println!("cargo:rustc-cfg=odc_doc_no_browser"),
    }
}
