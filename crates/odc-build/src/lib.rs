//! Generate typed Rust from device files in a build script, like `prost-build`.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), odc_build::Error> {
//!     odc_build::Config::new().device("eds/lxm23a.eds").role(odc_build::Role::Both).compile()
//! }
//! ```
//!
//! and in the crate:
//!
//! ```ignore
//! pub mod lxm23a {
//!     include!(concat!(env!("OUT_DIR"), "/lxm23a.rs"));
//! }
//! // or, with the runtime: odc::include_od!("lxm23a");
//! ```
//!
//! For each device file (EDS/DCF, or ESI by extension or a first non-blank `<`), the front-end
//! reads it, `odc-check` checks it, and `odc-codegen` writes `<module>.rs` into `OUT_DIR` (only
//! when its content changed, atomically). Every file read is announced with
//! `cargo:rerun-if-changed=`; warnings become `cargo:warning=` lines; errors come back as an
//! [`Error`] whose `Display` and `Debug` are the rendered diagnostics.
//!
//! A device file may have an overlay beside it ([`overlay_path`]: `<stem>.odc.toml`, else
//! `odc.toml` in its directory), the same file `odc check` reads: its checker settings (the
//! device's quirk allowances) apply unless [`Config::check_config`] was called, and its
//! `[[scheme]]` tables (vendor parameter numbering, see `odc_analysis::scheme`) become modules
//! of the generated code.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

use std::fmt;
use std::path::{Path, PathBuf};

use odc_model::{Diagnostic, diag};

pub use odc_pipeline::{self, Role};
pub use odc_pipeline::{
    Overlay, is_xml, odc_codegen, overlay_candidates, overlay_path, read_device_file, read_overlay,
    sha256_hex,
};

/// Why generation failed.
#[derive(thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("cannot access {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The device file has errors; the report is rendered like rustc's.
    #[error("{report}")]
    Diagnostics {
        /// The device file.
        path: PathBuf,
        /// The rendered diagnostics.
        report: String,
    },
    /// The file has no device at the index asked for ([`Config::select_device`]).
    #[error("{}: {message}", path.display())]
    NoSuchDevice {
        /// The device file.
        path: PathBuf,
        /// What did not match, with the devices the file describes.
        message: String,
    },
    /// A level names no rule or group.
    #[error(transparent)]
    UnknownRule(#[from] odc_pipeline::UnknownRule),
    /// The overlay beside a device file is not valid.
    #[error("invalid overlay {}: {message}", path.display())]
    Overlay {
        /// The overlay file.
        path: PathBuf,
        /// What is wrong, with its position.
        message: String,
    },
    /// The SII EEPROM image asked for (`Config::sii_image`, feature `sii`) cannot be made.
    #[error("{}: SII image: {message}", path.display())]
    Sii {
        /// The device file.
        path: PathBuf,
        /// Why (not an ESI device, or a part of the ESI that does not fit the SII).
        message: String,
    },
    /// No output directory: `OUT_DIR` is not set (not in a build script) and none was given.
    #[error("OUT_DIR is not set: call compile() from a build script, or set out_dir()")]
    NotInBuildScript,
}

impl From<odc_pipeline::Error> for Error {
    fn from(e: odc_pipeline::Error) -> Error {
        match e {
            odc_pipeline::Error::Io { path, source } => Error::Io { path, source },
            odc_pipeline::Error::Overlay { path, message } => Error::Overlay { path, message },
            odc_pipeline::Error::UnknownRule(e) => Error::UnknownRule(e),
            odc_pipeline::Error::Select { path, message } => Error::NoSuchDevice { path, message },
        }
    }
}

impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// One device file to generate.
#[derive(Clone, Debug)]
struct Input {
    path: PathBuf,
    module: Option<String>,
    device: usize,
    #[cfg(feature = "sii")]
    sii: bool,
    #[cfg(feature = "data-sheet")]
    sheet: bool,
}

/// The code generated for one device file.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The module (and file stem) name.
    pub module: String,
    /// The Rust source.
    pub code: String,
    /// The device file.
    pub path: PathBuf,
    /// The SII EEPROM image (ETG.2010), when asked for with `Config::sii_image` (feature `sii`).
    pub sii: Option<Vec<u8>>,
    /// The data sheet (`odc doc`): HTML page and Markdown, when asked for with
    /// `Config::data_sheet` (feature `data-sheet`).
    pub sheet: Option<(String, String)>,
}

