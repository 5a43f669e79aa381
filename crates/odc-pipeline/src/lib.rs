//! The one way from a device file to a checked model, shared by every odc driver: the `odc`
//! commands, `odc-build`, `include_device!` and the test harnesses.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let options = odc_pipeline::Options::new().level("F108", odc_pipeline::Level::Warn);
//! let loaded = odc_pipeline::load("eds/lxm23a.eds".as_ref(), &options)?;
//! loaded.gate()?; // refused when a diagnostic is at error level
//! let device = loaded.device()?;
//! let code = loaded.generate(device, odc_pipeline::Role::Both, "::odc");
//! # let _ = code;
//! # Ok(())
//! # }
//! ```
//!
//! [`load`] reads the file (EDS/DCF; ESI or XDD/XDC by extension or a first non-blank `<`, the
//! two told apart by the root element, see [`is_xdd`]), finds its
//! overlay (`<stem>.odc.toml` beside it, else `odc.toml` in its directory), builds the
//! checker's configuration (the overlay's, or `--config`, then the command-line levels and
//! `--strict`), applies it to the front-end's diagnostics, runs the checks on every selected
//! device and gives back the model, the diagnostics and every file it read.
//!
//! # The error gate
//!
//! A file is refused when, after the overlay and the command-line levels, a diagnostic is at
//! error level; warnings are reported and do not stop anything. [`Loaded::gate`] is that rule,
//! and its [`Refused`] error says in one line how to go on. A value the front-end could not
//! read as its type (`F107`, `F108`) is kept as written in the model, so that `odc convert`
//! loses nothing, and is left out of generated code: allowing the rule lets generation go on
//! without that value.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod select;

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use odc_model::{Device, Diagnostic, Registry, Severity, Sources, diag};
use sha2::{Digest, Sha256};

pub use odc_check::{Config as CheckConfig, Level, UnknownRule};
pub use odc_codegen::{self, Role};
pub use select::{Select, list_devices};

/// How a device file is loaded and checked: one type for the command line, the build API and
/// the macro.
#[derive(Clone, Debug)]
pub struct Options {
    /// A checker configuration file (`odc.toml` form) used instead of the overlay's checker
    /// settings (`--config`). The overlay's schemes still apply.
    pub config_file: Option<PathBuf>,
    /// A checker configuration used instead of the overlay's (`odc_build::Config::check_config`);
    /// its names are then resolved in [`registry`] (make it with [`check_config`] to set levels
    /// of front-end codes).
    pub check: Option<CheckConfig>,
    /// Levels by rule code, rule name or group, applied in order after the configuration
    /// (`-A`, `-W`, `-D`).
    pub levels: Vec<(String, Level)>,
    /// Warnings become errors (`--strict`).
    pub strict: bool,
    /// Which devices of the file to keep and check.
    pub select: Select,
    /// Whether to compute the device file's SHA-256 ([`Loaded::sha256`]), which generated code
    /// names; a command that generates nothing (`odc check`) turns it off.
    pub source_hash: bool,
    /// How diagnostics and refusals name the file; default: the path as given. A macro names
    /// it as the user wrote it, not by the absolute path it reads.
    pub name: Option<String>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            config_file: None,
            check: None,
            levels: Vec::new(),
            strict: false,
            select: Select::All,
            source_hash: true,
            name: None,
        }
    }
}

impl Options {
    /// Every device, the overlay's settings, no levels of its own.
    pub fn new() -> Options {
        Options::default()
    }

    /// Sets a rule's, a group's or `all` rules' level on top of the configuration.
    pub fn level(mut self, rule_or_group: impl Into<String>, level: Level) -> Options {
        self.levels.push((rule_or_group.into(), level));
        self
    }

    /// Turns warnings into errors.
    pub fn strict(mut self, on: bool) -> Options {
        self.strict = on;
        self
    }

    /// Picks the devices to keep.
    pub fn select(mut self, select: Select) -> Options {
        self.select = select;
        self
    }
}

/// Why a file could not be loaded at all (its content's problems are diagnostics instead).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// An overlay or `--config` file is not valid.
    #[error("invalid overlay {}: {message}", path.display())]
    Overlay {
        /// The overlay file.
        path: PathBuf,
        /// What is wrong, with its position.
        message: String,
    },
    /// A level was set for a rule or group that does not exist.
    #[error(transparent)]
    UnknownRule(#[from] UnknownRule),
    /// The device selection matches no device, or more than one where one is needed.
    #[error("{}: {message}", path.display())]
    Select {
        /// The device file.
        path: PathBuf,
        /// What did not match, with the devices the file describes.
        message: String,
    },
}

