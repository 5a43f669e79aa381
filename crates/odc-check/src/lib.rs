//! The odc rule registry: checks of a [`Device`] against CiA 306, CiA 301, CiA 402 and the
//! EtherCAT rules of ETG.1000/ETG.2000, each with a stable code, a kebab-case name, a group, a
//! default level and an explanation (`odc explain C303`).
//!
//! # Codes
//!
//! | range | group | what |
//! |---|---|---|
//! | `C1xx` | `cia301` | object lists and object structure (CiA 306 §4.5, CiA 301 §7.4) |
//! | `C2xx` | `cia301` | values, types, limits, mandatory objects, identity |
//! | `C3xx` | `cia301` | PDO mapping |
//! | `C4xx` | `cia301` | COB-IDs and communication objects |
//! | `C5xx` | `cia301` | DCF commissioning, modular devices, object links (CiA 306 §4.6–4.7) |
//! | `D5xx` | `cia402` | CiA 402 drives (when 0x1000, or an ESI `Profile`, says profile 402) |
//! | `T6xx` | `etg` | EtherCAT (ESI devices): PDO entries, sync managers, PDO assignment, `Exclude`, mailbox, DC |
//!
//! The front-ends have their own rules (`odc_eds::RULES`, `odc_esi::RULES`, group `format`), as
//! have the code generator (`odc_codegen::RULES`, `G6xx`) and the SII writer (`odc_sii::RULES`,
//! `S7xx`, group `sii`: what `odc sii` leaves out or refuses to fit `Eeprom/ByteSize`); this
//! crate knows none of them. A [`Config`]
//! made in the registry of every code (`odc_pipeline::registry`) applies levels to their
//! diagnostics too ([`Config::apply`]).
//!
//! # Levels
//!
//! Every rule has a default [`Level`]: `deny` (reported as an error), `warn` (a warning, or a
//! note for the rules whose default severity is a note) or `allow` (not reported). A
//! configuration sets levels per rule (code or name), per group (`format`, `cia301`, `cia402`,
//! `etg`) or for `all` rules; a rule's own setting beats its group's, which beats `all`.
//! `strict` turns every warning into an error (notes stay notes).
//!
//! # `odc.toml`
//!
//! ```toml
//! # Turn every warning into an error.
//! strict = false
//!
//! # Levels: "allow", "warn" or "deny", by rule code, rule name, group or `all`.
//! [rules]
//! C403 = "allow"
//! pdo-too-long = "warn"
//! cia402 = "deny"
//!
//! # Allowances for single objects: the rule (code, name, group or `all`) does not report
//! # problems about these objects. `0x2003` covers the object and all its sub-objects,
//! # `0x1A00:1` only that sub-object. Index and sub-index are hexadecimal, `0x` optional.
//! [allow-object]
//! C305 = ["0x2003", "0x1A00:1"]
//! ```
//!
//! Other top-level tables are left to the other odc tools that read the same file; unknown rule
//! names inside `[rules]` and `[allow-object]` and malformed addresses are errors.
//!
//! # Policies
//!
//! - `SubNumber` counts sub-objects (gaps are legal), it is not the highest sub-index;
//! - sub 0 of 0x1003 (error history), of PDO mapping objects and of the EtherCAT assignment
//!   objects 0x1C10–0x1C2F counts entries in use, so it is not compared with the highest
//!   sub-index;
//! - a `$NODEID`-relative value must be right for every node-ID 1..=127;
//! - an unsigned literal in a signed n-bit type, between 2^(n-1) and 2^n, is a two's-complement
//!   bit pattern (`0xFFFF` in an INTEGER16 is -1), as ESI files write negative limits;
//! - values of sub-objects whose stated bit size differs from their type's (ESI arrays typed by
//!   their element) are not range-checked;
//! - a diagnostic names the object it is about ([`Diagnostic::object`]); for front-end
//!   diagnostics that do not, [`Config::apply`] finds the EDS section the primary span lies in.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod config;
mod rules;
mod util;

use odc_model::{Device, Diagnostic, Registry, RuleInfo, Severity, Span};

pub use config::{Config, ConfigError, UnknownRule};

/// How a rule's findings are reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// Not reported.
    #[serde(alias = "off")]
    Allow,
    /// Reported as a warning (a note stays a note).
    #[serde(alias = "warning")]
    Warn,
    /// Reported as an error.
    #[serde(alias = "error")]
    Deny,
}

impl Level {
    /// The level a severity corresponds to: error → deny, warning and note → warn.
    pub fn from_severity(severity: Severity) -> Level {
        match severity {
            Severity::Error => Level::Deny,
            Severity::Warning | Severity::Note => Level::Warn,
        }
    }

