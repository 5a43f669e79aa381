//! The ethercrab sweep (#31): every corpus ESI device with a mailbox or process data, simulated
//! (the emulated ESC running odc's firmware stack) and brought up by ethercrab as its own
//! default does it, in process: `init_single_group` (INIT → PRE-OP), `into_pre_op_pdi` (PDO
//! assignment read over CoE or from the SII, FMMUs), SAFE-OP, OP, then 1,000 `tx_rx` cycles,
//! each checked against the expected working counter (an LRW counts 2 for a device it writes
//! and 1 for a device it reads, ETG.1000.4 Table 7).
//!
//! Shared by the hand-run program (`examples/crabsweep.rs`, the whole corpus or `--sample N`)
//! and the sample in `tests/ethercat_ethercrab.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, dead_code)]

use std::path::Path;
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use odc_model::Device;
use odc_sim::ethercat::{Chain, EthercrabLink, SubDevice};

/// Cycles a device runs in OP.
pub const CYCLES: u32 = 1000;
const MAX_FRAMES: usize = 16;
/// A whole Ethernet frame of datagrams (1,500 bytes less the EtherCAT header, one datagram's
/// header and working counter): ethercrab's examples use 1,100, which a few corpus mailboxes
/// exceed.
const MAX_PDU_DATA: usize = PduStorage::element_size(1486);
/// The largest process image of a corpus device fits (ethercrab sends it in frame-sized chunks).
const MAX_PDI: usize = 8192;

/// How far a device came.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// odc could not build the simulated device (its SII image).
    Build,
    /// `init_single_group`: found, SII read, mailboxes set, PRE-OP requested.
    Init,
    /// `into_pre_op_pdi`: PDO assignment read and FMMUs configured.
    Pdi,
    /// SAFE-OP requested.
    SafeOp,
    /// OP requested.
    Op,
    /// The cycles in OP.
    Cycles,
    /// Everything passed.
    Done,
}

impl Stage {
    /// Its name in the TSV.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Build => "build",
            Stage::Init => "init",
            Stage::Pdi => "pre-op-pdi",
            Stage::SafeOp => "safe-op",
            Stage::Op => "op",
            Stage::Cycles => "cycles",
            Stage::Done => "done",
        }
    }
}

/// One device's result: a TSV row.
#[derive(Clone, Debug)]
pub struct Row {
    /// The corpus file (manifest name) and the device's position in it.
    pub file: String,
    pub index: usize,
    pub name: String,
    pub product: u32,
    pub revision: u32,
    /// The stage that failed, or [`Stage::Done`].
    pub stage: Stage,
    /// ethercrab's error (or the wrong working counter, or a panic), empty when done.
    pub error: String,
    /// The simulated device's AL status (0x0130) and AL status code (0x0134) at the end.
    pub al_status: u8,
    pub al_code: u16,
    /// Process image sizes ethercrab computed.
    pub out_bytes: usize,
    pub in_bytes: usize,
    pub expected_wkc: u16,
    /// Cycles answered with the expected working counter.
    pub cycles_ok: u32,
    pub millis: u128,
    /// For a device that failed: the codes `odc check` gives it (distinct, sorted), to name
    /// the rule that flags an ESI's fault.
    pub check: String,
    /// For a device that failed: its class ([`classify`], tests/ethercat-sweep/ethercrab.md).
    pub class: String,
}

impl Row {
    /// The TSV header.
    pub const HEADER: &str = "file\tindex\tname\tproduct\trevision\tstage\tal_status\tal_code\t\
                              out_bytes\tin_bytes\texpected_wkc\tcycles_ok\tms\terror\tcheck\tclass";

    /// The row as TSV (tabs and newlines of the error text made spaces).
    pub fn tsv(&self) -> String {
        let error: String =
            self.error.chars().map(|c| if c == '\t' || c == '\n' { ' ' } else { c }).collect();
        format!(
            "{}\t{}\t{}\t{:#010x}\t{:#010x}\t{}\t{:#04x}\t{:#06x}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}",
            self.file,
            self.index,
            self.name,
            self.product,
            self.revision,
            self.stage.name(),
            self.al_status,
            self.al_code,
            self.out_bytes,
            self.in_bytes,
            self.expected_wkc,
            self.cycles_ok,
            self.millis,
            error,
            self.check,
            self.class
        )
    }

    /// Whether it reached OP.
    pub fn reached_op(&self) -> bool {
        self.stage >= Stage::Cycles
    }
}

/// The clock both sides use: ns since the first use.
pub fn now() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

