//! The EDS writer: parse → write → parse gives the same model, and the writer is stable. The
//! property (and what "the same" leaves out) is crates/odc-eds/tests/it/round_trip/mod.rs, shared
//! with the regression tests of what this target found.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../../crates/odc-eds/tests/it/round_trip/mod.rs"]
mod round_trip;

fuzz_target!(|data: &[u8]| {
    round_trip::round_trip(data);
});
