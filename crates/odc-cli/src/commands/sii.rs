//! `odc sii`: the SII EEPROM image (ETG.2010) of an ESI device, and the read-back view `odc info`
//! shows for an image.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use odc_model::{Diagnostic, Severity, Span};
use odc_sii::{Fit, Note, Options, Sii, codes};

use super::{Color, DiagFormat, HasErrors};
use crate::input;

/// Write the SII EEPROM image (ETG.2010) of an ESI device: info area from `Eeprom/ConfigData`,
/// identity, mailboxes, and the categories strings, general, FMMU, SyncManager, PDOs, DC and the
/// ESI's own categories. Where the content does not fit `Eeprom/ByteSize`, optional parts are
/// left out (warning S702, in the order `odc explain S702` gives); where even the rest does
/// not, the image is refused (S701). `odc info IMAGE.bin` reads one back.
#[derive(clap::Args)]
pub struct Args {
    /// ESI file.
    file: PathBuf,
    /// Output file (the binary image).
    #[arg(short, long)]
    output: PathBuf,
    /// Where the content does not fit `Eeprom/ByteSize`, leave nothing out and write the image
    /// for a larger EEPROM (the smallest power of two that holds it). Setting S701 to `warn` or
    /// `allow` does the same for an image that does not fit even with the optional parts left
    /// out.
    #[arg(long)]
    grow: bool,
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let loaded = input::load(&args.file, &args.levels)?;
    super::gate(&loaded)?;
    let device = loaded.device()?;
    let fit = if args.grow { Fit::Grow } else { Fit::Omit };
    let byte_size_span = device
        .ethercat
        .as_deref()
        .and_then(|ec| ec.eeprom.as_ref())
        .and_then(|ee| ee.spans.byte_size);
    let mut diags = Vec::new();
    let written = match odc_sii::write_with(device, &Options::default().fit(fit)) {
        Err(err @ odc_sii::Error::DoesNotFit { .. }) => {
            let d = Diagnostic::error(codes::DOES_NOT_FIT, err.to_string()).with_note(
                "`--grow` writes the image for a larger EEPROM; `-W S701` does so with this \
                 warning",
            );
            let applied = loaded.config.apply(device, vec![labelled(d, err.span())]);
            if applied.iter().any(Diagnostic::is_error) {
                return refuse(&loaded, &applied);
            }
            // The refusal is allowed: everything, for a larger EEPROM.
            diags = applied;
            odc_sii::write_with(device, &Options::default().fit(Fit::Grow))
        }
        other => other,
    };
    let (image, notes) = match written {
        Ok(written) => written,
        Err(err) => {
            let d = labelled(Diagnostic::error("SII", err.to_string()), err.span());
            eprint!("{}", odc_model::diag::render_human(&loaded.sources, &[d], false));
            return Ok(ExitCode::from(1));
        }
    };
    let from_notes = notes.iter().map(|note| note_diagnostic(note, byte_size_span)).collect();
    diags.extend(loaded.config.apply(device, from_notes));
    if diags.iter().any(Diagnostic::is_error) {
        return refuse(&loaded, &diags);
    }
    super::print_diagnostics(&loaded.sources, &diags, DiagFormat::Human, Color::Auto)?;
    input::write_atomic(&args.output, &image)?;
    eprintln!(
        "wrote {}: {} bytes of SII for {}",
        args.output.display(),
        image.len(),
        device.name()
    );
    Ok(ExitCode::SUCCESS)
}

/// The diagnostics, then the refusal (exit 1, naming the codes and how to allow them).
fn refuse(loaded: &odc_pipeline::Loaded, diags: &[Diagnostic]) -> anyhow::Result<ExitCode> {
    super::print_diagnostics(&loaded.sources, diags, DiagFormat::Human, Color::Auto)?;
    match loaded.refuse(diags) {
        Err(refused) => Err(HasErrors(refused).into()),
        Ok(()) => Ok(ExitCode::from(1)),
    }
}

fn labelled(d: Diagnostic, span: Option<Span>) -> Diagnostic {
    match span {
        Some(span) => d.with_label(span, "here"),
        None => d,
    }
}

/// A writer's note as a diagnostic: what was left out is S702 (a warning, at `ByteSize`),
/// the rest S703 (a note).
fn note_diagnostic(note: &Note, byte_size: Option<Span>) -> Diagnostic {
    match note {
        Note::LeftOut { full, byte_size: size, omitted } => {
            let message = format!(
                "the SII image needs {full} bytes with everything, more than `Eeprom/ByteSize` \
                 {size}: optional parts left out"
            );
            let d = Diagnostic::new(Severity::Warning, codes::LEFT_OUT, message);
            let d = omitted
                .iter()
                .fold(d, |d, (what, n)| d.with_note(format!("left out: {}", what.describe(*n))));
            labelled(d.with_note("`--grow` writes everything for a larger EEPROM"), byte_size)
        }
        _ => Diagnostic::new(Severity::Note, codes::ADJUSTED, note.to_string()),
    }
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
    // The info area alone reads as an image whatever it holds: ask for categories too.
    !text_start && bytes.len() > odc_sii::INFO_AREA && odc_sii::read(bytes).is_ok()
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
