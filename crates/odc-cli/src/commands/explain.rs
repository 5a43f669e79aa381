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
    let rule = odc_check::explain(&args.code).ok_or_else(|| {
        anyhow::anyhow!("no rule has the code or name `{}`; `odc lints` lists them", args.code)
    })?;
    println!(
        "{} ({}, group {}, default {})\n",
        rule.code,
        rule.name,
        rule.group,
        rule.default.as_str()
    );
    println!("{}\n", rule.summary);
    println!("{}", rule.explanation.trim_end());
    Ok(ExitCode::SUCCESS)
}

pub fn lints(_: LintsArgs) -> anyhow::Result<ExitCode> {
    let rules = odc_check::all_rules();
    let width = rules.iter().map(|r| r.name.len()).max().unwrap_or(0);
    for r in rules {
        println!(
            "{:<5} {:<width$}  {:<7} {:<8} {}",
            r.code,
            r.name,
            r.group,
            r.default.as_str(),
            r.summary
        );
    }
    Ok(ExitCode::SUCCESS)
}
