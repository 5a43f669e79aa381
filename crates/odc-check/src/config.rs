//! Levels, strictness and per-object allowances, read from `odc.toml` or set by a driver.

use std::collections::BTreeMap;

use odc_model::{Device, Diagnostic, FileId, Format, Registry, RuleInfo, Severity, diag};

use crate::{Level, own_rule};

/// The groups a level can be set for, besides single rules.
const GROUPS: &[&str] = &["format", "cia301", "cia402", "etg", "all"];

/// How to report: levels per rule, group or `all`; strictness; per-object allowances.
/// See the crate documentation for the `odc.toml` form.
///
/// Rule names are resolved in a [`Registry`], given when the configuration is made
/// ([`Config::in_registry`], [`Config::from_toml_in`]): the drivers' registry of every code
/// (`odc_pipeline::registry`, which knows the front-ends' `F` and the generator's `G` codes),
/// or this crate's rules alone ([`crate::rules`]). There is no `Default`: a default made of
/// this crate's rules alone refused a level set on an `F` code, and this crate cannot know the
/// others.
#[derive(Clone, Debug, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub struct Config {
    /// Warnings become errors.
    #[serde(default)]
    pub strict: bool,
    /// Levels by rule code, rule name, group or `all` (keys as written, matched
    /// case-insensitively).
    #[serde(default)]
    pub rules: BTreeMap<String, Level>,
    /// Objects a rule (code, name, group or `all`) is allowed for: `0x2003` or `0x1A00:1`.
    #[serde(default)]
    pub allow_object: BTreeMap<String, Vec<String>>,
    /// The rules names are resolved in.
    #[serde(skip, default = "crate::rules")]
    registry: Registry,
}

/// A rule or group name that no rule has.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown rule or group `{0}` (see `odc explain`)")]
pub struct UnknownRule(pub String);

/// What is wrong with an `odc.toml`.
#[derive(Clone, Debug, thiserror::Error)]
pub enum ConfigError {
    /// Not TOML, or not of the expected shape.
    #[error("odc.toml: {0}")]
    Toml(#[from] toml::de::Error),
    /// A rule name no rule has.
    #[error("odc.toml: {0}")]
    UnknownRule(#[from] UnknownRule),
    /// An object address that does not read as `0xIIII` or `0xIIII:SS`.
    #[error(
        "odc.toml: [allow-object] {rule}: `{text}` is not an object address (`0x2003`, `0x1A00:1`)"
    )]
    BadObject {
        /// The rule the address was given for.
        rule: String,
        /// The address as written.
        text: String,
    },
}

/// A rule key: a rule (by code) or a group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Key {
    Rule(&'static str),
    Group(&'static str),
}

fn resolve_key(registry: &Registry, key: &str) -> Result<Key, UnknownRule> {
    let k = key.trim();
    if let Some(g) = GROUPS.iter().find(|g| g.eq_ignore_ascii_case(k)) {
        return Ok(Key::Group(g));
    }
    registry.find(k).map(|r| Key::Rule(r.code)).ok_or_else(|| UnknownRule(key.to_string()))
}

/// An object selector of `[allow-object]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ObjectSel {
    index: u16,
    sub: Option<u8>,
}

fn parse_hex<T: TryFrom<u32>>(s: &str) -> Option<T> {
    let s = s.trim();
    let digits = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).unwrap_or(s);
    if digits.is_empty() {
        return None;
    }
    let v = u32::from_str_radix(digits, 16).ok()?;
    T::try_from(v).ok()
}

fn parse_sel(text: &str) -> Option<ObjectSel> {
    match text.split_once(':') {
        Some((i, s)) => Some(ObjectSel { index: parse_hex(i)?, sub: Some(parse_hex(s)?) }),
        None => Some(ObjectSel { index: parse_hex(text)?, sub: None }),
    }
}

impl ObjectSel {
    fn matches(self, object: Option<(u16, Option<u8>)>) -> bool {
        match object {
            Some((index, sub)) => index == self.index && (self.sub.is_none() || self.sub == sub),
            None => false,
        }
    }
}

impl Config {
    /// An empty configuration whose rule names are resolved in `registry`.
    pub fn in_registry(registry: Registry) -> Config {
        Config { strict: false, rules: BTreeMap::new(), allow_object: BTreeMap::new(), registry }
    }