/// Whether the sweep takes the device: it has a mailbox or process data.
pub fn eligible(device: &Device) -> bool {
    device.ethercat.as_deref().is_some_and(|e| e.mailbox.is_some()) || !device.pdos.is_empty()
}

/// The devices of the corpus's ESI files, in manifest and file order: (file, index, device).
pub fn corpus_devices(corpus: &Path) -> Vec<(String, usize, Device)> {
    let manifest = std::fs::read_to_string(corpus.join("MANIFEST.tsv")).unwrap();
    let files = manifest.lines().skip(1).filter_map(|l| {
        let mut cols = l.split('\t');
        let file = cols.next()?;
        (cols.next()? == "esi").then(|| file.to_owned())
    });
    let mut out = Vec::new();
    for file in files {
        out.extend(file_devices(corpus, &file));
    }
    out
}

/// The devices of one corpus ESI file, as odc loads them (`odc_pipeline`, every device).
pub fn file_devices(corpus: &Path, file: &str) -> Vec<(String, usize, Device)> {
    let options = odc_pipeline::Options { source_hash: false, ..odc_pipeline::Options::new() };
    match odc_pipeline::load(&corpus.join(file), &options) {
        Ok(loaded) => {
            loaded.devices.into_iter().enumerate().map(|(i, d)| (file.to_owned(), i, d)).collect()
        }
        Err(e) => {
            eprintln!("{file}: not loaded: {e}");
            Vec::new()
        }
    }
}

/// The last panic message of any thread (the link's thread included): a panic is odc's fault
/// and the row says so.
fn last_panic() -> &'static Mutex<Option<String>> {
    static LAST: OnceLock<Mutex<Option<String>>> = OnceLock::new();
    LAST.get_or_init(|| Mutex::new(None))
}

/// Records panics (once per process) instead of printing them.
pub fn catch_panics() {
    static ONCE: OnceLock<()> = OnceLock::new();
    ONCE.get_or_init(|| {
        std::panic::set_hook(Box::new(|info| {
            let message = format!("panic: {info}");
            *last_panic().lock().unwrap_or_else(|e| e.into_inner()) = Some(message);
        }));
    });
}

/// A master on a PDU storage of its own (`try_split` works once per storage: each device's
/// 24 KiB storage is leaked, as a program's static would be).
fn master(chain: Chain) -> (MainDevice<'static>, EthercrabLink) {
    let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().unwrap();
    let link = EthercrabLink::start(tx, rx, chain, now);
    // ethercrab's defaults but for the timeouts: the EEPROM and PDU ones longer (the link's
    // thread may wait for a core on a loaded machine), the state transition shorter (ethercrab
    // waits the whole timeout on a refused transition, whose answer here is immediate).
    let timeouts = Timeouts {
        eeprom: Duration::from_millis(500),
        pdu: Duration::from_millis(500),
        state_transition: Duration::from_millis(500),
        ..Timeouts::default()
    };
    (MainDevice::new(pdu_loop, timeouts, MainDeviceConfig::default()), link)
}

/// Runs one device through the bring-up and the cycles.
pub fn run(file: &str, index: usize, device: &Device) -> Row {
    let started = Instant::now();
    let ecat = device.ethercat.as_deref();
    let mut row = Row {
        file: file.to_owned(),
        index,
        name: device.name().to_owned(),
        product: ecat.and_then(|e| e.product_code).unwrap_or(0),
        revision: ecat.and_then(|e| e.revision).unwrap_or(0),
        stage: Stage::Build,
        error: String::new(),
        al_status: 0,
        al_code: 0,
        out_bytes: 0,
        in_bytes: 0,
        expected_wkc: 0,
        cycles_ok: 0,
        millis: 0,
        check: String::new(),
        class: String::new(),
    };
    *last_panic().lock().unwrap_or_else(|e| e.into_inner()) = None;
    let built = std::panic::catch_unwind(|| SubDevice::new(device));
    let sim = match built {
        Ok(Ok(sim)) => sim,
        Ok(Err(e)) => {
            row.error = format!("no simulated device: {e}");
            return row;
        }
        Err(_) => {
            row.error = panic_text();
            return row;
        }
    };
    let (maindevice, link) = master(Chain::new(vec![sim]));
    let result =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| bring_up(&maindevice, &mut row)));
    {
        let chain = link.chain();
        let sim = &chain.devices()[0];
        row.al_status = sim.al_state() | if sim.al_status_code() != 0 { 0x10 } else { 0 };
        row.al_code = sim.al_status_code();
    }
    link.stop();
    if result.is_err() || last_panic().lock().unwrap_or_else(|e| e.into_inner()).is_some() {
        row.error = format!("{} ({})", panic_text(), row.error);
        if row.stage == Stage::Done {
            row.stage = Stage::Cycles;
        }
    }
    row.millis = started.elapsed().as_millis();
    if row.stage != Stage::Done {
        row.check = check_codes(device);
        row.class = classify(&row, device).into();
    }
    row
}

