//! A file run by `odc_tests_support::main` (`harness = false`) is compiled without `--test`, so a
//! `#[test]` function added to it would silently never run. None may have one.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

#[test]
fn no_test_attribute_in_a_file_without_the_standard_harness() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut checked = 0;
    for group in ["crates", "tests", "."] {
        for dir in std::fs::read_dir(root.join(group)).unwrap() {
            let dir = dir.unwrap().path();
            let Ok(manifest) = std::fs::read_to_string(dir.join("Cargo.toml")) else { continue };
            for block in manifest.split("[[test]]").skip(1) {
                let block = block.split("\n[").next().unwrap();
                if !block.contains("harness = false") {
                    continue;
                }
                let name = block
                    .lines()
                    .find_map(|l| l.strip_prefix("name = "))
                    .unwrap()
                    .trim_matches('"');
                let file = dir.join("tests").join(format!("{name}.rs"));
                let text = std::fs::read_to_string(&file).unwrap();
                assert!(
                    !text.contains("#[test]"),
                    "{}: #[test] in a file whose harness is odc_tests_support::main; add the \
                     function to its main() list instead",
                    file.display()
                );
                checked += 1;
            }
        }
    }
    // crates/odc-cli: simulate, sdo_python, simulate_soem; odc-sim: ethercat_ethercrab,
    // ethernet; odc-doc: browser.
    assert!(checked >= 6, "{checked} files checked");
}

/// Each package has at most one integration-test binary on the standard harness (`tests/it/`,
/// or a single `tests/NAME.rs`): every file of `tests/` is a binary of its own that links the
/// package's whole dependency tree, and 83 of them were most of a fresh clone's `cargo test`
/// build and target directory (#33). A new test file goes into `tests/it/` as a module.
#[test]
fn one_standard_harness_test_binary_per_package() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut too_many = Vec::new();
    let mut packages = 0;
    for group in ["crates", "tests", "examples", "."] {
        let dirs = std::fs::read_dir(root.join(group)).unwrap().map(|d| d.unwrap().path());
        for dir in dirs.chain([root.join(group)]) {
            let Ok(manifest) = std::fs::read_to_string(dir.join("Cargo.toml")) else { continue };
            if !manifest.contains("[package]") {
                continue;
            }
            packages += 1;
            let Ok(entries) = std::fs::read_dir(dir.join("tests")) else { continue };
            let mut binaries = Vec::new();
            for entry in entries {
                let path = entry.unwrap().path();
                let name = path.file_stem().unwrap().to_string_lossy().into_owned();
                let own_harness = manifest.split("[[test]]").skip(1).any(|block| {
                    let block = block.split("\n[").next().unwrap();
                    block.contains(&format!("name = \"{name}\""))
                        && block.contains("harness = false")
                });
                let is_binary = (path.extension().is_some_and(|e| e == "rs") && path.is_file())
                    || path.join("main.rs").is_file();
                if is_binary && !own_harness {
                    binaries.push(name);
                }
            }
            if binaries.len() > 1 {
                binaries.sort();
                too_many.push(format!("{}: {}", dir.display(), binaries.join(", ")));
            }
        }
    }
    assert!(packages >= 30, "{packages} packages found");
    assert!(
        too_many.is_empty(),
        "more than one test binary (move them into tests/it/): {too_many:#?}"
    );
}