    /// The same configuration, resolving names in `registry` from now on: a wider registry
    /// (the drivers' registry of every code) keeps every name already set valid.
    pub fn with_registry(mut self, registry: Registry) -> Config {
        self.registry = registry;
        self
    }

    /// The rules names are resolved in.
    pub fn registry(&self) -> &Registry {
        &self.registry
    }

    /// Reads an `odc.toml` whose rule names are resolved in `registry`.
    pub fn from_toml_in(text: &str, registry: Registry) -> Result<Config, ConfigError> {
        let mut config: Config = toml::from_str(text)?;
        config.registry = registry;
        for key in config.rules.keys() {
            config.resolve(key)?;
        }
        for (rule, objects) in &config.allow_object {
            config.resolve(rule)?;
            for text in objects {
                if parse_sel(text).is_none() {
                    return Err(ConfigError::BadObject { rule: rule.clone(), text: text.clone() });
                }
            }
        }
        Ok(config)
    }

    /// Sets the level of a rule (code or name), a group or `all`.
    pub fn set_level(&mut self, rule_or_group: &str, level: Level) -> Result<(), UnknownRule> {
        let key = self.resolve(rule_or_group)?;
        // The last setting wins over others naming the same rule or group (code vs name).
        let registry = self.registry.clone();
        self.rules.retain(|k, _| resolve_key(&registry, k).ok() != Some(key));
        self.rules.insert(rule_or_group.trim().to_string(), level);
        Ok(())
    }

    /// Turns strict mode on or off.
    pub fn strict(&mut self, on: bool) {
        self.strict = on;
    }

    /// Allows a rule (code, name, group or `all`) for one object: `0x2003` or `0x1A00:1`.
    pub fn allow_object(&mut self, rule_or_group: &str, object: &str) -> Result<(), ConfigError> {
        self.resolve(rule_or_group)?;
        if parse_sel(object).is_none() {
            return Err(ConfigError::BadObject {
                rule: rule_or_group.to_string(),
                text: object.to_string(),
            });
        }
        self.allow_object.entry(rule_or_group.trim().to_string()).or_default().push(object.into());
        Ok(())
    }

    fn resolve(&self, key: &str) -> Result<Key, UnknownRule> {
        resolve_key(&self.registry, key)
    }

    /// Whether a configured key names this rule or its group, and how specifically
    /// (2 = the rule, 1 = its group, 0 = `all`).
    fn specificity(&self, key: &str, info: &RuleInfo) -> Option<u8> {
        match self.resolve(key).ok()? {
            Key::Rule(code) if code == info.code => Some(2),
            Key::Group("all") => Some(0),
            Key::Group(g) if g == info.group => Some(1),
            _ => None,
        }
    }

    /// The configured level for a rule, if any (its own beats its group's beats `all`).
    pub fn level_of(&self, info: &RuleInfo) -> Option<Level> {
        self.rules
            .iter()
            .filter_map(|(k, &level)| Some((self.specificity(k, info)?, level)))
            .max_by_key(|&(spec, _)| spec)
            .map(|(_, level)| level)
    }

    fn allowed_for(&self, info: &RuleInfo, object: Option<(u16, Option<u8>)>) -> bool {
        object.is_some()
            && self.allow_object.iter().any(|(k, objects)| {
                self.specificity(k, info).is_some()
                    && objects.iter().filter_map(|t| parse_sel(t)).any(|s| s.matches(object))
            })
    }

    /// Applies levels to diagnostics (the front-ends' too): drops the allowed ones (by level or
    /// by object), sets severities of configured rules, turns warnings into errors when strict,
    /// and sorts by position.
    pub fn apply(&self, device: &Device, diags: Vec<Diagnostic>) -> Vec<Diagnostic> {
        // Which object a diagnostic concerns is asked only by per-object allowances; the index
        // of sections that answers it for front-end diagnostics is built on first need.
        let mut sections: Option<SectionIndex> = None;
        let mut out = Vec::with_capacity(diags.len());
        for mut d in diags {
            let info = self.registry.get(d.code);
            if let Some(info) = info {
                let level = self.level_of(info).or_else(|| {
                    own_rule(info.code).map(|r| r.level).filter(|&l| l == Level::Allow)
                });
                match level {
                    Some(Level::Allow) => continue,
                    Some(Level::Deny) => d.severity = Severity::Error,
                    Some(Level::Warn) if d.severity == Severity::Error => {
                        d.severity = Severity::Warning;
                    }
                    Some(Level::Warn) | None => {}
                }
                if !self.allow_object.is_empty() {
                    let object = d.object.or_else(|| {
                        sections.get_or_insert_with(|| SectionIndex::new(device)).object_at(&d)
                    });
                    if self.allowed_for(info, object) {
                        continue;
                    }
                }
            }
            if self.strict && d.severity == Severity::Warning {
                d.severity = Severity::Error;
            }
            out.push(d);
        }
        diag::sort(&mut out);
        out
    }
}

