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
    // `None`: every node.
    let node = if args.node.eq_ignore_ascii_case("all") {
        None
    } else {
        let id = parse_u64(&args.node)
            .and_then(|n| u8::try_from(n).ok())
            .and_then(odc::cob::NodeId::new)
            .ok_or_else(|| anyhow::anyhow!("`{}`: a node-ID is 1..=127, or `all`", args.node))?;
        Some(id)
    };
    let command = match args.command {
        Command::Start => NmtCommand::Start,
        Command::Stop => NmtCommand::Stop,
        Command::Preop => NmtCommand::EnterPreOperational,
        Command::Reset => NmtCommand::ResetNode,
        Command::ResetComm => NmtCommand::ResetCommunication,
    };
    let mut master = Master::new(args.bus.open()?);
    match node {
        Some(n) => master.nmt(command, n),
        None => master.nmt_all(command),
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let [cs, target] = command.frame(node);
    let to = node.map_or_else(|| "all nodes".to_owned(), |n| format!("node {n}"));
    super::out(&format!("000  {cs:02X} {target:02X}  NMT {command:?} to {to}\n"))?;
    Ok(ExitCode::SUCCESS)
}
