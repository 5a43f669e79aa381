//! Cross-format truth: the corpus devices that ship as both EDS/DCF and XDD (files sharing a
//! stem) lower to the same dictionary, object by object and sub-object by sub-object (type,
//! access, PDO mapping, default, limits). Every difference is in the snapshot, with the
//! explanation of who is right in `explain` (the files themselves often disagree).
//!
//! The comparison is `odc diff`'s (`odc_diff::diff`), so the snapshot is also what `odc diff`
//! says of each pair. It reads an empty string default and none as the same value (CiA 306
//! writes an empty VISIBLE_STRING as `DefaultValue=`), as this test's verdict already did.

#![allow(clippy::unwrap_used, clippy::panic)]

use std::fmt::Write as _;

use odc_diff::{Place, What};
use odc_model::{Device, Sources};
use odc_tests_corpus::{files, path};

fn eds(file: &str) -> Device {
    odc_eds::parse(&mut Sources::new(), file, &std::fs::read(path(file)).unwrap()).device
}

fn xdd(file: &str) -> Device {
    let p = odc_xdd::parse(&mut Sources::new(), file, &std::fs::read(path(file)).unwrap());
    p.device.unwrap()
}

fn stem(f: &str) -> &str {
    let name = f.rsplit('/').next().unwrap();
    name.rsplit_once('.').map_or(name, |(s, _)| s)
}

/// The differences between the two dictionaries, one line each, and the number of
/// sub-objects compared: `odc diff`'s comparison (names, comments and the file's own
/// information left out), in this test's words.
fn compare(e: &Device, x: &Device, out: &mut Vec<String>) -> usize {
    let compared = e
        .objects
        .iter()
        .filter_map(|(i, eo)| Some((eo, x.objects.get(i)?)))
        .map(|(eo, xo)| eo.subs.keys().filter(|s| xo.subs.contains_key(s)).count())
        .sum();
    let opts =
        odc_diff::Options { ignore_names: true, ignore_comments: true, ignore_defaults: false };
    for c in odc_diff::diff(e, x, &opts) {
        let (at, var) = match c.place {
            Place::Object { index } => (format!("{index:04X}"), true),
            Place::Sub { index, sub } => (format!("{index:04X}sub{sub:X}"), false),
            // Identity, capabilities, PDOs, images: not this test's question.
            _ => continue,
        };
        match c.what {
            What::Added { .. } => out.push(format!("{at}: only in the XDD")),
            What::Removed { .. } => out.push(format!("{at}: only in the EDS")),
            What::Changed { field, a, b } => {
                // A VAR's own fields are its sub-object 0's.
                let at = if var && field != "object code" { format!("{at}sub0") } else { at };
                let (what, a, b) = match field.as_str() {
                    "object code" => ("object type", kind(&a), kind(&b)),
                    "data type" => ("type", a, b),
                    "access" => ("access", capitalised(&a), capitalised(&b)),
                    "PDO mapping" => ("PDO mapping", dirs(&a), dirs(&b)),
                    "default" | "low limit" | "high limit" => (field.as_str(), val(&a), val(&b)),
                    // Configured values and object flags: not compared here.
                    _ => continue,
                };
                out.push(format!("{at}: {what} EDS {a}, XDD {b}"));
            }
        }
    }
    compared
}

/// `ARRAY` as this test has always written it (`Array`).
fn kind(code: &str) -> String {
    match code {
        "DEFTYPE" => "DefType".into(),
        "DEFSTRUCT" => "DefStruct".into(),
        other => capitalised(other),
    }
}

