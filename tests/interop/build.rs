//! Generates master and slave code for the CANopen devices of `eds/` and for two corpus EDS
//! files (when the corpus is present: `ODC_CORPUS`, default `../shared/corpus` beside the
//! repository), so the interop tests serve and drive exactly what odc generates.
//!
//! Also looks for python-canopen (`ODC_INTEROP_PYTHON`, else `python3`): without it, and
//! without `ODC_INTEROP_REQUIRED`, the tests are compiled with `cfg(odc_interop_no_python)`,
//! which marks them ignored with the reason, so `cargo test` shows that they did not run.

use std::path::{Path, PathBuf};

/// The corpus files, chosen for what they add: a maxon EPOS4 (a real servo drive, 164 objects,
/// Low/HighLimit on many of them) and an Elcom e-RIO I/O module (another vendor and profile,
/// limits, CANopenNode-style dictionary).
const CORPUS: [(&str, &str); 2] = [
    ("maxon_epos4", "eds/maxon__Epos4_70_15.eds"),
    ("elcom_erio", "eds/elcom__Elcom_e-RIO_8xx_CANopen_Profile.eds"),
];

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    println!("cargo::rustc-check-cfg=cfg(odc_interop_corpus)");
    println!("cargo:rerun-if-env-changed=ODC_CORPUS");
    find_python();
    find_vcan();
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in ["lxm23a", "lexium-mdrive", "servoone", "lenze-e94aycca", "linmot-e1200"] {
        config.device(root.join(format!("eds/{name}.eds")));
    }
    let corpus = std::env::var_os("ODC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/corpus"));
    if CORPUS.iter().all(|(_, f)| corpus.join(f).is_file()) {
        for (module, file) in CORPUS {
            config.device(corpus.join(file)).module_name(module);
        }
        println!("cargo:rustc-cfg=odc_interop_corpus");
        println!("cargo:rustc-env=ODC_INTEROP_CORPUS={}", corpus.display());
    }
    // The checker's warnings are not this crate's business (odc check reports them); only
    // the generated code is.
    let out_dir =
        std::env::var_os("OUT_DIR").map(PathBuf::from).ok_or(odc_build::Error::NotInBuildScript)?;
    let output = config.generate()?;
    for path in &output.read {
        println!("{}", odc_build::rerun_line(path));
    }
    for g in &output.generated {
        odc_build::write_if_changed(&out_dir.join(format!("{}.rs", g.module)), g.code.as_bytes())?;
    }
    Ok(())
}

/// Sets `cfg(odc_interop_no_python)` when the python the tests would run cannot import
/// `canopen` and `can`, unless `ODC_INTEROP_REQUIRED` is set (then the tests run and fail,
/// saying so). Looked for again when either variable changes, or the interpreter found (a
/// path) changes or goes away.
fn find_python() {
    println!("cargo::rustc-check-cfg=cfg(odc_interop_no_python)");
    println!("cargo:rerun-if-env-changed=ODC_INTEROP_PYTHON");
    println!("cargo:rerun-if-env-changed=ODC_INTEROP_REQUIRED");
    let py = std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or_else(|| "python3".into());
    let ok = std::process::Command::new(&py)
        .args(["-c", "import canopen, can"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        if Path::new(&py).is_file() {
            println!("cargo:rerun-if-changed={}", Path::new(&py).display());
        }
    } else if std::env::var_os("ODC_INTEROP_REQUIRED").is_none() {
        println!("cargo:rustc-cfg=odc_interop_no_python");
    }
}

/// Sets `cfg(odc_vcan0)` when a SocketCAN interface `vcan0` exists (the node test over
/// SocketCAN runs then, and is shown ignored otherwise). Looked for at every build: an
/// interface comes and goes without any file of the crate changing.
fn find_vcan() {
    println!("cargo::rustc-check-cfg=cfg(odc_vcan0)");
    println!("cargo:rerun-if-changed=/sys/class/net");
    if Path::new("/sys/class/net/vcan0").exists() {
        println!("cargo:rustc-cfg=odc_vcan0");
    }
}
