//! `odc simulate --slcan`: the simulated device behind an slcan adapter. odc plays the adapter
//! (it answers `O`, `S6`, `V`… and carries `t` frames, `odc::transport::slcan`), so a host
//! that speaks slcan (python-can's `slcan` interface, `odc sdo --slcan`, slcand) drives the
//! device as it would a real one behind a CANable.
//!
//! `--slcan pty` makes a pseudo-terminal and prints `listening on /dev/pts/N` first (as
//! `--tcp` prints its address): the host opens that path. odc keeps the path's end open
//! itself, so hosts come and go (each `odc sdo` opens and closes it) without the device ever
//! reading an end-of-file. `--slcan DEVICE` acts as the adapter on an existing serial port
//! or pseudo-terminal end (a null-modem cable, a pty made by a test).

use std::process::ExitCode;
use std::sync::atomic::Ordering;

use anyhow::{Context, bail};
use odc::transport::slcan::serial::{Slcan, TTY_BAUD};
use odc_sim::SimDevice;

use super::stop;

/// Runs `devices` (one bus behind the adapter) as the adapter on `spec` (`pty` or a serial
/// device) until a signal (or the end of standard input, when asked).
pub fn run(spec: &str, devices: &mut [SimDevice], stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    let (mut bus, _host_end) = if spec == "pty" {
        let (adapter, host_end) = pty()?;
        (adapter, Some(host_end))
    } else {
        let port = serialport::new(spec, TTY_BAUD)
            .timeout(std::time::Duration::from_millis(100))
            .open()
            .with_context(|| format!("--slcan {spec}: cannot open the serial port"))?;
        elog!("adapter on {spec}");
        (Slcan::adapter(port), None)
    };
    let stop = stop::flag(stop_on_eof)?;
    let tick_ms = u64::try_from(odc_sim::TICK.as_millis()).unwrap_or(10);
    odc_sim::run_all_on_bus(&mut bus, devices, tick_ms, || stop.load(Ordering::Relaxed))
        .with_context(|| format!("--slcan {spec}"))?;
    Ok(ExitCode::SUCCESS)
}

/// A pseudo-terminal: the adapter on its master end, and its slave end (the path a host
/// opens) held open, after printing that path.
#[cfg(unix)]
fn pty() -> anyhow::Result<(Slcan, Box<dyn serialport::SerialPort>)> {
    let (master, slave) =
        serialport::TTYPort::pair().context("--slcan pty: cannot make a pseudo-terminal")?;
    let Some(path) = serialport::SerialPort::name(&slave) else {
        bail!("--slcan pty: the pseudo-terminal has no path")
    };
    super::super::out_flushed(&format!("listening on {path}\n"))?;
    Ok((Slcan::adapter(Box::new(master)), Box::new(slave)))
}

#[cfg(not(unix))]
fn pty() -> anyhow::Result<(Slcan, Box<dyn serialport::SerialPort>)> {
    bail!("--slcan pty: pseudo-terminals are a Unix thing; give a serial port (COM3)")
}
