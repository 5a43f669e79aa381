//! Generates the code of a real device of the repository (`eds/lxm23a.eds`, the one in `eds/`
//! whose default PDO mappings carry data) for the pack/unpack comparison.

use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    odc_build::Config::new().device(root.join("eds/lxm23a.eds")).compile()
}
