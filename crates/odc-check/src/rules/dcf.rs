//! C501–C509: device configuration files and modular devices (CiA 306 §4.6, §4.7), and the
//! links between objects.

use odc_model::{Device, Format, Label, Span};

use super::rule;
use crate::Ctx;
use crate::util::{all_subs, first_span, idx};

fn is_dcf(dev: &Device) -> bool {
    dev.format == Some(Format::Dcf)
}

rule!(
    C501,
    "C501",
    "dcf-only-keys",
    "cia301",
    Note,
    Warn,
    dcf_only_keys,
    "a file with DCF content (ParameterValue, Denotation, [DeviceComissioning]) calls itself an EDS",
    "An EDS describes what a device type can do; a DCF describes one configured device. \
     ParameterValue (the value configured for this device), Denotation (its name in this \
     application) and [DeviceComissioning] are DCF content (CiA 306 §4.7), and odc reads a file \
     that has them as a DCF. This rule notes such a file when its [FileInfo] FileName (which \
     CiA 306 makes the file's own name) says .eds — a DCF saved under an EDS name, an EDS into \
     which a tool leaked project data, or a DCF whose tool copied [FileInfo] from the EDS — \
     and an EDS with Denotation keys. Tools that go by the name treat the file as an EDS and \
     ignore or apply the ParameterValues differently (python-canopen applies them since PR \
     #654), so the device's initial values depend on the tool. Fix: correct FileName (and the \
     extension), or move the values to DefaultValue."
);

/// Why the device holds DCF content: the first ParameterValue, Denotation or commissioning.
fn dcf_content(dev: &Device) -> Option<(u16, Option<u8>, Span, String)> {
    if let Some(c) = &dev.commissioning {
        return Some((0, None, c.span, "[DeviceComissioning]".to_string()));
    }
    if let Some(o) = dev.objects.values().find(|o| o.denotation.is_some()) {
        let span = o.denotation.as_ref().map_or(o.span, |d| d.span);
        return Some((o.index, None, span, format!("a Denotation in {}", idx(o.index))));
    }
    all_subs(dev).find_map(|(o, s)| {
        let (what, v) = match (&s.parameter_value, &s.rare().denotation) {
            (Some(v), _) => ("a ParameterValue", v.span),
            (None, Some(d)) => ("a Denotation", d.span),
            (None, None) => return None,
        };
        let sub = o.kind.has_subs().then_some(s.sub_index);
        let at = crate::util::addr(o, s.sub_index);
        Some((o.index, sub, first_span([v, s.span, o.span]), format!("{what} in {at}")))
    })
}

fn dcf_only_keys(dev: &Device, ctx: &mut Ctx) {
    let named_eds = dev
        .file_info
        .file_name
        .as_ref()
        .is_some_and(|f| f.value.trim().to_ascii_lowercase().ends_with(".eds"));
    let applies = match dev.format {
        Some(Format::Dcf) => named_eds,
        Some(Format::Eds) => true,
        _ => false,
    };
    if !applies {
        return;
    }
    let Some((index, sub, span, what)) = dcf_content(dev) else { return };
    let message = match dev.file_info.file_name.as_ref() {
        Some(f) => format!("FileName={} names an EDS, but the file has {what}", f.value.trim()),
        None => format!("the EDS has {what}"),
    };
    let d = if index == 0 {
        ctx.report_device(span, message)
    } else {
        ctx.report(index, sub, span, message)
    };
    d.notes.push("odc reads the file as a DCF".into());
}

rule!(
    C502,
    "C502",
    "dcf-last-eds",
    "cia301",
    Note,
    Allow,
    dcf_last_eds,
    "a DCF does not name the EDS it was made from (LastEDS)",
    "CiA 306 §4.7 lets a DCF record in [FileInfo] LastEDS the EDS it was derived from, so that \
     a tool can tell which device description a configuration belongs to and update it when the \
     EDS changes (EdsDcfNet checks it). Nearly all real DCFs do without (all but a handful in \
     odc's corpus), so the rule is off by default; turn it on (`--warn C502`) where DCFs are expected \
     to be traceable. Fix: add LastEDS=<file name of the EDS> to [FileInfo]."
);

fn dcf_last_eds(dev: &Device, ctx: &mut Ctx) {
    if !is_dcf(dev) {
        return;
    }
    let fi = &dev.file_info;
    let has = fi
        .extra
        .iter()
        .any(|e| e.key.eq_ignore_ascii_case("LastEDS") && !e.value.trim().is_empty());
    if !has {
        let span = first_span(
            [fi.file_name.as_ref().map(|f| f.span), fi.description.as_ref().map(|d| d.span)]
                .into_iter()
                .flatten(),
        );
        ctx.report_device(span, "the DCF has no LastEDS in [FileInfo]");
    }
}

/// Whether a commissioning node-ID is usable: 1..=127, or 255 (LSS: not configured, CiA 305).
fn node_id_ok(n: u8) -> bool {
    (1..=127).contains(&n) || n == 255
}