/// A device file read and checked.
pub struct Loaded {
    /// The device file, as given.
    pub path: PathBuf,
    /// How diagnostics name it ([`Options::name`]).
    pub name: String,
    /// The source text of every file, for rendering diagnostics.
    pub sources: Sources,
    /// The selected devices (one for EDS/DCF, one per selected `<Device>` of an ESI; none when
    /// the file could not be read as a device description).
    pub devices: Vec<Device>,
    /// Front-end and checker diagnostics at their configured levels, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
    /// Every file read: the device file, the overlay, the `--config` file.
    pub read: Vec<PathBuf>,
    /// The overlay that applied, if any.
    pub overlay: Option<PathBuf>,
    /// What the overlay adds to generated code.
    pub codegen: odc_codegen::Overlay,
    /// The checker's configuration that applied (overlay or `--config`, then the levels), for
    /// a command that checks a device it derives from the file (`odc convert` of an ESI).
    pub config: CheckConfig,
    /// SHA-256 of the device file's bytes, lower-case hex; empty when
    /// [`Options::source_hash`] was off.
    pub sha256: String,
}

/// A file refused by the error gate: how many errors, of which rules, and how to go on.
#[derive(Debug, Clone)]
pub struct Refused {
    /// The device file.
    pub path: PathBuf,
    /// The number of error-level diagnostics.
    pub errors: usize,
    /// Their codes, each once, in order of first appearance.
    pub codes: Vec<&'static str>,
    /// The overlay where an allowance would go: the one that applied, else `<stem>.odc.toml`.
    pub overlay: PathBuf,
}

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.errors;
        let plural = if n == 1 { "" } else { "s" };
        write!(f, "{}: refused: {n} error{plural}", self.path.display())?;
        // The first code a level can be set for (generator codes cannot be allowed) and
        // that is worth allowing: a file that is not well-formed is not advised around.
        let allowable = |c: &&&str| registry().get(c).is_some() && !UNREADABLE.contains(*c);
        match self.codes.iter().find(allowable) {
            Some(first) => write!(
                f,
                " ({}); fix the file, or allow a rule: `{first} = \"allow\"` under [rules] in \
                 {} (on the command line `-A {first}`)",
                self.codes.join(", "),
                self.overlay.display()
            ),
            None if self.codes.iter().any(|c| UNREADABLE.contains(c)) => write!(
                f,
                " ({}); the file cannot be read as a device description: fix it",
                self.codes.join(", ")
            ),
            None => write!(f, " ({})", self.codes.join(", ")),
        }
    }
}

/// The front-ends' codes for a file that cannot be read as it stands (not well-formed, wrong
/// encoding, over a limit, not the format at all): allowing them only hides what was lost, so
/// a refusal does not suggest it.
const UNREADABLE: &[&str] = &[
    odc_esi::codes::UNSUPPORTED_ENCODING,
    odc_esi::codes::MALFORMED_XML,
    odc_esi::codes::INVALID_UTF8,
    odc_esi::codes::DEPTH_LIMIT,
    odc_esi::codes::SIZE_LIMIT,
    odc_esi::codes::NOT_ETHERCATINFO,
    odc_xdd::codes::UNSUPPORTED_ENCODING,
    odc_xdd::codes::MALFORMED_XML,
    odc_xdd::codes::DEPTH_LIMIT,
    odc_xdd::codes::SIZE_LIMIT,
    odc_xdd::codes::NOT_XDD,
];

impl std::error::Error for Refused {}

