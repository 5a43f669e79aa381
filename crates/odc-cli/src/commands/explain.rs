//! `odc explain` and `odc lints`: the rule registry, for people.

use std::process::ExitCode;

/// Explain a diagnostic code or rule name (e.g. `odc explain C301`).
#[derive(clap::Args)]
pub struct Args {
    /// Code (`C301`) or kebab-case name.
    code: String,
}

/// List every rule: code, name, group, default level, summary.
#[derive(clap::Args)]
pub struct LintsArgs {}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let rule = odc_pipeline::registry().find(&args.code).ok_or_else(|| {
        anyhow::anyhow!("no rule has the code or name `{}`; `odc lints` lists them", args.code)
    })?;
    super::out(&format!(
        "{} ({}, group {}, default {})\n\n{}\n\n{}\n",
        rule.code,
        rule.name,
        rule.group,
        rule.default.as_str(),
        rule.summary,
        rule.explanation.trim_end()
    ))?;
    Ok(ExitCode::SUCCESS)
}

pub fn lints(_: LintsArgs) -> anyhow::Result<ExitCode> {
    let rules: Vec<_> = odc_pipeline::registry().iter().collect();
    let width = rules.iter().map(|r| r.name.len()).max().unwrap_or(0);
    let table: String = rules
        .iter()
        .map(|r| {
            let level = r.default.as_str();
            format!("{:<5} {:<width$}  {:<7} {level:<8} {}\n", r.code, r.name, r.group, r.summary)
        })
        .collect();
    super::out(&table)?;
    Ok(ExitCode::SUCCESS)
}
