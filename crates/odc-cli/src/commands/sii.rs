//! `odc sii`: the SII EEPROM image (ETG.2010) of an ESI device, and the read-back view `odc info`
//! shows for an image.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use odc_model::Diagnostic;
use odc_sii::Sii;

use crate::input;

/// Write the SII EEPROM image (ETG.2010) of an ESI device: info area from `Eeprom/ConfigData`,
/// identity, mailboxes, and the categories strings, general, FMMU, SyncManager, PDOs, DC and the
/// ESI's vendor categories. `odc info IMAGE.bin` reads one back.
#[derive(clap::Args)]
pub struct Args {
    /// ESI file.
    file: PathBuf,
    /// Output file (the binary image).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let loaded = input::load(&args.file, &args.levels)?;
    super::gate(&loaded)?;
    let device = loaded.device()?;
    let (image, notes) = match odc_sii::write_with_notes(device) {
        Ok(written) => written,
        Err(err) => {
            let mut d = Diagnostic::error("SII", err.to_string());
            if let Some(span) = err.span() {
                d = d.with_label(span, "here");
            }
            eprint!("{}", odc_model::diag::render_human(&loaded.sources, &[d], false));
            return Ok(ExitCode::from(1));
        }
    };
    for note in &notes {
        eprintln!("note: {note}");
    }
    input::write_atomic(&args.output, &image)?;
    eprintln!(
        "wrote {}: {} bytes of SII for {}",
        args.output.display(),
        image.len(),
        device.name()
    );
    Ok(ExitCode::SUCCESS)
}

/// Whether `odc info` should read `path` as an SII image: a `.bin`/`.sii` file, or content that
/// is not a text device file and decodes as an image.
pub fn is_image(path: &Path, bytes: &[u8]) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("bin" | "sii")) {
        return true;
    }
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    let text_start = matches!(first, Some(b'<' | b'[' | b';' | 0xEF | 0xFE | 0xFF));
    !text_start && odc_sii::read(bytes).is_ok()
}

/// `odc info` of an SII image.
pub fn info(path: &Path, bytes: &[u8]) -> anyhow::Result<ExitCode> {
    let sii = odc_sii::read(bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    super::out(&describe(&sii, bytes.len()))?;
    Ok(ExitCode::SUCCESS)
}

fn describe(sii: &Sii, len: usize) -> String {
    let mut o = String::new();
    let i = &sii.info;
    let s = |idx: u8| sii.string(idx).map_or_else(|| "-".to_owned(), |t| format!("\"{t}\""));
    let _ = writeln!(
        o,
        "SII image, {len} bytes (size word: {} bytes), version {}",
        i.eeprom_bytes(),
        i.version
    );
    let _ = writeln!(
        o,
        "  vendor 0x{:08X}  product 0x{:08X}  revision 0x{:08X}  serial 0x{:08X}",
        i.vendor_id, i.product_code, i.revision, i.serial
    );
    let _ = writeln!(
        o,
        "  PDI control 0x{:04X}  PDI config 0x{:04X}  sync impulse {}  PDI config2 0x{:04X}  alias {}",
        i.pdi_control, i.pdi_config, i.sync_impulse, i.pdi_config2, i.alias
    );
    let _ = writeln!(
        o,
        "  checksum 0x{:02X} ({})",
        i.checksum,
        if i.checksum_ok { "ok" } else { "WRONG" }
    );
    for (name, m) in [("bootstrap", i.bootstrap), ("standard", i.standard)] {
        let _ = writeln!(
            o,
            "  {name} mailbox: receive 0x{:04X}+{}  send 0x{:04X}+{}",
            m.receive_offset, m.receive_size, m.send_offset, m.send_size
        );
    }
    let protocols: Vec<&str> =
        [(0x01, "AoE"), (0x02, "EoE"), (0x04, "CoE"), (0x08, "FoE"), (0x10, "SoE"), (0x20, "VoE")]
            .iter()
            .filter(|(bit, _)| i.mailbox_protocols & bit != 0)
            .map(|(_, n)| *n)
            .collect();
    let _ =
        writeln!(o, "  mailbox protocols: 0x{:04X} {}", i.mailbox_protocols, protocols.join(" "));
    if let Some(g) = &sii.general {
        let _ = writeln!(
            o,
            "  name {}  order {}  group {}  image {}",
            s(g.name),
            s(g.order),
            s(g.group),
            s(g.image)
        );
        let _ = writeln!(
            o,
            "  CoE details 0x{:02X}  FoE {}  EoE {}  flags 0x{:02X}  E-bus current {} mA  ports 0x{:04X}",
            g.coe_details, g.foe_details, g.eoe_details, g.flags, g.ebus_current, g.ports
        );
    }
    if !sii.fmmus.is_empty() {
        let usage: Vec<&str> = sii
            .fmmus
            .iter()
            .map(|u| match u {
                1 => "Outputs",
                2 => "Inputs",
                3 => "MBoxState",
                _ => "unused",
            })
            .collect();
        let _ = writeln!(o, "  FMMUs: {}", usage.join(", "));
    }
    for (n, sm) in sii.sync_managers.iter().enumerate() {
        let kind = match sm.kind {
            1 => "MBoxOut",
            2 => "MBoxIn",
            3 => "Outputs",
            4 => "Inputs",
            _ => "unused",
        };
        let _ = writeln!(
            o,
            "  SM{n} {kind:<8} start 0x{:04X} length {:<5} control 0x{:02X} enable 0x{:02X}",
            sm.start_address, sm.length, sm.control, sm.enable
        );
    }
    for (dir, pdos) in [("TxPDO", &sii.tx_pdos), ("RxPDO", &sii.rx_pdos)] {
        for p in pdos {
            let sm =
                if p.sync_manager == 0xFF { "-".to_owned() } else { p.sync_manager.to_string() };
            let bits: u32 = p.entries.iter().map(|e| u32::from(e.bits)).sum();
            let _ = writeln!(
                o,
                "  {dir} 0x{:04X} {} SM {sm} flags 0x{:04X}, {bits} bits:",
                p.index,
                s(p.name),
                p.flags
            );
            for e in &p.entries {
                let _ = writeln!(
                    o,
                    "    0x{:04X}:{:02X} {:>2} bits type 0x{:02X} {}",
                    e.index,
                    e.sub,
                    e.bits,
                    e.data_type,
                    s(e.name)
                );
            }
        }
    }
    for m in &sii.dc {
        let _ = writeln!(
            o,
            "  DC {} ({}): AssignActivate 0x{:04X} sync0 cycle {} factor {} shift {}, sync1 factor {} shift {}",
            s(m.name),
            s(m.desc),
            m.assign_activate,
            m.cycle_time0,
            m.sync0_factor,
            m.shift_time0 as i32,
            m.sync1_factor,
            m.shift_time1 as i32
        );
    }
    let _ = writeln!(o, "  {} strings", sii.strings.len());
    let cats: Vec<String> = sii
        .categories
        .iter()
        .map(|c| format!("{} ({} bytes at 0x{:04X})", c.kind, c.data.len(), c.offset))
        .collect();
    let _ = writeln!(o, "  categories: {}", cats.join(", "));
    o
}