/// The result of [`Config::generate`]: code, and what a build script reports to cargo.
#[derive(Clone, Debug, Default)]
pub struct Output {
    /// One entry per device file, in the order they were added.
    pub generated: Vec<Generated>,
    /// Every file read.
    pub read: Vec<PathBuf>,
    /// Warnings in the short form (`path:line:col: warning[CODE]: message`), one per line.
    pub warnings: Vec<String>,
}

/// Builder for code generation from device files.
#[derive(Clone, Debug)]
pub struct Config {
    inputs: Vec<Input>,
    role: Role,
    out_dir: Option<PathBuf>,
    runtime_path: String,
    check: Option<odc_check::Config>,
    emit_rerun: Option<bool>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            inputs: Vec::new(),
            role: Role::Both,
            out_dir: None,
            runtime_path: "::odc".to_string(),
            check: None,
            emit_rerun: None,
        }
    }
}

/// Generates code for the given device files with the defaults, into `OUT_DIR`.
///
/// # Errors
///
/// As [`Config::compile`].
pub fn compile(paths: &[impl AsRef<Path>]) -> Result<(), Error> {
    let mut config = Config::new();
    for p in paths {
        config.device(p);
    }
    config.compile()
}

impl Config {
    /// A configuration with no device, role `Both`, runtime `::odc`.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a device file (EDS, DCF or ESI), relative to the build script's working directory
    /// (the package root).
    pub fn device(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.inputs.push(Input {
            path: path.as_ref().to_path_buf(),
            module: None,
            device: 0,
            #[cfg(feature = "sii")]
            sii: false,
            #[cfg(feature = "data-sheet")]
            sheet: false,
        });
        self
    }

    /// Names the module (and output file) of the device added last; by default its file stem,
    /// in snake case.
    pub fn module_name(&mut self, name: &str) -> &mut Self {
        if let Some(last) = self.inputs.last_mut() {
            last.module = Some(name.to_string());
        }
        self
    }

    /// For an ESI file with several devices, picks the `index`-th (from 0) for the device
    /// added last.
    pub fn select_device(&mut self, index: usize) -> &mut Self {
        if let Some(last) = self.inputs.last_mut() {
            last.device = index;
        }
        self
    }

    /// Also writes the SII EEPROM image (ETG.2010, see `odc_sii`) of the ESI device added
    /// last, as `<module>.sii.bin` beside its code: firmware that emulates its EEPROM can
    /// `include_bytes!` it. A device that is not an ESI device is an [`Error::Sii`].
    /// Feature `sii`.
    #[cfg(feature = "sii")]
    pub fn sii_image(&mut self) -> &mut Self {
        if let Some(last) = self.inputs.last_mut() {
            last.sii = true;
        }
        self
    }

    /// Also writes the data sheet of the device added last (what `odc doc` writes: a
    /// self-contained `<module>.html` with the PDOs drawn bit by bit, and `<module>.md`)
    /// beside its code, so the documentation of the device a crate is built for stays in
    /// step with its code. Feature `data-sheet`.
    #[cfg(feature = "data-sheet")]
    pub fn data_sheet(&mut self) -> &mut Self {
        if let Some(last) = self.inputs.last_mut() {
            last.sheet = true;
        }
        self
    }

    /// Master, slave or both.
    pub fn role(&mut self, role: Role) -> &mut Self {
        self.role = role;
        self
    }

    /// Where to write; default `OUT_DIR`.
    pub fn out_dir(&mut self, dir: impl AsRef<Path>) -> &mut Self {
        self.out_dir = Some(dir.as_ref().to_path_buf());
        self
    }

    /// The runtime crate's path in generated code; default `::odc`.
    pub fn runtime_path(&mut self, path: &str) -> &mut Self {
        self.runtime_path = path.to_string();
        self
    }

    /// The checker configuration (levels, allowances) for every device; default: each
    /// device's overlay ([`overlay_path`]), else every rule at its level.
    pub fn check_config(&mut self, config: odc_check::Config) -> &mut Self {
        self.check = Some(config);
        self
    }

    /// Whether to print `cargo:rerun-if-changed=`; default: when run by cargo.
    pub fn emit_rerun_if_changed(&mut self, on: bool) -> &mut Self {
        self.emit_rerun = Some(on);
        self
    }

