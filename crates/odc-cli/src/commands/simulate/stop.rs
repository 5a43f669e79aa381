//! When a simulation stops: at SIGINT or SIGTERM, as any server, and at the end of standard
//! input only when asked (`--stop-on-eof`). Reading standard input by default stopped the
//! server at once under `nohup`, systemd or CI (stdin /dev/null) and froze it for tty input
//! when started with `&` in a terminal.

use std::io::BufRead;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;

/// Calls `stop` once, at the first SIGINT or SIGTERM (or end of standard input when
/// `on_eof`). A second signal ends the process at once (exit 130), for a run that does not
/// stop.
pub fn on_stop(on_eof: bool, stop: impl Fn() + Send + Sync + 'static) -> anyhow::Result<()> {
    let stop = Arc::new(Once::new(stop));
    let by_signal = Arc::clone(&stop);
    ctrlc::set_handler(move || {
        if !by_signal.call() {
            std::process::exit(130);
        }
    })
    .context("cannot install the SIGINT/SIGTERM handler")?;
    if on_eof {
        std::thread::spawn(move || {
            for line in std::io::stdin().lock().lines() {
                if line.is_err() {
                    break;
                }
            }
            stop.call();
        });
    }
    Ok(())
}

/// A flag that turns true when the simulation is to stop ([`on_stop`]).
pub fn flag(on_eof: bool) -> anyhow::Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let set = Arc::clone(&flag);
    on_stop(on_eof, move || set.store(true, Ordering::Relaxed))?;
    Ok(flag)
}

/// A function called at most once, from whichever thread asks first.
struct Once<F> {
    called: AtomicBool,
    f: F,
}

impl<F: Fn()> Once<F> {
    fn new(f: F) -> Self {
        Once { called: AtomicBool::new(false), f }
    }

    /// Calls the function unless it was called before; whether it called it.
    fn call(&self) -> bool {
        if self.called.swap(true, Ordering::SeqCst) {
            return false;
        }
        (self.f)();
        true
    }
}