rule!(
    C503,
    "C503",
    "dcf-node-id",
    "cia301",
    Warning,
    Warn,
    dcf_node_id,
    "the DCF's [DeviceComissioning] NodeID is not a CANopen node-ID",
    "A DCF configures one device at one node-ID (CiA 306 §4.7 [DeviceComissioning] NodeID); \
     CANopen node-IDs are 1..=127 (CiA 301 §7.3.2; 255 marks an LSS device that has none yet, \
     CiA 305). Every `$NODEID` value of the file is resolved with it, so with 0 or 128..=254 \
     the COB-IDs of the configured device (0x180 + node-ID, ...) are wrong or restricted. \
     Fix: set NodeID to the device's node-ID."
);

fn dcf_node_id(dev: &Device, ctx: &mut Ctx) {
    let Some(c) = dev.commissioning.as_ref() else { return };
    let Some(n) = c.node_id.as_ref() else { return };
    if !node_id_ok(n.value) {
        ctx.report_device(
            first_span([n.span, c.span]),
            format!("NodeID={} is not a node-ID (1..=127)", n.value),
        );
    }
}

/// CiA 301 bit rates in kbit/s (CiA 306 `BaudRate_NNN` keys).
const BIT_RATES: [u32; 8] = [10, 20, 50, 125, 250, 500, 800, 1000];

rule!(
    C504,
    "C504",
    "dcf-baudrate",
    "cia301",
    Warning,
    Warn,
    dcf_baudrate,
    "the DCF's Baudrate is not a CiA bit rate, or not one the device supports",
    "[DeviceComissioning] Baudrate is the configured bit rate in kbit/s (CiA 306 §4.7). CiA 301 \
     bit rates are 10, 20, 50, 125, 250, 500, 800 and 1000 kbit/s; the device supports those \
     its [DeviceInfo] lists with BaudRate_NNN=1. Another value (0 is what some tools write when nothing was \
     chosen) configures a bus the device cannot join. Fix: set Baudrate to a bit rate the \
     device supports."
);

fn dcf_baudrate(dev: &Device, ctx: &mut Ctx) {
    let Some(c) = dev.commissioning.as_ref() else { return };
    let Some(b) = c.baudrate.as_ref() else { return };
    let span = first_span([b.span, c.span]);
    let supported = &dev.device_info.baud_rates;
    if !BIT_RATES.contains(&b.value) {
        ctx.report_device(span, format!("Baudrate={} is not a CiA 301 bit rate (kbit/s)", b.value));
    } else if !supported.is_empty() && !supported.contains(&b.value) {
        let list: Vec<String> = supported.iter().map(u32::to_string).collect();
        ctx.report_device(
            span,
            format!(
                "Baudrate={} but [DeviceInfo] supports only {} kbit/s",
                b.value,
                list.join(", ")
            ),
        );
    }
}

rule!(
    C505,
    "C505",
    "module-sub-extend-parent",
    "cia301",
    Error,
    Deny,
    module_sub_extend_parent,
    "a module's [MxSubExtIIII] extends an object that does not exist",
    "A module of a modular device (CiA 306 §4.6) adds sub-objects to an object of the bus \
     coupler with [MxSubExtIIII] (ObjExtend names the object when given, else IIII). The object \
     must exist, in the device's dictionary or among the module's [MxFixedIIII] objects; \
     otherwise a tool plugging the module in has nowhere to put the sub-objects (CANopenEditor, \
     CANchkEDS \"module description\"). Fix: correct the index, or add the object."
);

fn module_sub_extend_parent(dev: &Device, ctx: &mut Ctx) {
    for m in &dev.modules.supported {
        for (&index, ext) in &m.sub_extends {
            let target = ext.obj_extend.as_ref().map_or(index, |o| o.value);
            if dev.objects.contains_key(&target) || m.fixed_objects.contains_key(&target) {
                continue;
            }
            let span = first_span([
                ext.obj_extend.as_ref().map_or(Span::DUMMY, |o| o.span),
                ext.template.span,
                m.span,
            ]);
            ctx.report(
                target,
                None,
                span,
                format!(
                    "module {} extends {}, which neither the device nor the module defines",
                    m.number,
                    idx(target)
                ),
            );
        }
    }
}

/// Whether a `Count` is `n` or `n;m` with u8 numbers (decimal or 0x hex).
fn count_ok(text: &str) -> bool {
    let parse = |s: &str| {
        let s = s.trim();
        match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
            Some(h) => u8::from_str_radix(h, 16).is_ok(),
            None => s.parse::<u8>().is_ok(),
        }
    };
    let mut parts = text.split(';');
    let ok = parts.next().is_some_and(parse);
    ok && parts.next().is_none_or(parse) && parts.next().is_none()
}

rule!(
    C506,
    "C506",
    "module-count",
    "cia301",
    Error,
    Deny,
    module_count,
    "a module's sub-extension Count is missing or not `n` / `n;m`",
    "Count in [MxSubExtIIII] says how many sub-objects the module adds: an UNSIGNED8 `n`, or \
     `n;m` (CiA 306 §4.6). Without a readable Count a tool cannot build the extended object \
     when the module is plugged in. Fix: write the number of sub-objects the module adds."
);