    /// Reads, checks and generates every device, without writing anything.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] when a file cannot be read, [`Error::Diagnostics`] when a device file has
    /// errors, [`Error::NoSuchDevice`] for a bad [`Config::select_device`].
    pub fn generate(&self) -> Result<Output, Error> {
        let mut out = Output::default();
        for input in &self.inputs {
            let options = odc_pipeline::Options {
                check: self.check.clone(),
                select: odc_pipeline::Select::Index(input.device),
                ..Default::default()
            };
            let loaded = odc_pipeline::load(&input.path, &options).map_err(Error::from)?;
            out.read.extend(loaded.read.iter().cloned());
            loaded
                .gate_report()
                .map_err(|report| Error::Diagnostics { path: input.path.clone(), report })?;
            let warnings: Vec<Diagnostic> = loaded.warnings().cloned().collect();
            out.warnings
                .extend(diag::render_short(&loaded.sources, &warnings).lines().map(String::from));
            let device = loaded.device().map_err(Error::from)?;
            let code = loaded.generate(device, self.role, &self.runtime_path).map_err(|diags| {
                Error::Diagnostics { path: input.path.clone(), report: loaded.render(&diags) }
            })?;
            let module = input.module.clone().unwrap_or_else(|| module_name(&input.path));
            #[cfg(feature = "sii")]
            let sii = match input.sii {
                true => {
                    let (image, notes) = odc_sii::write_with_notes(device).map_err(|e| {
                        Error::Sii { path: input.path.clone(), message: e.to_string() }
                    })?;
                    // What was left out to fit `Eeprom/ByteSize`: a warning, as `odc sii` says.
                    let left_out =
                        notes.iter().filter(|n| matches!(n, odc_sii::Note::LeftOut { .. }));
                    out.warnings.extend(left_out.map(|n| {
                        format!("{}: warning[{}]: {n}", loaded.name, odc_sii::codes::LEFT_OUT)
                    }));
                    Some(image)
                }
                false => None,
            };
            #[cfg(not(feature = "sii"))]
            let sii = None;
            #[cfg(feature = "data-sheet")]
            let sheet = input.sheet.then(|| {
                let sheet = odc_doc::sheet(&odc_doc::Input {
                    device,
                    file: &loaded.name,
                    sources: Some(&loaded.sources),
                    diagnostics: &warnings,
                    schemes: &loaded.codegen.scheme,
                });
                (odc_doc::html::page(&sheet), odc_doc::markdown::markdown(&sheet))
            });
            #[cfg(not(feature = "data-sheet"))]
            let sheet = None;
            out.generated.push(Generated { module, code, path: input.path.clone(), sii, sheet });
        }
        Ok(out)
    }

    /// Generates every device into the output directory, writing only files whose content
    /// changed, and tells cargo about the files read and the warnings.
    ///
    /// # Errors
    ///
    /// As [`Config::generate`], plus [`Error::NotInBuildScript`] without an output directory
    /// and [`Error::Io`] when a file cannot be written.
    pub fn compile(&mut self) -> Result<(), Error> {
        let emit = self.emit_rerun.unwrap_or_else(|| std::env::var_os("CARGO").is_some());
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => {
                std::env::var_os("OUT_DIR").map(PathBuf::from).ok_or(Error::NotInBuildScript)?
            }
        };
        if emit {
            for input in &self.inputs {
                for path in watch_paths(&input.path) {
                    println!("{}", rerun_line(&path));
                }
            }
        }
        let output = self.generate()?;
        for w in &output.warnings {
            println!("cargo:warning={w}");
        }
        for g in &output.generated {
            write_if_changed(&out_dir.join(format!("{}.rs", g.module)), g.code.as_bytes())?;
            if let Some(image) = &g.sii {
                write_if_changed(&out_dir.join(format!("{}.sii.bin", g.module)), image)?;
            }
            if let Some((html, md)) = &g.sheet {
                write_if_changed(&out_dir.join(format!("{}.html", g.module)), html.as_bytes())?;
                write_if_changed(&out_dir.join(format!("{}.md", g.module)), md.as_bytes())?;
            }
        }
        Ok(())
    }
}

/// What a build script watches for a device file: the file, its overlay if one exists, and the
/// directory they are in, so that an overlay created beside the file (or an `odc.toml`) makes
/// cargo run the script again instead of replaying the old warnings.
///
/// A missing file cannot be watched by name (cargo then re-runs the script on every build), so
/// the directory stands for it; cargo watches a directory by every file in it. A device file in
/// the package root has no such directory (watching the root would take in `target/`): there,
/// creating an overlay needs a `cargo clean -p` or a touch of the device file.
pub fn watch_paths(file: &Path) -> Vec<PathBuf> {
    let mut paths = vec![file.to_path_buf()];
    paths.extend(overlay_path(file));
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty() && *d != Path::new(".")) {
        paths.push(dir.to_path_buf());
    }
    paths
}

