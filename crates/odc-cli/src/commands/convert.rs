//! `odc convert`: write a device file as EDS, DCF, XDD or XDC.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use odc_model::Format;

use crate::input;

/// Convert a device file: EDS/DCF ↔ XDD/XDC in every direction, a normalised EDS, or one device
/// of an ESI as EDS.
///
/// The output format follows `--to`, else the extension of `-o` (`.eds`, `.dcf`, `.xdd`,
/// `.xdc`); what the output format has no place for is named in a warning; a file holding DCF values
/// (ParameterValue, Denotation, `[DeviceComissioning]`, `[ConnectedModules]`) stays a DCF unless
/// `--to eds` asks for an EDS, which leaves them out with a warning that counts them. Keys and
/// sections odc does not interpret are carried over. The output is read back and checked
/// first: a file `odc check` would refuse at the same levels is not written (an ESI device that
/// breaks CiA 301 as a CANopen device, say a 96-bit PDO). The output file is replaced only when
/// writing succeeded.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF, XDD, XDC or ESI file.
    input: PathBuf,
    /// Output file; standard output when absent.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum)]
    to: Option<Target>,
    #[command(flatten)]
    levels: input::Levels,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Target {
    Eds,
    Dcf,
    Xdd,
    Xdc,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let loaded = input::load(&args.input, &args.levels)?;
    super::gate(&loaded)?;
    let mut device = loaded.device()?.clone();
    // An EtherCAT device written as EDS/DCF is a CANopen device: it gets the objects CiA 301
    // makes mandatory when its ESI has none (most I/O terminals have no CoE dictionary).
    let added = odc_eds::add_mandatory_objects(&mut device);
    if !added.is_empty() {
        let list: Vec<String> = added.iter().map(|i| format!("0x{i:04X}")).collect();
        eprintln!(
            "note: added the CiA 301 mandatory object(s) the ESI device lacks: {} (device type \
             from <Profile>, identity from <Type>)",
            list.join(", ")
        );
    }
    if loaded.device()?.format == Some(Format::Esi) {
        gate_as_canopen(&loaded, &device)?;
    }
    for pdo in odc_eds::pdo_directions_by_index(&device) {
        let (was, becomes) = match pdo.direction {
            odc_model::Direction::Rx => ("RxPdo", "a TPDO"),
            odc_model::Direction::Tx => ("TxPdo", "an RPDO"),
        };
        eprintln!(
            "warning: {was} 0x{:04X} is numbered outside its direction's range; an EDS gives a \
             PDO's direction by its index, so it is written as {becomes}",
            pdo.mapping_index
        );
    }
    let device = &device;
    // What an EDS has no place for. Left out only when an EDS is asked for by name: without
    // them a DCF's compact PDO mappings ([1600Value]) would be left with no entries.
    let dcf_values = odc_eds::dcf_only(device);
    let ext = |want: &str| {
        args.output
            .as_ref()
            .and_then(|o| o.extension())
            .is_some_and(|e| e.eq_ignore_ascii_case(want))
    };
    let xml = match args.to {
        Some(Target::Xdd) => Some(Format::Xdd),
        Some(Target::Xdc) => Some(Format::Xdc),
        Some(_) => None,
        None if ext("xdc") => Some(Format::Xdc),
        None if ext("xdd") && dcf_values.is_empty() => Some(Format::Xdd),
        None if ext("xdd") => {
            eprintln!(
                "note: the input holds {} DCF value(s) ({dcf_values}); written as XDC to keep \
                 them (--to xdd leaves them out)",
                dcf_values.total()
            );
            Some(Format::Xdc)
        }
        None => None,
    };
    if let Some(format) = xml {
        let written = odc_xdd::write(device, format);
        for lost in &written.lost {
            eprintln!("warning: not written (an XDD/XDC has no place for it): {lost}");
        }
        gate_output(&loaded, &written.text, args.output.as_deref())?;
        match &args.output {
            Some(path) => input::write_atomic(path, written.text.as_bytes())?,
            None => super::out(&written.text)?,
        }
        return Ok(ExitCode::SUCCESS);
    }
    // XML elements kept inside objects (keys `<name`) have no EDS spelling either.
    let mut eds_device = device.clone();
    let inner = strip_xml_entries(&mut eds_device);
    if inner > 0 {
        eprintln!(
            "warning: {inner} XML element(s) kept in objects' parameters not written (an EDS \
             has no place for them)"
        );
    }
    let device = &eds_device;
    if !device.xml_extra.is_empty() {
        eprintln!(
            "warning: {} XML element(s) of the XDD not written (an EDS has no place for them): {}",
            device.xml_extra.len(),
            xml_names(&device.xml_extra)
        );
    }
    let target = match (args.to, &args.output) {
        (Some(Target::Eds), _) => Format::Eds,
        (Some(Target::Dcf), _) => Format::Dcf,
        (Some(Target::Xdd | Target::Xdc), _) => Format::Eds, // handled above
        (None, Some(_)) if ext("dcf") => Format::Dcf,
        (None, _) if !dcf_values.is_empty() => {
            eprintln!(
                "note: the input holds {} DCF value(s) ({dcf_values}); written as DCF to keep \
                 them (--to eds leaves them out)",
                dcf_values.total()
            );
            Format::Dcf
        }
        _ => Format::Eds,
    };
    if target == Format::Eds && !dcf_values.is_empty() {
        eprintln!(
            "warning: {} DCF value(s) not written to the EDS ({dcf_values}); to keep them, \
             write a DCF (leave out --to eds, or --to dcf)",
            dcf_values.total()
        );
    }
    let text = odc_eds::write(device, target);
    gate_output(&loaded, &text, args.output.as_deref())?;
    match &args.output {
        Some(path) => input::write_atomic(path, text.as_bytes())?,
        None => super::out(&text)?,
    }
    Ok(ExitCode::SUCCESS)
}

