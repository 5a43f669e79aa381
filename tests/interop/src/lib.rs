//! The Rust side of the python-canopen interop tests: the loopback CAN transport, the python
//! processes, and the generated code of every device under test.
//!
//! Transport: the Rust test listens on 127.0.0.1 (a free port), the Python script connects;
//! each CAN frame is one 16-byte record ([`odc::transport::tcp`], `python/socketbus.py`).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod node_report;
use odc::plan::SdoWrite;
use odc::slave::ObjectDictionary;
use std::io::{self, Read};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use odc::transport::tcp::TcpCan;

/// The python interpreter with `canopen`: `ODC_INTEROP_PYTHON`, else `python3`.
///
/// # Panics
///
/// When it cannot import canopen. The build script looked for it: where it found none (and
/// `ODC_INTEROP_REQUIRED` is not set) the tests that call this are ignored, so a failure here
/// means it is required or went away since the build.
pub fn python() -> PathBuf {
    let py = std::env::var_os("ODC_INTEROP_PYTHON")
        .map_or_else(|| PathBuf::from("python3"), PathBuf::from);
    let ok = Command::new(&py)
        .args(["-c", "import canopen, can"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "{} cannot import canopen and can (set ODC_INTEROP_PYTHON; see tests/interop/README.md)",
        py.display()
    );
    py
}

/// A python script with the loopback bus connected; killed if dropped before it ended.
pub struct Peer {
    child: Child,
    out: Option<JoinHandle<String>>,
    err: Option<JoinHandle<String>>,
    /// The connected bus.
    pub bus: TcpCan,
}

fn drain(r: Option<impl Read + Send + 'static>) -> Option<JoinHandle<String>> {
    r.map(|mut r| {
        std::thread::spawn(move || {
            let mut s = String::new();
            let _ = r.read_to_string(&mut s);
            s
        })
    })
}

impl Peer {
    /// Starts `python/<script>` with `--connect 127.0.0.1:PORT` and `args`, and accepts its
    /// connection (within 30 s, which covers importing canopen on a slow machine).
    pub fn start(python: &Path, script: &str, args: &[&str]) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("python").join(script);
        let mut child = Command::new(python)
            .arg(&script)
            .arg("--connect")
            .arg(format!("127.0.0.1:{port}"))
            .args(args)
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {}: {e}", python.display()));
        let out = drain(child.stdout.take());
        let err = drain(child.stderr.take());
        listener.set_nonblocking(true).unwrap();
        let deadline = Instant::now() + Duration::from_secs(30);
        let stream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                    if Instant::now() > deadline || child.try_wait().unwrap().is_some() {
                        let _ = child.kill();
                        let _ = child.wait();
                        let err = err.map(|h| h.join().unwrap()).unwrap_or_default();
                        panic!("{} did not connect:\n{err}", script.display());
                    }
                    std::thread::sleep(Duration::from_millis(10));
                }
                Err(e) => panic!("accept: {e}"),
            }
        };
        stream.set_nonblocking(false).unwrap();
        Self { child, out, err, bus: TcpCan::new(stream).unwrap() }
    }

    /// Whether the script has ended.
    pub fn exited(&mut self) -> bool {
        self.child.try_wait().unwrap().is_some()
    }

    /// Closes the link, waits for the script (at most `limit`, then kills it) and returns
    /// its stdout and stderr; panics when it failed.
    pub fn finish(mut self, limit: Duration) -> (String, String) {
        let _ = self.bus.shutdown();
        let deadline = Instant::now() + limit;
        let status = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break Some(s);
            }
            if Instant::now() > deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                break None;
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        let out = self.out.take().map(|h| h.join().unwrap()).unwrap_or_default();
        let err = self.err.take().map(|h| h.join().unwrap()).unwrap_or_default();
        match status {
            Some(s) if s.success() => (out, err),
            Some(s) => panic!("python peer failed ({s}):\n{err}\n{out}"),
            None => panic!("python peer killed after {limit:?}:\n{err}\n{out}"),
        }
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// One device under test: its file and the code odc generated for it.
pub struct Device {
    /// Short name for reports.
    pub name: &'static str,
    /// The device file.
    pub path: PathBuf,
    /// The rows of the slave's table (`slave::TABLE`).
    pub entries: &'static [odc::slave::Row],
    /// A fresh slave dictionary (`slave::Dictionary::new`) for a node id.
    pub slave: fn(odc::cob::NodeId) -> Box<dyn ObjectDictionary + Send>,
    /// The master's configuration plan (`master::plan`) for a node id.
    pub plan: fn(odc::cob::NodeId) -> Vec<SdoWrite>,
    /// The default of `od::DEVICE_TYPE`, read through the typed client call.
    pub device_type: &'static odc::Entry<u32>,
}

macro_rules! devices {
    ($($(#[$m:meta])* $module:ident => $path:expr;)*) => {
        $(
            $(#[$m])*
            #[allow(missing_docs, clippy::all)]
            pub mod $module {
                include!(concat!(env!("OUT_DIR"), "/", stringify!($module), ".rs"));
            }
        )*

        /// Every device under test.
        #[allow(clippy::vec_init_then_push)] // pushes under `cfg`, not a `vec![]`
        pub fn devices() -> Vec<Device> {
            let mut v = Vec::new();
            $(
                $(#[$m])*
                v.push(Device {
                    name: stringify!($module),
                    path: $path,
                    entries: $module::slave::TABLE.rows(),
                    slave: |n| Box::new($module::slave::Dictionary::new(n)),
                    plan: |n| $module::master::plan(n).to_vec(),
                    device_type: &$module::od::DEVICE_TYPE,
                });
            )*
            v
        }
    };
}

fn repo(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file)
}

#[cfg(odc_interop_corpus)]
fn corpus(file: &str) -> PathBuf {
    Path::new(env!("ODC_INTEROP_CORPUS")).join(file)
}

devices! {
    lxm23a => repo("eds/lxm23a.eds");
    lexium_mdrive => repo("eds/lexium-mdrive.eds");
    servoone => repo("eds/servoone.eds");
    lenze_e94aycca => repo("eds/lenze-e94aycca.eds");
    linmot_e1200 => repo("eds/linmot-e1200.eds");
    #[cfg(odc_interop_corpus)]
    maxon_epos4 => corpus("eds/maxon__Epos4_70_15.eds");
    #[cfg(odc_interop_corpus)]
    elcom_erio => corpus("eds/elcom__Elcom_e-RIO_8xx_CANopen_Profile.eds");
}

/// The report a python script prints as its last JSON line (its other output is progress).
///
/// # Panics
///
/// When there is none, or it is no JSON: the test fails, showing the output.
pub fn last_json(out: &str) -> serde_json::Value {
    let line = out
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON in:\n{out}"));
    serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"))
}