/// The directive that makes cargo re-run the build script when `path` changes.
pub fn rerun_line(path: &Path) -> String {
    format!("cargo:rerun-if-changed={}", path.display())
}

/// The default module name of a device file: its stem in snake case (`lexium-mdrive.eds` →
/// `lexium_mdrive`).
pub fn module_name(path: &Path) -> String {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let mut out: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' })
        .collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert_str(0, "device_");
    }
    out
}

/// Writes `contents` to `path` unless it already holds exactly that; atomically (see
/// [`write_atomic`]).
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be written.
pub fn write_if_changed(path: &Path, contents: &[u8]) -> Result<(), Error> {
    if std::fs::read(path).is_ok_and(|old| old == contents) {
        return Ok(());
    }
    write_atomic(path, |w| w.write_all(contents))
        .map_err(|source| Error::Io { path: path.to_path_buf(), source })
}

/// Writes a file so that readers only ever see the old content or the complete new one.
///
/// `write` fills a temporary file created beside `path` (same directory, so the rename cannot
/// cross file systems; named `.<name>.<pid>.<n>.tmp`); the file is flushed and synced, then
/// renamed over `path`. If `write`, the flush or the rename fails, the temporary file is
/// removed and `path` is left as it was: a generation that fails halfway, a full disk or a
/// killed process never leaves a truncated output for the next build to pick up.
///
/// A symbolic link is followed: the file it points to is replaced and the link stays. A target
/// that exists and is not a regular file (`/dev/null`, `/dev/stdout`, a FIFO) is written into
/// directly, since a rename would replace the device itself.
///
/// # Errors
///
/// The first I/O error (from `write`, creating, syncing or renaming the file).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    use std::io::Write as _;
    use std::sync::atomic::{AtomicU32, Ordering};
    /// Distinguishes temporary files of threads of one process writing beside each other.
    static NEXT: AtomicU32 = AtomicU32::new(0);

    if std::fs::metadata(path).is_ok_and(|meta| !meta.is_file() && !meta.is_dir()) {
        let mut out = std::io::BufWriter::new(std::fs::OpenOptions::new().write(true).open(path)?);
        write(&mut out)?;
        return out.flush();
    }
    let resolved = std::fs::canonicalize(path).ok();
    let path = resolved.as_deref().unwrap_or(path);
    let file_name = path.file_name().ok_or_else(|| {
        std::io::Error::new(std::io::ErrorKind::InvalidInput, "output path has no file name")
    })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(".{}.{}.tmp", std::process::id(), NEXT.fetch_add(1, Ordering::Relaxed)));
    let tmp = path.with_file_name(tmp_name);
    let file = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp)?;
    let result = (|| {
        let mut out = std::io::BufWriter::new(file);
        write(&mut out)?;
        out.flush()?;
        let file = out.into_inner().map_err(std::io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_script_watches_the_directory_where_an_overlay_may_appear() {
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds");
        let with = repo.join("lxm23a.eds");
        assert_eq!(watch_paths(&with), [with.clone(), repo.join("lxm23a.odc.toml"), repo.clone()]);
        let without = repo.join("lexium-mdrive.eds");
        assert_eq!(watch_paths(&without), [without.clone(), repo]);
        // Not the package root: cargo would scan target/ and re-run on every build.
        assert_eq!(watch_paths(Path::new("x.eds")), [PathBuf::from("x.eds")]);
        assert_eq!(watch_paths(Path::new("./x.eds")), [PathBuf::from("./x.eds")]);
    }

    #[test]
    fn names_and_directives() {
        assert_eq!(module_name(Path::new("eds/lexium-mdrive.eds")), "lexium_mdrive");
        assert_eq!(module_name(Path::new("esi/3x.xml")), "device_3x");
        assert_eq!(rerun_line(Path::new("eds/x.eds")), "cargo:rerun-if-changed=eds/x.eds");
        assert!(is_xml(Path::new("a.bin"), b"  \n<?xml"));
        assert!(!is_xml(Path::new("a.bin"), b"[FileInfo]"));
        assert_eq!(sha256_hex(b"").len(), 64);
        assert!(sha256_hex(b"").starts_with("e3b0c442"));
    }

    #[test]
    fn overlay_beside_the_file_gives_allowances_and_schemes() {
        let dir = std::env::temp_dir().join(format!("odc-build-overlay-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds");
        let eds = dir.join("lxm23a.eds");
        let _ = std::fs::copy(repo.join("lxm23a.eds"), &eds);
        assert_eq!(overlay_path(&eds), None);
        // Without its overlay, the LXM23A's 0x6502 quirk is a warning.
        let out = Config::new().device(&eds).generate();
        assert!(out.as_ref().is_ok_and(|o| o.warnings.iter().any(|w| w.contains("D504"))));
        let _ = std::fs::copy(repo.join("lxm23a.odc.toml"), dir.join("lxm23a.odc.toml"));
        assert_eq!(overlay_path(&eds), Some(dir.join("lxm23a.odc.toml")));
        let out = Config::new().device(&eds).generate();
        let out = out.unwrap_or_default();
        assert!(out.warnings.is_empty(), "{:?}", out.warnings);
        assert!(out.read.contains(&dir.join("lxm23a.odc.toml")));
        let code = out.generated.first().map(|g| g.code.as_str()).unwrap_or("");
        assert!(code.contains("pub mod keypad {"));
        assert!(code.contains("pub const P3_05: ::odc::Entry<u16>"));
        // An explicit checker configuration wins over the overlay's; the schemes stay.
        let out = Config::new()
            .device(&eds)
            .check_config(odc_check::Config::in_registry(odc_pipeline::registry()))
            .generate();
        assert!(out.is_ok_and(|o| o.warnings.iter().any(|w| w.contains("D504"))));
        // A broken overlay is an error naming the file.
        let _ = std::fs::write(dir.join("lxm23a.odc.toml"), "[[scheme]]\nmodule = 1\n");
        let e = Config::new().device(&eds).generate().err().map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("lxm23a.odc.toml")));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn sii_image_beside_the_code() {
        let dir = std::env::temp_dir().join(format!("odc-build-sii-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let r = Config::new()
            .device(root.join("esi/servoone.xml"))
            .sii_image()
            .out_dir(&dir)
            .emit_rerun_if_changed(false)
            .compile();
        assert!(r.is_ok(), "{r:?}");
        let image = std::fs::read(dir.join("servoone.sii.bin")).unwrap_or_default();
        // ETG.2010: a 2048-byte EEPROM (ByteSize) with version 1 at word 0x3F.
        assert_eq!(image.len(), 2048);
        assert_eq!(image.get(0x7E..0x80), Some(&[1u8, 0][..]));
        // A smaller EEPROM: parts left out, with warning S702 (esi/servoone.xml's DC op
        // modes and PDOs do not fit 256 bytes).
        let esi = std::fs::read_to_string(root.join("esi/servoone.xml")).unwrap_or_default();
        let small = dir.join("small.xml");
        let _ = std::fs::write(&small, esi.replace("<ByteSize>2048<", "<ByteSize>256<"));
        let _ = std::fs::copy(root.join("esi/servoone.odc.toml"), dir.join("small.odc.toml"));
        let out = Config::new().device(&small).sii_image().generate().unwrap_or_default();
        assert!(out.warnings.iter().any(|w| w.contains("warning[S702]")), "{:?}", out.warnings);
        let image = out.generated.first().and_then(|g| g.sii.as_ref()).map(Vec::len);
        assert_eq!(image, Some(256));
        // Not an ESI device: refused, naming the file.
        let e = Config::new().device(root.join("eds/lxm23a.eds")).sii_image().generate().err();
        assert!(matches!(e, Some(Error::Sii { .. })), "{e:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn errors_render_as_reports() {
        let dir = std::env::temp_dir().join(format!("odc-build-test-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let eds = dir.join("broken.eds");
        let _ = std::fs::write(&eds, "[1000]\nParameterName=Device type\nDataType=0x0007\n");
        let e = Config::new().device(&eds).out_dir(&dir).generate().err();
        let text = e.map(|e| format!("{e:?}")).unwrap_or_default();
        assert!(text.contains("error"), "{text}");
        let missing = Config::new().device(dir.join("nope.eds")).generate().err();
        assert!(matches!(missing, Some(Error::Io { .. })));
        let out = dir.join("x.rs");
        assert!(write_if_changed(&out, b"a").is_ok());
        assert!(write_if_changed(&out, b"a").is_ok());
        assert_eq!(std::fs::read(&out).ok().as_deref(), Some(&b"a"[..]));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