impl Loaded {
    /// The error-level diagnostics.
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| d.is_error())
    }

    /// The warnings (not the notes).
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| d.severity == Severity::Warning)
    }

    /// The error gate: `Ok` when no diagnostic is at error level.
    ///
    /// # Errors
    ///
    /// [`Refused`], naming the codes and where to allow them.
    pub fn gate(&self) -> Result<(), Refused> {
        self.refuse(&self.diagnostics)
    }

    /// The error gate over other diagnostics of this file (say, those of a device derived from
    /// it): `Ok` when none is at error level.
    ///
    /// # Errors
    ///
    /// [`Refused`], naming the codes and where to allow them.
    pub fn refuse(&self, diagnostics: &[Diagnostic]) -> Result<(), Refused> {
        let mut codes = Vec::new();
        let mut errors = 0;
        for d in diagnostics.iter().filter(|d| d.is_error()) {
            errors += 1;
            if !codes.contains(&d.code) {
                codes.push(d.code);
            }
        }
        if errors == 0 {
            return Ok(());
        }
        // Both named as the file is: where an allowance would go, the overlay that applied,
        // else `<stem>.odc.toml` beside the file.
        let name = Path::new(&self.name);
        let [beside, _] = overlay_candidates(name);
        let overlay = match self.overlay.as_deref().and_then(Path::file_name) {
            Some(file) => name.with_file_name(file),
            None => beside,
        };
        Err(Refused { path: name.to_path_buf(), errors, codes, overlay })
    }

    /// The error gate for a driver that reports in text (build script, macro): the error-level
    /// diagnostics rendered like rustc's, then the refusal's line.
    ///
    /// # Errors
    ///
    /// That report, when a diagnostic is at error level.
    pub fn gate_report(&self) -> Result<(), String> {
        self.gate().map_err(|refused| {
            let errors: Vec<Diagnostic> = self.errors().cloned().collect();
            format!("{}error: {refused}\n", self.render(&errors))
        })
    }

    /// The one device a command works on.
    ///
    /// # Errors
    ///
    /// [`Error::Select`] when the file has none or several selected devices.
    pub fn device(&self) -> Result<&Device, Error> {
        match self.devices.as_slice() {
            [one] => Ok(one),
            [] => Err(self.select_error("the file describes no device".into())),
            many => Err(self.select_error(format!(
                "the file describes {} devices; choose one with --device PRODUCT[:REVISION] or a name:\n{}",
                many.len(),
                list_devices(many)
            ))),
        }
    }

    fn select_error(&self, message: String) -> Error {
        Error::Select { path: PathBuf::from(&self.name), message }
    }

    /// The device file's name without its directory, as generated code names its source.
    pub fn file_name(&self) -> String {
        self.path
            .file_name()
            .map_or_else(|| self.path.display().to_string(), |n| n.to_string_lossy().into_owned())
    }

    /// Generates Rust for `device` (one of [`Loaded::devices`]) with the overlay's schemes and
    /// process data.
    ///
    /// # Errors
    ///
    /// The generator's diagnostics (invalid scheme, runtime path, …).
    pub fn generate(
        &self,
        device: &Device,
        role: Role,
        runtime_path: &str,
    ) -> Result<String, Vec<Diagnostic>> {
        let opts = odc_codegen::Options {
            role,
            runtime_path: runtime_path.to_string(),
            source_name: self.file_name(),
            source_sha256: self.sha256.clone(),
            overlay: self.codegen.clone(),
        };
        odc_codegen::generate(device, &opts)
    }

    /// Diagnostics rendered like rustc's.
    pub fn render(&self, diags: &[Diagnostic]) -> String {
        diag::render_human(&self.sources, diags, false)
    }
}

/// A device file's bytes lowered by its front-end.
#[derive(Debug, Default)]
pub struct Parsed {
    /// The devices (none when the file could not be read as one).
    pub devices: Vec<Device>,
    /// The front-end's diagnostics, at their default levels.
    pub diagnostics: Vec<Diagnostic>,
}

/// Lowers a device file's bytes with the front-end its format needs ([`is_xml`]); `name` is
/// how diagnostics name the file.
pub fn parse(sources: &mut Sources, name: &str, path: &Path, bytes: Vec<u8>) -> Parsed {
    if is_xdd(path, &bytes) {
        let parsed = odc_xdd::parse_vec(sources, name, bytes);
        Parsed { devices: parsed.device.into_iter().collect(), diagnostics: parsed.diagnostics }
    } else if is_xml(path, &bytes) {
        let parsed = odc_esi::parse_vec(sources, name, bytes);
        Parsed { devices: parsed.devices, diagnostics: parsed.diagnostics }
    } else {
        let parsed = odc_eds::parse(sources, name, &bytes);
        // A file too large to read describes no device (as an unreadable ESI): checking the
        // empty model would only add noise.
        let read = !parsed.diagnostics.iter().any(|d| d.code == odc_eds::codes::SIZE_LIMIT);
        Parsed {
            devices: if read { vec![parsed.device] } else { Vec::new() },
            diagnostics: parsed.diagnostics,
        }
    }
}