fn module_count(dev: &Device, ctx: &mut Ctx) {
    for m in &dev.modules.supported {
        for (&index, ext) in &m.sub_extends {
            let (why, span) = match &ext.count {
                None => ("has no Count".to_string(), ext.template.span),
                Some(c) if !count_ok(&c.value) => {
                    (format!("has Count={}, not `n` or `n;m`", c.value), c.span)
                }
                Some(_) => continue,
            };
            ctx.report(
                index,
                None,
                first_span([span, m.span]),
                format!("module {}'s extension of {} {why}", m.number, idx(index)),
            );
        }
    }
}

rule!(
    C507,
    "C507",
    "connected-module-unknown",
    "cia301",
    Error,
    Deny,
    connected_module_unknown,
    "[ConnectedModules] names a module the file does not describe",
    "A DCF of a modular device lists the modules plugged in, slot by slot, in \
     [ConnectedModules] by their number in [SupportedModules] (the x of [MxModuleInfo], CiA 306 \
     §4.6). A number without its [MxModuleInfo] leaves the slot's objects undefined, and tools \
     disagree about what to do (CANopenEditor drops the slot). Fix: correct the number or add \
     the module's description."
);

fn connected_module_unknown(dev: &Device, ctx: &mut Ctx) {
    for (slot, c) in dev.modules.connected.iter().enumerate() {
        if !dev.modules.supported.iter().any(|m| m.number == c.value) {
            ctx.report_device(
                c.span,
                format!(
                    "slot {} holds module {}, which the file does not describe",
                    slot + 1,
                    c.value
                ),
            );
        }
    }
}

rule!(
    C508,
    "C508",
    "object-link-missing",
    "cia301",
    Warning,
    Warn,
    object_link_missing,
    "[IIIIObjectLinks] names an object that does not exist",
    "CiA 306 §4.5.4 lets an object name related objects ([IIIIObjectLinks]), e.g. a process \
     value and its scaling. A link to an index the dictionary does not have is a typo or a \
     left-over from an object that was removed (EdsDcfNet, CANchkEDS \"object links\"), and \
     tools that follow it show nothing. Fix: correct or remove the link."
);

fn object_link_missing(dev: &Device, ctx: &mut Ctx) {
    for o in dev.objects.values() {
        for l in &o.links {
            if !dev.objects.contains_key(&l.value) {
                ctx.report(
                    o.index,
                    None,
                    first_span([l.span, o.span]),
                    format!("{} links to {}, which does not exist", idx(o.index), idx(l.value)),
                )
                .labels
                .push(Label {
                    span: o.span,
                    message: "object here".into(),
                    primary: false,
                });
            }
        }
    }
}

rule!(
    C509,
    "C509",
    "supported-modules",
    "cia301",
    Error,
    Deny,
    supported_modules,
    "[SupportedModules] NrOfEntries disagrees with the [MxModuleInfo] sections",
    "A modular device (CiA 306 §4.6) lists its modules in [SupportedModules]: NrOfEntries=N, \
     and each module x in 1..=N is described by [MxModuleInfo] (name, version, order code), \
     with its [MxFixedObjects] and [MxSubExtends]. A count without its module descriptions, \
     a module section whose [MxModuleInfo] is missing, or a module numbered outside 1..=N \
     leaves a tool unsure which modules exist: CANopenEditor and EdsDcfNet read N and then \
     look for exactly those sections, and CANchkEDS reports the \"module description\" as \
     inconsistent. Fix: set NrOfEntries to the number of modules and give every module x in \
     1..=N its [MxModuleInfo]."
);

fn supported_modules(dev: &Device, ctx: &mut Ctx) {
    if !crate::util::is_canopen(dev) {
        return;
    }
    let modules = &dev.modules;
    let Some(n) = modules.nr_of_entries.as_ref() else {
        if let Some(m) = modules.supported.first() {
            ctx.report_device(
                m.span,
                format!(
                    "the file describes {} module(s) but has no [SupportedModules] NrOfEntries",
                    modules.supported.len()
                ),
            );
        }
        return;
    };
    for k in 1..=n.value {
        let m = modules.supported.iter().find(|m| m.number == k);
        if !m.is_some_and(|m| m.has_info) {
            let d = ctx.report_device(
                n.span,
                format!("NrOfEntries={} but [M{k}ModuleInfo] is missing", n.value),
            );
            if m.is_some() {
                d.notes.push(format!("module {k} has other [M{k}...] sections"));
            }
        }
    }
    for m in modules.supported.iter().filter(|m| m.number == 0 || m.number > n.value) {
        let what = if m.has_info {
            format!("[M{}ModuleInfo]", m.number)
        } else {
            format!("[M{}...] sections", m.number)
        };
        ctx.report_device(
            first_span([m.span, n.span]),
            format!(
                "module {} has {what} but NrOfEntries={} numbers the modules 1..={}",
                m.number, n.value, n.value
            ),
        )
        .labels
        .push(Label { span: n.span, message: "NrOfEntries here".into(), primary: false });
    }
}