/// Whether ethercrab's error is a timeout a loaded machine explains (a PDU or the EEPROM not
/// answered within 500 ms): the device is run once more.
pub fn timed_out(row: &Row) -> bool {
    ["Timeout(Pdu)", "Timeout(Eeprom)", "Timeout(MailboxResponse)"]
        .iter()
        .any(|t| row.error.contains(t))
}

/// The class of a failed device, with the standard's words (tests/ethercat-sweep/ethercrab.md
/// names each): from the stage it stopped at, the AL status code the simulated device gave
/// (ETG.1000.6 Table 11), ethercrab's error, the `odc check` codes of its ESI and what the ESI
/// declares. `unclassified: …` for a failure no rule explains.
pub fn classify(row: &Row, device: &Device) -> &'static str {
    use odc_model::ethercat::SmUsage;
    let code = |c: &str| row.check.split(',').any(|x| x == c);
    let ecat = device.ethercat.as_deref();
    let eeprom = ecat.and_then(|e| e.eeprom.as_ref());
    // `Eeprom/ByteSize` 128: the 64-word info area and no category (odc sii: S702).
    let info_only = eeprom.and_then(|e| e.byte_size).is_some_and(|b| b <= 128);
    // The ESI's own categories, written as given (ETG.2000), in another layout than ETG.2010's:
    // a SyncManager category (41) not in 8-byte records, a General one (30) under 32 bytes.
    let own = |cat: u16, bad: &dyn Fn(usize) -> bool| {
        eeprom.is_some_and(|e| e.categories.iter().any(|c| c.cat_no == cat && bad(c.data.len())))
    };
    let fmmus = ecat.map_or(&[][..], |e| &e.fmmus[..]);
    let odd_fmmu = fmmus.iter().any(|f| matches!(f.usage, SmUsage::Other(_)));
    // A process data SM not declared enabled (`Enable="0"`, or no `Enable`: odc reads it as
    // 0 and the SII says disabled) that carries a default PDO, on a device with firmware.
    let emulation = eeprom.is_some_and(|e| e.config_data.get(1).is_some_and(|b| b & 1 != 0));
    let disabled_pd = ecat.is_some_and(|e| {
        e.sync_managers.iter().any(|sm| {
            matches!(sm.usage, SmUsage::Outputs | SmUsage::Inputs)
                && !sm.enable
                && device.pdos.iter().any(|p| p.sync_manager == Some(sm.number))
        })
    }) && !emulation;
    let mapping = matches!(row.al_code, 0x0024 | 0x0025);
    match row.stage {
        Stage::Init if row.error.contains("SectionOverrun") && own(30, &|n| n < 32) => {
            "ESI: its own General category (CatNo 30) shorter than ETG.2010's 32 bytes"
        }
        Stage::Init if row.al_code == 0x0016 && info_only => {
            "ESI: Eeprom/ByteSize holds the SII info area only (S702): no mailbox SM (AL 0x0016)"
        }
        Stage::Init if row.al_code == 0x0016 && code("T624") => {
            "ESI: T624, mailbox sync managers declared disabled (AL 0x0016)"
        }
        Stage::Init if row.al_code == 0x0016 && code("T606") => {
            "ESI: T606, mailbox DefaultSize outside MinSize..MaxSize (AL 0x0016)"
        }
        Stage::Init if row.al_code == 0x0016 && (code("T613") || code("T614")) => {
            "ESI: T613/T614, a mailbox SM without a size or with another type (AL 0x0016)"
        }
        Stage::Init if row.al_code == 0x0016 && own(41, &|n| n % 8 != 0) => {
            "ESI: its own SyncManager category (CatNo 41) not in 8-byte records (AL 0x0016)"
        }
        Stage::Pdi if row.error.contains("item: Fmmu") && odd_fmmu => {
            "ESI: FMMU types other than ETG.2000's Outputs, Inputs, MBoxState"
        }
        Stage::Pdi if row.error.contains("item: Fmmu") => {
            "ethercrab: requires an FMMU category where ETG.2000 makes Fmmu optional"
        }
        Stage::Pdi if row.error.contains("Aborted") && row.error.contains("address: 0,") => {
            "ESI: T608, an assignment default counting PDO 0x0000"
        }
        Stage::Pdi if row.error.contains("Aborted") => {
            "ESI: an assigned PDO or mapped entry the dictionary lacks (SDO abort)"
        }
        Stage::Pdi if row.error.contains("ReadBufferTooShort") => {
            "ESI: F218, mapping entries typed UNSIGNED8, not UNSIGNED32"
        }
        Stage::SafeOp if mapping && code("T601") => {
            "ESI: T601, a mapped object the dictionary lacks (AL 0x0024/0x0025)"
        }
        Stage::SafeOp if mapping && code("T622") => {
            "ESI: T622, a mapping object's default differs from its PDO (AL 0x0024/0x0025)"
        }
        Stage::SafeOp if matches!(row.al_code, 0x001D | 0x001E) && disabled_pd => {
            "ESI: a process data SM not declared enabled carries a default PDO (AL 0x001D/0x001E)"
        }
        _ if timed_out(row) => "tester: a timeout of a loaded machine, twice",
        _ => "unclassified",
    }
}

