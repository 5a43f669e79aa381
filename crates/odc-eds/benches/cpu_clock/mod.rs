//! The clock of the EDS and ESI parse benches (odc-esi includes this file): CPU time of the
//! benchmarking thread (`/proc/thread-self/schedstat`), wall time when that is unavailable or
//! `ODC_BENCH_WALL` is set. Shared machines make wall time measure the neighbours.

use std::time::{Duration, Instant};

use criterion::Throughput;
use criterion::measurement::{Measurement, ValueFormatter};

/// CPU time of the calling thread (wall time when unavailable or `ODC_BENCH_WALL` is set).
#[derive(Clone, Copy)]
pub struct Clock {
    pub cpu: bool,
}

impl Clock {
    pub fn from_env() -> Self {
        Clock { cpu: std::env::var_os("ODC_BENCH_WALL").is_none() && thread_cpu_ns().is_some() }
    }
}

/// Nanoseconds this thread has run on a CPU (the first field of its schedstat).
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_ascii_whitespace().next()?.parse().ok()
}

impl Measurement for Clock {
    type Intermediate = (Instant, u64);
    type Value = Duration;

    fn start(&self) -> (Instant, u64) {
        (Instant::now(), if self.cpu { thread_cpu_ns().unwrap_or(0) } else { 0 })
    }
    fn end(&self, (t, cpu): (Instant, u64)) -> Duration {
        if self.cpu {
            Duration::from_nanos(thread_cpu_ns().unwrap_or(cpu).saturating_sub(cpu))
        } else {
            t.elapsed()
        }
    }
    fn add(&self, a: &Duration, b: &Duration) -> Duration {
        *a + *b
    }
    fn zero(&self) -> Duration {
        Duration::ZERO
    }
    fn to_f64(&self, v: &Duration) -> f64 {
        v.as_nanos() as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &Nanos
    }
}

/// Formats nanoseconds and decimal byte rates (what criterion's own formatter does for wall
/// time; it is not public).
struct Nanos;

impl ValueFormatter for Nanos {
    fn scale_values(&self, ns: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = match ns {
            n if n < 1e3 => (1.0, "ns"),
            n if n < 1e6 => (1e-3, "µs"),
            n if n < 1e9 => (1e-6, "ms"),
            _ => (1e-9, "s"),
        };
        values.iter_mut().for_each(|v| *v *= factor);
        unit
    }

    fn scale_throughputs(&self, typical: f64, t: &Throughput, values: &mut [f64]) -> &'static str {
        let (per, giga, mega) = match *t {
            Throughput::Bytes(n) | Throughput::BytesDecimal(n) => (n as f64, "GB/s", "MB/s"),
            Throughput::Bits(n) => (n as f64, "Gb/s", "Mb/s"),
            Throughput::Elements(n) | Throughput::ElementsAndBytes { elements: n, .. } => {
                (n as f64, "Gelem/s", "Melem/s")
            }
        };
        let (div, unit) = if per * 1e9 / typical >= 1e9 { (1e9, giga) } else { (1e6, mega) };
        values.iter_mut().for_each(|v| *v = per * 1e9 / *v / div);
        unit
    }

    fn scale_for_machines(&self, _: &mut [f64]) -> &'static str {
        "ns"
    }
}