/// An EtherCAT device written as EDS or DCF is a CANopen device, and is judged as one: by the
/// CiA 301 rules that do not apply to EtherCAT (a PDO fits a CAN frame's 64 bits, maps objects
/// the dictionary has, with their lengths and access; modules are CiA 306's), each PDO in the
/// direction its index gives in an EDS. Refused like any file when
/// that judgement has an error at the levels that apply, so that what `convert` writes passes
/// `odc check`; `-A`/`-W` with the rule writes it anyway, and `check` with the same levels passes.
fn gate_as_canopen(
    loaded: &odc_pipeline::Loaded,
    device: &odc_model::Device,
) -> anyhow::Result<()> {
    let canopen = odc_eds::as_canopen(device);
    // Only the errors: the warnings of the EDS syntax rules (C115, SubNumber) concern text the
    // writer makes right, and the rest are reported by `check` on the output.
    let errors: Vec<_> =
        odc_pipeline::check(std::slice::from_ref(&canopen), Vec::new(), &loaded.config)
            .into_iter()
            .filter(odc_model::Diagnostic::is_error)
            .collect();
    if !errors.is_empty() {
        eprintln!(
            "note: written as EDS/DCF, the EtherCAT device is a CANopen device and is checked by \
             CiA 301's rules; the errors below are of the device taken as CANopen"
        );
    }
    super::gate_over(loaded, &errors)
}

/// What `convert` writes passes `odc check` at the levels that apply: the text is read back
/// and checked before it is written. An ESI whose mapping objects (0x1600/0x1A00 defaults)
/// map other objects than its `<RxPdo>`/`<TxPdo>` elements passes [`gate_as_canopen`] and
/// fails here, since an EDS gives its PDOs by those objects alone.
fn gate_output(
    loaded: &odc_pipeline::Loaded,
    text: &str,
    output: Option<&Path>,
) -> anyhow::Result<()> {
    let mut sources = odc_model::Sources::new();
    let name = match output {
        Some(path) => format!("{} (not written)", path.display()),
        None => "<output> (not written)".to_owned(),
    };
    // Read as `odc check` reads a file: by its content (an XDD's root element), else as EDS.
    let back = odc_pipeline::parse(&mut sources, &name, Path::new(&name), text.as_bytes().to_vec());
    let diagnostics = odc_pipeline::check(&back.devices, back.diagnostics, &loaded.config);
    let errors: Vec<_> = diagnostics.into_iter().filter(odc_model::Diagnostic::is_error).collect();
    if errors.is_empty() {
        return Ok(());
    }
    eprintln!(
        "note: the converted file, read back, fails odc check at these levels; it was not written"
    );
    super::print_diagnostics(&sources, &errors, super::DiagFormat::Human, super::Color::Auto)?;
    loaded.refuse(&errors).map_err(|refused| super::HasErrors(refused).into())
}

/// The kept XML elements as `parent/name`, each once, in order.
fn xml_names(extra: &[odc_model::XmlExtra]) -> String {
    let mut names: Vec<String> = Vec::new();
    for x in extra {
        let name: String = x
            .xml
            .trim_start_matches('<')
            .chars()
            .take_while(|c| !c.is_whitespace() && *c != '>' && *c != '/')
            .collect();
        let local = name.rsplit(':').next().unwrap_or(&name);
        let n = format!("{}/{local}", x.parent);
        if !names.contains(&n) {
            names.push(n);
        }
    }
    names.join(", ")
}

/// Removes the XML elements the XDD front-end kept in objects' `extra` (keys starting with
/// `<`); returns how many.
fn strip_xml_entries(device: &mut odc_model::Device) -> usize {
    let mut n = 0;
    let mut strip = |extra: &mut Vec<odc_model::RawEntry>| {
        let before = extra.len();
        extra.retain(|e| !e.key.starts_with('<'));
        n += before - extra.len();
    };
    for o in device.objects.values_mut() {
        strip(&mut o.extra);
        for s in o.subs.values_mut() {
            if s.rare().extra.iter().any(|e| e.key.starts_with('<')) {
                strip(&mut s.rare_mut().extra);
            }
        }
    }
    n
}
