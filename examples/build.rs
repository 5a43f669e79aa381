//! Generates the code of the device files the examples drive (role both: the master side for
//! the controller, the slave side for the simulated drive), each with its overlay; and the
//! master side of the EtherCAT devices of the ethercrab examples: `esi/servoone.xml`, and the
//! Beckhoff EM2042 of the corpus (its ESI is not in the repository: where no corpus is found,
//! `cfg(odc_no_corpus)` is set and that example says so when run).

use std::path::{Path, PathBuf};

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in
        ["eds/lxm23a.eds", "eds/lexium-mdrive.eds", "eds/servoone.eds", "eds/linmot-e1200.eds"]
    {
        config.device(root.join(name));
    }
    config.compile()?;

    println!("cargo::rustc-check-cfg=cfg(odc_no_corpus)");
    println!("cargo::rerun-if-env-changed=ODC_CORPUS");
    let mut ethercat = odc_build::Config::new();
    ethercat.role(odc_build::Role::Master);
    ethercat.device(root.join("esi/servoone.xml")).module_name("servoone_ecat");
    let corpus = std::env::var_os("ODC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/corpus"));
    let em2042 = corpus.join("esi/beckhoff__Beckhoff_EM2xxx.xml");
    if em2042.is_file() {
        ethercat.device(em2042).module_name("em2042");
    } else {
        println!("cargo::rustc-cfg=odc_no_corpus");
    }
    ethercat.compile()
}