/// Applies `config` to the front-end's diagnostics and runs the checks on every device: the
/// diagnostics of a parsed file at their configured levels, sorted.
pub fn check(
    devices: &[Device],
    front_end: Vec<Diagnostic>,
    config: &CheckConfig,
) -> Vec<Diagnostic> {
    let empty = Device::default();
    // The front-end's diagnostics are the file's, whichever device they concern; the first
    // device only serves to find the EDS section a diagnostic lies in.
    let first = devices.first().unwrap_or(&empty);
    let mut all = config.apply(first, front_end);
    for device in devices {
        all.extend(odc_check::check(device, config));
    }
    diag::sort(&mut all);
    all
}

/// Reads, selects and checks a device file (see the crate documentation).
///
/// # Errors
///
/// [`Error`] when a file cannot be read, the overlay or `--config` is invalid, a level names
/// no rule, or the selection matches no device. Problems in the device file's content are
/// diagnostics in [`Loaded::diagnostics`], never errors here.
pub fn load(path: &Path, options: &Options) -> Result<Loaded, Error> {
    let bytes =
        read_device_file(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    load_bytes(path, bytes, options)
}

/// [`load`] of a device file already read (standard input, or a file a caller looked at
/// first): `path` names it in diagnostics, decides the format by its extension when it has
/// one, and is where the overlay is looked for.
///
/// # Errors
///
/// As [`load`], but for the device file's own reading.
pub fn load_bytes(path: &Path, bytes: Vec<u8>, options: &Options) -> Result<Loaded, Error> {
    let mut read = vec![path.to_path_buf()];
    let overlay_path = overlay_path(path);
    let overlay = match &overlay_path {
        Some(p) => {
            read.push(p.clone());
            Some(read_overlay(p)?)
        }
        None => None,
    };
    let mut config = match (&options.check, &options.config_file) {
        (Some(config), _) => config.clone().with_registry(registry()),
        (None, Some(file)) => {
            read.push(file.clone());
            read_overlay(file)?.check
        }
        (None, None) => overlay.as_ref().map_or_else(check_config, |o| o.check.clone()),
    };
    for (rule, level) in &options.levels {
        config.set_level(rule, *level)?;
    }
    if options.strict {
        config.strict(true);
    }
    let mut sources = Sources::new();
    let sha256 = if options.source_hash { sha256_hex(&bytes) } else { String::new() };
    let name = options.name.clone().unwrap_or_else(|| path.display().to_string());
    let parsed = parse(&mut sources, &name, path, bytes);
    // A file read as no device has nothing to select: its diagnostics say why.
    let devices = if parsed.devices.is_empty() {
        parsed.devices
    } else {
        let select = options.select.apply(parsed.devices);
        select.map_err(|message| Error::Select { path: PathBuf::from(&name), message })?
    };
    let diagnostics = check(&devices, parsed.diagnostics, &config);
    Ok(Loaded {
        path: path.to_path_buf(),
        name,
        sources,
        devices,
        diagnostics,
        read,
        overlay: overlay_path,
        codegen: overlay.map(|o| o.codegen).unwrap_or_default(),
        config,
        sha256,
    })
}

/// Every diagnostic code odc can emit: the front-ends' (`F1xx` EDS/DCF, `F2xx` ESI, `F3xx`
/// XDD/XDC), the
/// checker's (`C`, `D`, `T`) and the code generator's (`G6xx`). `odc explain`, `odc lints`,
/// overlays and `-A/-W/-D` name rules in it.
pub fn registry() -> Registry {
    static REGISTRY: OnceLock<Registry> = OnceLock::new();
    REGISTRY
        .get_or_init(|| {
            Registry::new(
                (odc_check::RULES.iter().map(|r| &r.info))
                    .chain(odc_eds::RULES)
                    .chain(odc_esi::RULES)
                    .chain(odc_xdd::RULES)
                    .chain(odc_codegen::RULES),
            )
        })
        .clone()
}

/// An empty checker configuration that names rules in [`registry`] (every code), for
/// [`Options::check`] and `odc_build::Config::check_config`.
pub fn check_config() -> CheckConfig {
    CheckConfig::in_registry(registry())
}

/// The places a device file's overlay may be, in the order they are tried: `<stem>.odc.toml`
/// beside the file, then `odc.toml` in its directory.
pub fn overlay_candidates(file: &Path) -> [PathBuf; 2] {
    let dir = file.parent().unwrap_or(Path::new(""));
    let mut beside = file.file_stem().map(|s| s.to_os_string()).unwrap_or_default();
    beside.push(".odc.toml");
    [dir.join(beside), dir.join("odc.toml")]
}

/// The overlay of a device file, if one exists (see [`overlay_candidates`]).
pub fn overlay_path(file: &Path) -> Option<PathBuf> {
    overlay_candidates(file).into_iter().find(|p| p.is_file())
}

/// A device's overlay, read: the checker's settings and what the code generator adds.
#[derive(Clone, Debug)]
pub struct Overlay {
    /// Levels, strictness and per-object allowances.
    pub check: CheckConfig,
    /// Vendor parameter schemes and process-data layouts.
    pub codegen: odc_codegen::Overlay,
}

/// Reads an overlay (or `--config`) file.
///
/// # Errors
///
/// [`Error::Io`] when it cannot be read, [`Error::Overlay`] when either part is invalid.
pub fn read_overlay(path: &Path) -> Result<Overlay, Error> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let bad = |message: String| Error::Overlay { path: path.to_path_buf(), message };
    let check = CheckConfig::from_toml_in(&text, registry()).map_err(|e| bad(e.to_string()))?;
    let codegen = odc_codegen::Overlay::from_toml(&text).map_err(|e| bad(e.to_string()))?;
    Ok(Overlay { check, codegen })
}

