//! Loading a shipped device file as `odc doc` does, named as the repository names it.
#![allow(dead_code, clippy::unwrap_used)]

use std::path::Path;

/// The repository.
pub fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The file (relative to the repository) read and checked, with its overlay.
pub fn load(file: &str) -> odc_pipeline::Loaded {
    let mut options = odc_pipeline::Options::new();
    options.name = Some(file.to_owned());
    odc_pipeline::load(&root().join(file), &options).unwrap()
}

/// The sheet of the one device of a loaded file.
pub fn sheet(loaded: &odc_pipeline::Loaded) -> odc_doc::Sheet {
    let input = odc_doc::Input {
        device: &loaded.devices[0],
        file: &loaded.name,
        sources: Some(&loaded.sources),
        diagnostics: &loaded.diagnostics,
        schemes: &loaded.codegen.scheme,
    };
    odc_doc::sheet(&input)
}
