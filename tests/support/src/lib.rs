//! What a test needs of the machine, decided when the test runs rather than by a build script.
//!
//! The library crates are published, and a build script of theirs would probe every user's
//! machine (python, Chromium, `ip`) at each build. Tests that need such a peer use this crate's
//! [`main`] as their harness instead (`harness = false`, through libtest-mimic): a test whose
//! need is missing is reported `ignored` by `cargo test`, with the reason printed above the
//! run. The environment variables `.ci/run` sets (`ODC_INTEROP_REQUIRED`, `ODC_NET_REQUIRED`,
//! `ODC_BROWSER_REQUIRED`) turn a missing peer into a failing test instead.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// Something a test needs of the machine.
#[derive(Clone, Copy, Debug)]
pub enum Need {
    /// The real-world corpus (`ODC_CORPUS`, default `../shared/corpus` beside the repository).
    Corpus,
    /// A python (`ODC_INTEROP_PYTHON`, default `python3`) that imports these modules.
    Python(&'static [&'static str]),
    /// Network interfaces the test makes itself (veth pairs, namespaces): root and iproute2.
    Netdevs,
    /// A headless Chromium (`ODC_CHROMIUM`, else `chromium`, `chromium-browser`, `google-chrome`).
    Chromium,
}

/// One test: its name, its body (fails by panicking, like a `#[test]`), and its needs.
pub struct Test {
    /// The name `cargo test` prints and filters on.
    pub name: &'static str,
    /// The body.
    pub run: fn(),
    /// What it needs of the machine.
    pub needs: &'static [Need],
}

/// Runs `tests` as `cargo test` would, ignoring (with the reason on standard error) those whose
/// needs are missing.
pub fn main(tests: &[Test]) -> ExitCode {
    let args = libtest_mimic::Arguments::from_args();
    let trials = tests
        .iter()
        .map(|t| {
            let why: Vec<String> = t.needs.iter().filter_map(|n| missing(*n)).collect();
            if !why.is_empty() && !args.list {
                eprintln!("ignored {}: {}", t.name, why.join("; "));
            }
            let run = t.run;
            libtest_mimic::Trial::test(t.name, move || {
                run();
                Ok(())
            })
            .with_ignored_flag(!why.is_empty())
        })
        .collect();
    libtest_mimic::run(&args, trials).exit_code()
}

/// Why `need` is missing here, or `None` when it is present or required (then the test runs
/// and fails, naming what is missing).
pub fn missing(need: Need) -> Option<String> {
    match need {
        Need::Corpus => corpus_dir().is_none().then(|| {
            "needs the real-world corpus: set ODC_CORPUS to a directory with MANIFEST.tsv".into()
        }),
        Need::Python(modules) => {
            let import = format!("import {}", modules.join(", "));
            let ok = runs(Command::new(python()).args(["-c", &import]));
            (!ok && !set("ODC_INTEROP_REQUIRED")).then(|| {
                format!(
                    "needs a python with `{import}`: set ODC_INTEROP_PYTHON \
                     (tests/interop/README.md)"
                )
            })
        }
        Need::Netdevs => (!set("ODC_NET_REQUIRED") && !can_make_netdevs()).then(|| {
            "needs network interfaces of its own: root and iproute2's `ip` (or ODC_NET_REQUIRED)"
                .into()
        }),
        Need::Chromium => (find_chromium().is_none() && !set("ODC_BROWSER_REQUIRED"))
            .then(|| "needs a headless Chromium: install `chromium` or set ODC_CHROMIUM".into()),
    }
}

/// The corpus directory. Panics without one: call it only from a test that needs
/// [`Need::Corpus`].
pub fn corpus() -> PathBuf {
    match corpus_dir() {
        Some(d) => d,
        // A test reaches this only when it did not declare Need::Corpus: its own mistake.
        #[allow(clippy::panic)]
        None => panic!("no corpus: set ODC_CORPUS to a directory with MANIFEST.tsv"),
    }
}

/// The python of the interop tests.
pub fn python() -> PathBuf {
    std::env::var_os("ODC_INTEROP_PYTHON").map_or_else(|| "python3".into(), PathBuf::from)
}

/// The Chromium to run; `chromium` when none was found (the test then fails naming it).
pub fn chromium() -> String {
    find_chromium().unwrap_or_else(|| "chromium".into())
}

fn corpus_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("ODC_CORPUS").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"),
        PathBuf::from,
    );
    dir.join("MANIFEST.tsv").is_file().then_some(dir)
}

fn find_chromium() -> Option<String> {
    let candidates: Vec<String> = match std::env::var("ODC_CHROMIUM") {
        Ok(c) => vec![c],
        Err(_) => ["chromium", "chromium-browser", "google-chrome"].map(String::from).to_vec(),
    };
    candidates.into_iter().find(|c| runs(Command::new(c).arg("--version")))
}

fn can_make_netdevs() -> bool {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    root && runs(Command::new("ip").arg("-V"))
}

fn runs(cmd: &mut Command) -> bool {
    cmd.stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
}

fn set(var: &str) -> bool {
    std::env::var_os(var).is_some()
}