/// Reads a device file, but never more than one byte past the larger front-end limit
/// ([`odc_eds::MAX_FILE_SIZE`], [`odc_esi::MAX_FILE_SIZE`]): the front-end then reports the
/// file as too large, and a huge or endless input (`/dev/zero`, a FIFO) costs no more memory
/// than that.
///
/// # Errors
///
/// When the file cannot be opened or read.
pub fn read_device_file(path: &Path) -> std::io::Result<Vec<u8>> {
    read_device(std::fs::File::open(path)?)
}

/// [`read_device_file`] from any reader (standard input): at most one byte past the largest
/// size a front-end accepts, so an endless input ends.
pub fn read_device(reader: impl std::io::Read) -> std::io::Result<Vec<u8>> {
    use std::io::Read as _;
    let limit = odc_eds::MAX_FILE_SIZE.max(odc_esi::MAX_FILE_SIZE) as u64 + 1;
    let mut bytes = Vec::new();
    reader.take(limit).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Whether the bytes are a CiA 311 XDD/XDC: by extension (`.xdd`, `.xdc`), else, for XML, by
/// the root element (`ISO15745ProfileContainer`): ESI files are `.xml` too.
pub fn is_xdd(path: &Path, bytes: &[u8]) -> bool {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("xdd" | "xdc") => true,
        Some("eds" | "dcf" | "esi") => false,
        _ => is_xml(path, bytes) && odc_xdd::is_xdd(bytes),
    }
}

/// Whether the bytes are XML (an ESI, or an XDD/XDC: [`is_xdd`] tells them apart) rather than
/// an EDS/DCF: by extension, else by the first non-blank character.
pub fn is_xml(path: &Path, bytes: &[u8]) -> bool {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("xml" | "esi" | "xdd" | "xdc") => true,
        Some("eds" | "dcf") => false,
        _ => {
            let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
            body.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'<')
        }
    }
}

/// The SHA-256 of `bytes` in lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xdd_told_from_esi_by_root_element() {
        let xdd = b"<?xml version=\"1.0\"?>\n<ISO15745ProfileContainer xmlns=\"x\"/>";
        let esi = b"<?xml version=\"1.0\"?>\n<EtherCATInfo/>";
        // `.xml` is either: the root element decides.
        assert!(is_xdd(Path::new("a.xml"), xdd));
        assert!(!is_xdd(Path::new("a.xml"), esi));
        assert!(is_xml(Path::new("a.xml"), esi));
        // No extension: by content.
        assert!(is_xdd(Path::new("a"), xdd));
        // `.xdd`/`.xdc` always are (a broken one gets the XDD front-end's diagnostics).
        assert!(is_xdd(Path::new("a.XDC"), esi));
        assert!(!is_xdd(Path::new("a.eds"), xdd));
        let mut s = Sources::new();
        let p = parse(&mut s, "a.xml", Path::new("a.xml"), xdd.to_vec());
        assert!(p.diagnostics.iter().all(|d| d.code.starts_with("F3")), "{:?}", p.diagnostics);
        assert!(registry().get("F310").is_some());
    }
}
