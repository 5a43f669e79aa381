//! The registry of diagnostic codes: every rule a checker configuration, `odc explain` and
//! `odc lints` know. Each crate that emits diagnostics lists its own rules; the drivers
//! assemble them into one registry (`odc_pipeline::registry`), so that the checker needs no
//! knowledge of the front-ends or the code generator.

use std::sync::Arc;

use crate::diag::RuleInfo;

/// A set of rules, sorted by code. Cloning is cheap (shared).
#[derive(Clone, Debug, Default)]
pub struct Registry {
    rules: Arc<[&'static RuleInfo]>,
}

impl Registry {
    /// These rules, sorted by code (a code given twice is kept once).
    pub fn new(rules: impl IntoIterator<Item = &'static RuleInfo>) -> Registry {
        let mut rules: Vec<&'static RuleInfo> = rules.into_iter().collect();
        rules.sort_by_key(|r| r.code);
        rules.dedup_by_key(|r| r.code);
        Registry { rules: rules.into() }
    }

    /// The rule with this code.
    pub fn get(&self, code: &str) -> Option<&'static RuleInfo> {
        let i = self.rules.binary_search_by(|r| r.code.cmp(code)).ok()?;
        self.rules.get(i).copied()
    }

    /// The rule with this code or kebab-case name, in any case.
    pub fn find(&self, code_or_name: &str) -> Option<&'static RuleInfo> {
        let key = code_or_name.trim();
        self.rules
            .iter()
            .find(|r| r.code.eq_ignore_ascii_case(key) || r.name.eq_ignore_ascii_case(key))
            .copied()
    }

    /// Every rule, in code order.
    pub fn iter(&self) -> impl Iterator<Item = &'static RuleInfo> + '_ {
        self.rules.iter().copied()
    }

    /// The number of rules.
    pub fn len(&self) -> usize {
        self.rules.len()
    }

    /// Whether there is no rule.
    pub fn is_empty(&self) -> bool {
        self.rules.is_empty()
    }
}
