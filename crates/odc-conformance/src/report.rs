//! The report: the checks in order, with counts; as terminal text, JSON or HTML.

use std::fmt::Write as _;

use serde::Serialize;

use crate::{CheckResult, Outcome};

/// Counts of a report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Checks passed.
    pub pass: usize,
    /// Checks failed.
    pub fail: usize,
    /// Checks that do not apply.
    pub not_applicable: usize,
}

/// What a run of the checks found.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The device's name in its file.
    pub device: String,
    /// The node-ID tested.
    pub node_id: u8,
    /// The counts.
    pub counts: Counts,
    /// Every check, in the order it ran.
    pub checks: Vec<CheckResult>,
}

impl Report {
    pub(crate) fn new(device: &str, node_id: u8, checks: Vec<CheckResult>) -> Self {
        let mut counts = Counts::default();
        for c in &checks {
            match c.outcome {
                Outcome::Pass { .. } => counts.pass += 1,
                Outcome::Fail { .. } => counts.fail += 1,
                Outcome::NotApplicable { .. } => counts.not_applicable += 1,
            }
        }
        Report { device: device.to_string(), node_id, counts, checks }
    }

    /// The check with identifier `id`.
    pub fn get(&self, id: &str) -> Option<&CheckResult> {
        self.checks.iter().find(|c| c.id == id)
    }

    /// The identifiers of the failed checks.
    pub fn failed(&self) -> Vec<&'static str> {
        self.checks
            .iter()
            .filter(|c| matches!(c.outcome, Outcome::Fail { .. }))
            .map(|c| c.id)
            .collect()
    }

    /// One line per check, the frames of each failure below it, and the counts.
    pub fn summary(&self) -> String {
        let mut out = format!("conformance of {} at node {}\n", self.device, self.node_id);
        for c in &self.checks {
            let (tag, text) = match &c.outcome {
                Outcome::Pass { detail } => ("pass", detail.as_str()),
                Outcome::Fail { reason, .. } => ("FAIL", reason.as_str()),
                Outcome::NotApplicable { why } => ("n/a ", why.as_str()),
            };
            let _ = writeln!(out, "{tag}  {:<28} {}: {text}", c.id, c.clause);
            if let Outcome::Fail { frames, .. } = &c.outcome {
                for f in frames.iter().take(12) {
                    let _ = writeln!(out, "        {f}");
                }
                if frames.len() > 12 {
                    let _ = writeln!(
                        out,
                        "        ... {} more frames in the report",
                        frames.len() - 12
                    );
                }
            }
        }
        let n = self.counts;
        let _ = writeln!(
            out,
            "{} passed, {} failed, {} not applicable",
            n.pass, n.fail, n.not_applicable
        );
        out
    }

    /// The report as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }

    /// The report as one HTML page.
    pub fn to_html(&self) -> String {
        let n = self.counts;
        let mut out = format!(
            "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>odc conformance: {}</title>\n\
             <style>body{{font-family:sans-serif}}td,th{{border-bottom:1px solid #ccc;padding:4px;\
             vertical-align:top;text-align:left}}.pass{{color:#060}}.fail{{color:#a00}}\
             .na{{color:#666}}pre{{margin:0}}</style></head><body>\n\
             <h1>{} at node {}</h1>\n<p>{} passed, {} failed, {} not applicable</p>\n\
             <table><tr><th>result</th><th>check</th><th>clause</th><th>what</th><th>detail</th></tr>\n",
            esc(&self.device),
            esc(&self.device),
            self.node_id,
            n.pass,
            n.fail,
            n.not_applicable
        );
        for c in &self.checks {
            let (class, tag, text, frames) = match &c.outcome {
                Outcome::Pass { detail } => ("pass", "pass", detail.clone(), String::new()),
                Outcome::Fail { reason, frames } => (
                    "fail",
                    "FAIL",
                    reason.clone(),
                    format!("<pre>{}</pre>", esc(&frames.join("\n"))),
                ),
                Outcome::NotApplicable { why } => ("na", "n/a", why.clone(), String::new()),
            };
            let _ = writeln!(
                out,
                "<tr class=\"{class}\"><td>{tag}</td><td>{}</td><td>{}</td><td>{}</td><td>{}{frames}</td></tr>",
                esc(c.id),
                esc(c.clause),
                esc(c.title),
                esc(&text)
            );
        }
        out += "</table></body></html>\n";
        out
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Group;

    fn check(id: &'static str, outcome: Outcome) -> CheckResult {
        CheckResult { id, group: Group::Sdo, clause: "CiA 301 x", title: "t", outcome }
    }

    #[test]
    fn counts_summary_json_and_html() {
        let r = Report::new(
            "Dev <1>",
            5,
            vec![
                check("sdo.a", Outcome::pass("ok")),
                check(
                    "sdo.b",
                    Outcome::Fail {
                        reason: "bad & worse".into(),
                        frames: vec!["     1 ms -> 605 [40 00 10 00 00 00 00 00]".into()],
                    },
                ),
                check("sdo.c", Outcome::na("why")),
            ],
        );
        assert_eq!(r.counts, Counts { pass: 1, fail: 1, not_applicable: 1 });
        assert_eq!(r.failed(), ["sdo.b"]);
        let text = r.summary();
        assert!(text.contains("FAIL  sdo.b "), "{text}");
        assert!(text.contains("        1 ms -> 605 [40"), "the frames under the failure: {text}");
        assert!(text.ends_with("1 passed, 1 failed, 1 not applicable\n"), "{text}");
        let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
        assert_eq!(json["checks"][1]["result"], "fail");
        assert_eq!(json["checks"][1]["reason"], "bad & worse");
        assert_eq!(json["checks"][2]["why"], "why");
        assert_eq!(json["checks"][0]["group"], "sdo");
        let html = r.to_html();
        assert!(html.contains("Dev &lt;1&gt;") && html.contains("bad &amp; worse"), "{html}");
        assert!(!html.contains("<1>"));
    }

    #[test]
    fn problems_become_one_outcome() {
        assert!(matches!(Outcome::from_problems(&[], 0, "x"), Outcome::NotApplicable { .. }));
        assert_eq!(Outcome::from_problems(&[], 3, "limits"), Outcome::pass("3 limits checked"));
        let many: Vec<String> = (0..15).map(|i| format!("p{i}")).collect();
        let Outcome::Fail { reason, .. } = Outcome::from_problems(&many, 20, "entries") else {
            panic!()
        };
        assert!(reason.starts_with("15 of 20 entries: p0; p1"), "{reason}");
        assert!(reason.ends_with("p11; and 3 more"), "{reason}");
        assert_eq!(Group::from_name("CiA402"), Some(Group::Cia402));
        assert_eq!(Group::from_name("nope"), None);
    }
}
