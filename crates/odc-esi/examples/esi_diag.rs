//! Prints the diagnostics of ESI files: `cargo run --example esi_diag -- FILE...`.
fn main() {
    for path in std::env::args().skip(1) {
        let Ok(bytes) = std::fs::read(&path) else {
            eprintln!("cannot read {path}");
            continue;
        };
        let mut sources = odc_model::Sources::new();
        let parsed = odc_esi::parse(&mut sources, &path, &bytes);
        print!("{}", odc_model::diag::render_short(&sources, &parsed.diagnostics));
        println!("{path}: {} device(s)", parsed.devices.len());
    }
}
