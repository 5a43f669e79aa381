//! Whether the tests that need their own network interfaces (a veth pair made with `ip`, as
//! root) can run: `cfg(odc_sim_no_netdev)` when not root and `ODC_NET_REQUIRED` is unset, so
//! they show as ignored with the reason. `.ci/run` sets `ODC_NET_REQUIRED`: there they run,
//! and fail if the machine refuses them. Likewise `cfg(odc_sim_no_corpus)` without the
//! real-world corpus (`ODC_CORPUS`, default `../shared/corpus` beside the repository), whose
//! path reaches the tests as `ODC_SIM_CORPUS`.

include!("../../build-support/probes.rs");

fn main() {
    find_corpus("odc_sim");
    println!("cargo::rustc-check-cfg=cfg(odc_sim_no_netdev)");
    println!("cargo:rerun-if-env-changed=ODC_NET_REQUIRED");
    if std::env::var_os("ODC_NET_REQUIRED").is_none() && !can_make_netdevs() {
        println!("cargo:rustc-cfg=odc_sim_no_netdev");
    }
}
