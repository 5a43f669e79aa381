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
    let bytes = odc_build::read_device_file(path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let name = path.display().to_string();
    let (devices, diagnostics) = if is_xml(path, &bytes) {
        let parsed = odc_esi::parse_vec(sources, &name, bytes);
        (parsed.devices, parsed.diagnostics)
    } else {
        let parsed = odc_eds::parse(sources, &name, &bytes);
        // A file too large to read describes no device (as an unreadable ESI): checking the
        // empty model would only add noise.
        let read = !parsed.diagnostics.iter().any(|d| d.code == odc_eds::codes::SIZE_LIMIT);
        (if read { vec![parsed.device] } else { Vec::new() }, parsed.diagnostics)
    };
    Ok(Loaded { devices, diagnostics })
}

/// The checker configuration for a device file: `--config` if given, else `<stem>.odc.toml`
/// beside the file, else `odc.toml` in its directory, else the defaults. Quirk allowances of one
/// device thus live next to that device's file.
pub fn config_for(explicit: Option<&Path>, file: &Path) -> anyhow::Result<odc_check::Config> {
    let Some(path) = explicit.map(Path::to_path_buf).or_else(|| odc_build::overlay_path(file))
    else {
        return Ok(odc_check::Config::default());
    };
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    odc_check::Config::from_toml(&text)
        .with_context(|| format!("invalid configuration in {}", path.display()))
}

/// What the overlay of a device file (found as for [`config_for`]) adds to its generated code:
/// vendor parameter schemes and process-data layouts; nothing without one.
pub fn codegen_overlay_for(file: &Path) -> anyhow::Result<odc_build::odc_codegen::Overlay> {
    let Some(path) = odc_build::overlay_path(file) else { return Ok(Default::default()) };
    Ok(odc_build::read_overlay(&path)?.codegen)
}

/// Writes `contents` to `path` atomically ([`odc_build::write_atomic`]): into a temporary file
/// beside it, then renamed over it, so an interrupted or failed run never leaves a half-written
/// file.
pub fn write_atomic(path: &Path, contents: &[u8]) -> anyhow::Result<()> {
    odc_build::write_atomic(path, |w| w.write_all(contents))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Picks the device a command works on. A file with one device needs no `spec`; otherwise
/// `spec` is `PRODUCT[:REVISION]` (numbers in decimal, `0x` or `#x` hex) or a name (product name
/// or order code, any case). Without a revision the highest revision of that product is taken.
pub fn select<'a>(devices: &'a [Device], spec: Option<&str>) -> anyhow::Result<&'a Device> {
    let Some(spec) = spec else {
        return match devices {
            [one] => Ok(one),
            [] => anyhow::bail!("the file describes no device"),
            many => anyhow::bail!(
                "the file describes {} devices; choose one with --device PRODUCT[:REVISION] or a name:\n{}",
                many.len(),
                list(many)
            ),
        };
    };
    let (product, revision) = match spec.split_once(':') {
        Some((p, r)) => {
            (p, Some(parse_number(r).with_context(|| format!("`{r}` is not a revision number"))?))
        }
        None => (spec, None),
    };
    let number = parse_number(product);
    let matches = |d: &&Device| {
        let info = &d.device_info;
        let product_ok = match number {
            Some(n) => info.product_number.as_deref() == Some(&n),
            None => [&info.product_name, &info.order_code]
                .into_iter()
                .any(|s| s.as_deref().is_some_and(|s| s.eq_ignore_ascii_case(product))),
        };
        product_ok && revision.is_none_or(|r| info.revision_number.as_deref() == Some(&r))
    };
    devices
        .iter()
        .filter(matches)
        .max_by_key(|d| d.device_info.revision_number.as_deref().copied())
        .with_context(|| {
            format!("no device matches `{spec}`; the file describes:\n{}", list(devices))
        })
}

/// One line per device: product code, revision, name, PDO count.
pub fn list(devices: &[Device]) -> String {
    let hex = |v: Option<&u32>| v.map_or_else(|| "-".to_owned(), |v| format!("0x{v:08X}"));
    devices
        .iter()
        .map(|d| {
            let info = &d.device_info;
            format!(
                "  {}:{}  {}  ({} PDOs)\n",
                hex(info.product_number.as_deref()),
                hex(info.revision_number.as_deref()),
                d.name(),
                d.pdos.len()
            )
        })
        .collect()
}

fn parse_number(s: &str) -> Option<u32> {
    let s = s.trim();
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).or_else(|| s.strip_prefix("#x")) {
        Some(hex) => u32::from_str_radix(hex, 16).ok(),
        None => s.parse().ok(),
    }
}