fn capitalised(s: &str) -> String {
    let lower = s.to_lowercase();
    let mut c = lower.chars();
    c.next().map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

/// The PDO directions in this test's words.
fn dirs(s: &str) -> String {
    match s {
        "RPDO/TPDO" => "rx+tx",
        "RPDO" => "rx",
        "TPDO" => "tx",
        other => other,
    }
    .to_owned()
}

fn val(v: &str) -> String {
    if v.is_empty() { "-".to_owned() } else { format!("`{v}`") }
}

/// Who is right about a difference, read from both files (CiA 306 for the EDS, CiA 311 for
/// the XDD, CiA 301 for the objects). `pair` is the EDS file, `line` the difference.
fn verdict(pair: &str, line: &str) -> &'static str {
    let (at, what) = line.split_once(": ").unwrap_or(("", line));
    let sub0_1003 = at == "1003sub0";
    let mapping_count = at.len() == 8
        && at.ends_with("sub0")
        && (at.starts_with("16")
            || at.starts_with("17")
            || at.starts_with("1A")
            || at.starts_with("1B"));
    match what {
        _ if what.starts_with("only in the") => {
            "the files disagree: an object or sub-object one file has and the other lacks (the two \
             were edited apart); not a reading difference"
        }
        "PDO mapping EDS tx, XDD rx" if pair.contains("iota2") => {
            "both files are broken here: the EDS's AccessType=UNKNOWN (F115) and the XDD's \
             noAccess (F319) both read as ro, and only the XDD adds RPDO; neither is right"
        }
        "PDO mapping EDS tx, XDD rx" if at.starts_with("6200") => {
            "0x6200 (CiA 401 write output 8-bit) is UNSIGNED8, rww: the XDD is right, the DCF is \
             wrong"
        }
        "PDO mapping EDS tx, XDD rx" => {
            "the XDD contradicts itself: an access on the TPDO side (readWriteInput, CiA 311's \
             read/write on process input, CiA 306 rwr; in one case a parameter without access, \
             read) with PDOmapping=\"RPDO\"; the EDS (rwr or ro, PDOMapping=1: TPDO) is \
             consistent. The EDS is right"
        }
        "access EDS Rww, XDD Rw" | "PDO mapping EDS rx, XDD rx+tx" => {
            "the XDD lost the direction: the EDS says rww (RPDO only); CiA 311 spells that \
             readWriteOutput, and the XDD says readWrite, mappable (optional or default: either \
             direction). The EDS is right"
        }
        "access EDS Const, XDD Rw" | "default EDS `0x8`, XDD `0x0`" if sub0_1003 => {
            "0x1003 sub 0 is the number of errors, rw, 0 at start (CiA 301 7.5.2.3); the EDS \
             says const with the array size. The XDD is right"
        }
        _ if mapping_count && (what.starts_with("access") || what.starts_with("default")) => {
            "the files disagree on whether a PDO mapping is fixed: the EDS says sub 0 (number of \
             mapped objects) is const with the entries it lists (static mapping), the XDD rw with \
             0 (configurable, nothing mapped). CiA 301 allows both; the two describe different \
             builds of the device"
        }
        "access EDS Const, XDD Ro" => {
            "the files disagree on a highest-sub-index entry: const against read; both forbid \
             writing, so a master reads it the same; not a conflict in practice"
        }
        "type EDS DOMAIN, XDD OCTET_STRING" => {
            "the XDD lost the type: it says DOMAIN as the IEC type BITSTRING without a dataType \
             attribute, which CiA 311 reads as OCTET_STRING. The EDS is right"
        }
        "type EDS 0x0040, XDD INTEGER32" | "low limit EDS `0x3`, XDD `3`" => {
            "the EDS's type is the manufacturer type 0x0040 its own DEFTYPE object defines; the \
             XDD gives the IEC type DINT. The EDS is more precise; the values are the same number"
        }
        "type EDS BOOLEAN, XDD UNSIGNED8" | "access EDS Rwr, XDD Rww" => {
            "0x6200 (CiA 401 write output 8-bit) is UNSIGNED8, rww: the XDD is right, the DCF is \
             wrong"
        }
        _ if what.starts_with("default EDS") && what.ends_with("XDD -") => {
            "the XDD gives no default where the EDS gives one: the XDD is incomplete, the EDS \
             has more"
        }
        _ if what.starts_with("default EDS") => {
            "the files disagree on the value (edited apart: e.g. a different device type, \
             heartbeat or name); which is right is the device's to say, not a standard's"
        }
        _ => {
            "the files disagree (type, access, object type or PDO mapping of a manufacturer \
             object, edited apart); no standard decides, each front-end reads its file as written"
        }
    }
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn eds_and_xdd_twins_agree() {
    let xdds = files(&["xdd"]);
    let edss = files(&["eds", "dcf"]);
    let mut report = String::new();
    // Verdicts in order of first use, with their counts; each line names its own.
    let mut verdicts: Vec<(&str, usize)> = Vec::new();
    let (mut pairs, mut total_objects, mut total_subs, mut total_diffs) = (0, 0, 0, 0);
    for x in &xdds {
        for e in edss.iter().filter(|e| stem(e) == stem(x)) {
            let (ed, xd) = (eds(e), xdd(x));
            let mut diffs = Vec::new();
            let subs = compare(&ed, &xd, &mut diffs);
            let objects = ed.objects.keys().filter(|i| xd.objects.contains_key(i)).count();
            pairs += 1;
            total_objects += objects;
            total_subs += subs;
            total_diffs += diffs.len();
            let _ = writeln!(
                report,
                "\n## {e} / {x}: {objects} objects, {subs} sub-objects compared, {} differences",
                diffs.len()
            );
            for d in diffs {
                let v = verdict(e, &d);
                let k = match verdicts.iter().position(|(t, _)| *t == v) {
                    Some(k) => k,
                    None => {
                        verdicts.push((v, 0));
                        verdicts.len() - 1
                    }
                };
                verdicts[k].1 += 1;
                let _ = writeln!(report, "{d}  [V{}]", k + 1);
            }
        }
    }
    let mut head = format!(
        "{pairs} pairs, {total_objects} objects and {total_subs} sub-objects compared, \
         {total_diffs} differences\n\n# Who is right (each difference names its verdict)\n"
    );
    for (k, (v, n)) in verdicts.iter().enumerate() {
        let _ = writeln!(head, "V{}: {n} differences: {v}", k + 1);
    }
    insta::assert_snapshot!(head + &report);
}
