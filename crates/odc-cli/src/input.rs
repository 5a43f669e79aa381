//! Reading device files: the one place that decides EDS/DCF versus ESI.

use std::path::Path;

use anyhow::Context;
use odc_model::{Device, Diagnostic, Sources};

/// A device file read and lowered: its devices (one for EDS/DCF, one per `<Device>` of an ESI)
/// and the front-end's diagnostics.
pub struct Loaded {
    pub devices: Vec<Device>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Whether the bytes are an XML document (ESI) rather than INI text (EDS/DCF): by extension,
/// else by the first non-blank character.
fn is_xml(path: &Path, bytes: &[u8]) -> bool {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("xml" | "esi") => true,
        Some("eds" | "dcf") => false,
        _ => {
            let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
            body.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'<')
        }
    }
}

/// Reads and lowers one file. I/O problems are errors; problems in the content are diagnostics.
pub fn load(sources: &mut Sources, path: &Path) -> anyhow::Result<Loaded> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let name = path.display().to_string();
    let (devices, diagnostics) = if is_xml(path, &bytes) {
        let parsed = odc_esi::parse(sources, &name, &bytes);
        (parsed.devices, parsed.diagnostics)
    } else {
        let parsed = odc_eds::parse(sources, &name, &bytes);
        (vec![parsed.device], parsed.diagnostics)
    };
    Ok(Loaded { devices, diagnostics })
}

/// The checker configuration for a device file: `--config` if given, else `<stem>.odc.toml`
/// beside the file, else `odc.toml` in its directory, else the defaults. Quirk allowances of one
/// device thus live next to that device's file.
pub fn config_for(explicit: Option<&Path>, file: &Path) -> anyhow::Result<odc_check::Config> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let beside = file.file_stem().map(|stem| {
        let mut name = stem.to_os_string();
        name.push(".odc.toml");
        dir.join(name)
    });
    let candidates = [explicit.map(Path::to_path_buf), beside, Some(dir.join("odc.toml"))];
    for path in candidates.into_iter().flatten() {
        if explicit.is_some_and(|e| e == path) || path.is_file() {
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            return odc_check::Config::from_toml(&text)
                .with_context(|| format!("invalid configuration in {}", path.display()));
        }
    }
    Ok(odc_check::Config::default())
}

/// Writes `contents` to `path` atomically: into a temporary file beside it, then renamed over
/// it, so an interrupted or failed run never leaves a half-written file.
pub fn write_atomic(path: &Path, contents: &[u8]) -> anyhow::Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let file_name = path.file_name().context("output path has no file name")?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(".{}.tmp", std::process::id()));
    let tmp = dir.join(tmp_name);
    std::fs::write(&tmp, contents).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::Error::new(e).context(format!("cannot write {}", path.display()))
    })
}
