//! `odc nmt`: an NMT command to one node or all.

use std::process::ExitCode;

use odc::master::Master;
use odc::nmt::NmtCommand;

use super::link::{BusArgs, parse_u64};

/// Send an NMT command (CiA 301 7.2.8.3.1) to one node or to all.
#[derive(clap::Args)]
pub struct Args {
    /// The command.
    command: Command,
    /// The node-ID (1..=127), or `all` (node-ID 0 in the frame).
    #[arg(default_value = "all")]
    node: String,
    #[command(flatten)]
    bus: BusArgs,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Command {
    /// Start remote node (to operational).
    Start,
    /// Stop remote node (to stopped).
    Stop,
    /// Enter pre-operational.
    Preop,
    /// Reset node (application and communication).
    Reset,
    /// Reset communication.
    ResetComm,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let node = if args.node.eq_ignore_ascii_case("all") {
        0
    } else {
        parse_u64(&args.node)
            .and_then(|n| u8::try_from(n).ok())
            .filter(|n| (1..=127).contains(n))
            .ok_or_else(|| anyhow::anyhow!("`{}`: a node-ID is 1..=127, or `all`", args.node))?
    };
    let command = match args.command {
        Command::Start => NmtCommand::Start,
        Command::Stop => NmtCommand::Stop,
        Command::Preop => NmtCommand::EnterPreOperational,
        Command::Reset => NmtCommand::ResetNode,
        Command::ResetComm => NmtCommand::ResetCommunication,
    };
    let mut master = Master::new(args.bus.open()?);
    master.nmt(command, node).map_err(|e| anyhow::anyhow!("{e}"))?;
    let to = if node == 0 { "all nodes".to_owned() } else { format!("node {node}") };
    super::out(&format!("000  {:02X} {node:02X}  NMT {command:?} to {to}\n", command as u8))?;
    Ok(ExitCode::SUCCESS)
}