    /// `allow`, `warn` or `deny`.
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Allow => "allow",
            Level::Warn => "warn",
            Level::Deny => "deny",
        }
    }
}

/// One rule: its description, its default level and the function that checks it.
pub struct Rule {
    /// Code, name, group, default severity, summary, explanation.
    pub info: RuleInfo,
    /// The level the rule has when nothing is configured.
    pub level: Level,
    /// Checks a device and reports through the context.
    pub check: fn(&Device, &mut Ctx),
}

/// What a rule's check function reports into.
pub struct Ctx {
    info: &'static RuleInfo,
    diags: Vec<Diagnostic>,
}

impl Ctx {
    /// A context for `info`'s rule.
    pub fn new(info: &'static RuleInfo) -> Ctx {
        Ctx { info, diags: Vec::new() }
    }

    /// The rule being checked.
    pub fn info(&self) -> &'static RuleInfo {
        self.info
    }

    /// Reports a problem about object `index` (sub-object `sub`) at `span`, with the rule's
    /// code and default severity; returns it so that notes and labels can be added.
    pub fn report(
        &mut self,
        index: u16,
        sub: Option<u8>,
        span: Span,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        let d = Diagnostic::new(self.info.default, self.info.code, message)
            .with_label(span, "")
            .with_object(index, sub);
        self.push(d)
    }

    /// Reports a problem that is not about one object.
    pub fn report_device(&mut self, span: Span, message: impl Into<String>) -> &mut Diagnostic {
        let d = Diagnostic::new(self.info.default, self.info.code, message).with_label(span, "");
        self.push(d)
    }

    fn push(&mut self, d: Diagnostic) -> &mut Diagnostic {
        self.diags.push(d);
        let last = self.diags.len() - 1;
        &mut self.diags[last]
    }

    /// The diagnostics reported so far.
    pub fn into_diagnostics(self) -> Vec<Diagnostic> {
        self.diags
    }
}

/// This crate's rules, in code order.
pub static RULES: &[Rule] = rules::ALL;

/// This crate's rules as a [`Registry`]: what a [`Config`] resolves names in by default.
/// Drivers give it the registry of every code instead (`odc_pipeline::registry`).
pub fn rules() -> Registry {
    Registry::new(RULES.iter().map(|r| &r.info))
}

/// This crate's rule with this code, if it is one.
fn own_rule(code: &str) -> Option<&'static Rule> {
    // RULES is in code order (a test holds it so).
    RULES.binary_search_by(|r| r.info.code.cmp(code)).ok().and_then(|i| RULES.get(i))
}

/// Runs every enabled rule on `device`, applies `config` and returns the diagnostics sorted by
/// position.
pub fn check(device: &Device, config: &Config) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    for rule in RULES {
        if config.level_of(&rule.info).unwrap_or(rule.level) == Level::Allow {
            continue;
        }
        let mut ctx = Ctx::new(&rule.info);
        (rule.check)(device, &mut ctx);
        diags.extend(ctx.into_diagnostics());
    }
    config.apply(device, diags)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_names_are_unique_and_well_formed() {
        let mut seen = std::collections::BTreeSet::new();
        for r in RULES {
            let i = &r.info;
            assert!(seen.insert(i.code), "duplicate code {}", i.code);
            assert!(seen.insert(i.name), "duplicate name {}", i.name);
            assert!(
                i.name.chars().all(|c| c.is_ascii_lowercase() || c == '-' || c.is_ascii_digit()),
                "{} is not kebab-case",
                i.name
            );
            let group = match i.code.as_bytes().first() {
                Some(b'C') => "cia301",
                Some(b'D') => "cia402",
                Some(b'T') => "etg",
                _ => "?",
            };
            assert_eq!(i.group, group, "{}", i.code);
            assert!(!i.summary.is_empty() && !i.explanation.is_empty(), "{}", i.code);
            assert!(i.explanation.len() > 120, "{} explanation too short", i.code);
            assert_eq!(
                Level::from_severity(i.default) == Level::Deny,
                r.level == Level::Deny,
                "{}: level and default severity disagree",
                i.code
            );
        }
        let codes: Vec<_> = RULES.iter().map(|r| r.info.code).collect();
        let mut sorted = codes.clone();
        sorted.sort_unstable();
        assert_eq!(codes, sorted, "RULES is in code order");
    }

    #[test]
    fn the_registry_finds_by_code_and_name() {
        let first = &RULES[0].info;
        assert_eq!(rules().find(first.code).map(|r| r.code), Some(first.code));
        assert_eq!(rules().find(&first.name.to_uppercase()).map(|r| r.code), Some(first.code));
        assert!(rules().find("no-such-rule").is_none());
        assert_eq!(rules().len(), RULES.len());
    }
}