/// The distinct codes of `odc check`'s warnings and errors for `device`.
fn check_codes(device: &Device) -> String {
    let diags = odc_pipeline::check(
        std::slice::from_ref(device),
        Vec::new(),
        &odc_pipeline::check_config(),
    );
    let mut codes: Vec<&str> = diags
        .iter()
        .filter(|d| matches!(d.severity, odc_model::Severity::Error | odc_model::Severity::Warning))
        .map(|d| d.code)
        .collect();
    codes.sort_unstable();
    codes.dedup();
    codes.join(",")
}

fn panic_text() -> String {
    last_panic().lock().unwrap_or_else(|e| e.into_inner()).clone().unwrap_or_else(|| "panic".into())
}

/// ethercrab's default bring-up, stage by stage (`into_op` is `into_safe_op` then OP, and
/// `into_safe_op` is `into_pre_op_pdi` then SAFE-OP: the same calls, separated to tell where
/// a device stops).
fn bring_up(maindevice: &MainDevice<'static>, row: &mut Row) {
    smol::block_on(async {
        row.stage = Stage::Init;
        let group = match maindevice.init_single_group::<2, MAX_PDI>(now).await {
            Ok(g) => g,
            Err(e) => return row.error = format!("{e:?}"),
        };
        if group.len() != 1 {
            return row.error = format!("{} SubDevices found", group.len());
        }
        row.stage = Stage::Pdi;
        let group = match group.into_pre_op_pdi(maindevice).await {
            Ok(g) => g,
            Err(e) => return row.error = format!("{e:?}"),
        };
        {
            let sd = group.subdevice(maindevice, 0).unwrap();
            row.out_bytes = sd.outputs_raw().len();
            row.in_bytes = sd.inputs_raw().len();
        }
        row.expected_wkc =
            if row.out_bytes > 0 { 2 } else { 0 } + if row.in_bytes > 0 { 1 } else { 0 };
        row.stage = Stage::SafeOp;
        let group = match group.into_safe_op(maindevice).await {
            Ok(g) => g,
            Err(e) => return row.error = format!("{e:?}"),
        };
        row.stage = Stage::Op;
        let group = match group.into_op(maindevice).await {
            Ok(g) => g,
            Err(e) => return row.error = format!("{e:?}"),
        };
        row.stage = Stage::Cycles;
        for cycle in 0..CYCLES {
            match group.tx_rx(maindevice).await {
                Ok(r) if r.working_counter == row.expected_wkc => row.cycles_ok += 1,
                Ok(r) => {
                    if row.error.is_empty() {
                        row.error = format!(
                            "cycle {cycle}: working counter {} (expected {})",
                            r.working_counter, row.expected_wkc
                        );
                    }
                }
                Err(e) => return row.error = format!("cycle {cycle}: {e:?}"),
            }
        }
        if row.cycles_ok == CYCLES {
            row.stage = Stage::Done;
        }
    });
}

/// `n` devices spread evenly over `all` (every one when `n` is at least their number).
pub fn spread<T>(all: Vec<T>, n: usize) -> Vec<T> {
    let len = all.len();
    if n >= len {
        return all;
    }
    all.into_iter()
        .enumerate()
        .filter(|(i, _)| i * n / len != (i + 1) * n / len)
        .map(|(_, x)| x)
        .collect()
}
