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