/// EDS sections by position: which object a span lies in, for diagnostics that do not say.
struct SectionIndex {
    starts: Vec<(FileId, u32, u16, Option<u8>)>,
}

impl SectionIndex {
    fn new(device: &Device) -> SectionIndex {
        let mut starts = Vec::new();
        if matches!(device.format, Some(Format::Eds | Format::Dcf)) {
            for o in device.objects.values() {
                if !o.span.is_dummy() {
                    starts.push((o.span.file, o.span.start, o.index, None));
                }
                if o.kind.has_subs() {
                    for s in o.subs.values() {
                        if !s.span.is_dummy() {
                            starts.push((s.span.file, s.span.start, o.index, Some(s.sub_index)));
                        }
                    }
                }
            }
            starts.sort_unstable();
        }
        SectionIndex { starts }
    }

    fn object_at(&self, d: &Diagnostic) -> Option<(u16, Option<u8>)> {
        let span = d.primary_span()?;
        let i = self.starts.partition_point(|&(f, s, _, _)| (f, s) <= (span.file, span.start));
        let &(file, _, index, sub) = self.starts.get(i.checked_sub(1)?)?;
        (file == span.file).then_some((index, sub))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_levels_and_allowances() {
        let c = Config::from_toml_in(
            "strict = true\n[rules]\nC201 = \"allow\"\ncia402 = \"deny\"\n\
             [allow-object]\nC201 = [\"0x2003\", \"1A00:1\"]\n[generate]\nx = 1\n",
            crate::rules(),
        );
        let c = match c {
            Ok(c) => c,
            Err(e) => panic!("{e}"),
        };
        assert!(c.strict);
        assert_eq!(c.rules.len(), 2);
        assert_eq!(parse_sel("1A00:1"), Some(ObjectSel { index: 0x1A00, sub: Some(1) }));
        assert_eq!(parse_sel("0x1A00:0x10"), Some(ObjectSel { index: 0x1A00, sub: Some(0x10) }));
        assert_eq!(parse_sel("0x2003"), Some(ObjectSel { index: 0x2003, sub: None }));
    }

    #[test]
    fn rejects_unknown_rules_and_bad_addresses() {
        assert!(matches!(
            Config::from_toml_in("[rules]\nno-such-rule = \"warn\"\n", crate::rules()),
            Err(ConfigError::UnknownRule(_))
        ));
        assert!(matches!(
            Config::from_toml_in("[rules]\nC201 = \"loud\"\n", crate::rules()),
            Err(ConfigError::Toml(_))
        ));
        assert!(matches!(
            Config::from_toml_in("[allow-object]\nC201 = [\"0x12345\"]\n", crate::rules()),
            Err(ConfigError::BadObject { .. })
        ));
        let mut c = Config::in_registry(crate::rules());
        assert_eq!(c.set_level("nope", Level::Warn), Err(UnknownRule("nope".into())));
        assert_eq!(c.set_level("etg", Level::Warn), Ok(()));
    }

    #[test]
    fn rule_beats_group_beats_all() {
        let mut c = Config::in_registry(crate::rules());
        let info = &crate::RULES[0].info;
        assert_eq!(c.level_of(info), None);
        assert!(c.set_level("all", Level::Allow).is_ok());
        assert_eq!(c.level_of(info), Some(Level::Allow));
        assert!(c.set_level(info.group, Level::Deny).is_ok());
        assert_eq!(c.level_of(info), Some(Level::Deny));
        assert!(c.set_level(info.name, Level::Warn).is_ok());
        assert_eq!(c.level_of(info), Some(Level::Warn));
    }
}
