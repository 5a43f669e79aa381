//! Which devices of a file to work on: all, the n-th, or one named by product and revision.

use odc_model::Device;

/// A device selection.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Select {
    /// Every device of the file.
    #[default]
    All,
    /// The n-th device (from 0) of an ESI file (`odc_build::Config::select_device`,
    /// `include_device!(…, device = N)`).
    Index(usize),
    /// `PRODUCT[:REVISION]` (numbers in decimal, `0x` or `#x` hex) or a name (product name or
    /// order code, any case); without a revision the highest revision of that product (`--device`).
    Spec(String),
}

impl Select {
    /// The selected devices; the error says what did not match and lists the file's devices.
    pub(crate) fn apply(&self, devices: Vec<Device>) -> Result<Vec<Device>, String> {
        match self {
            Select::All => Ok(devices),
            Select::Index(i) => {
                let count = devices.len();
                match devices.into_iter().nth(*i) {
                    Some(d) => Ok(vec![d]),
                    None => Err(format!("no device number {i}; the file describes {count}")),
                }
            }
            Select::Spec(spec) => {
                let best = best_match(&devices, spec)?;
                Ok(devices.into_iter().nth(best).into_iter().collect())
            }
        }
    }
}

fn best_match(devices: &[Device], spec: &str) -> Result<usize, String> {
    let (product, revision) = match spec.split_once(':') {
        Some((p, r)) => {
            (p, Some(parse_number(r).ok_or_else(|| format!("`{r}` is not a revision number"))?))
        }
        None => (spec, None),
    };
    let number = parse_number(product);
    let matches = |d: &Device| {
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
        .enumerate()
        .filter(|(_, d)| matches(d))
        .max_by_key(|(_, d)| d.device_info.revision_number.as_deref().copied())
        .map(|(i, _)| i)
        .ok_or_else(|| {
            format!("no device matches `{spec}`; the file describes:\n{}", list_devices(devices))
        })
}

/// One line per device: product code, revision, name, PDO count.
pub fn list_devices(devices: &[Device]) -> String {
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
