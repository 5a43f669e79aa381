//! SOEM (PyPI `pysoem`), the most used open EtherCAT master, against `odc simulate FILE.xml
//! --interface IFACE` over a veth pair whose master end is in a network namespace the test
//! makes (and removes): tests/interop/python/soem_master.py finds the devices, maps the
//! process data, reaches OP, reads, writes and aborts over CoE and exchanges process data;
//! this test decides on what it reports. Expected values are the ESI's and CiA 402's.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("ip (iproute2) runs");
    assert!(out.status.success(), "ip {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// A network namespace with one end of a veth pair in it (the master's), the other end
/// (the devices') in this namespace; both removed on drop.
struct Wire {
    netns: String,
    devices: String,
    master: String,
}

impl Wire {
    /// `tag` tells apart the wires of tests that run at once.
    fn new(tag: char) -> Wire {
        let id = std::process::id() % 100_000;
        let wire = Wire {
            netns: format!("odcsoem{tag}{id}"),
            devices: format!("odc{tag}{id}d"),
            master: format!("odc{tag}{id}m"),
        };
        ip(&["netns", "add", &wire.netns]);
        ip(&["link", "add", &wire.devices, "type", "veth", "peer", "name", &wire.master]);
        ip(&["link", "set", &wire.master, "netns", &wire.netns]);
        ip(&["link", "set", &wire.devices, "up"]);
        ip(&["netns", "exec", &wire.netns, "ip", "link", "set", &wire.master, "up"]);
        wire
    }
}

impl Drop for Wire {
    fn drop(&mut self) {
        let _ = Command::new("ip").args(["link", "del", &self.devices]).status();
        let _ = Command::new("ip").args(["netns", "del", &self.netns]).status();
    }
}

/// `program` under SCHED_FIFO where the machine allows it (`chrt`, root): SOEM gives a datagram
/// 2 ms to come back (EC_TIMEOUTRET), as a real device answers in microseconds; a simulated
/// device that a loaded machine does not schedule in time would make SOEM give up on it.
fn realtime(program: &str) -> Command {
    let allowed =
        Command::new("chrt").args(["-f", "10", "true"]).status().is_ok_and(|s| s.success());
    if allowed {
        let mut c = Command::new("chrt");
        c.args(["-f", "10", program]);
        c
    } else {
        Command::new(program)
    }
}

/// A PDO mapping value (ETG.1000.6: index << 16 | sub << 8 | bits), as SDO download data.
fn entry(index: u16, sub: u8, bits: u8) -> String {
    let v = u32::from(index) << 16 | u32::from(sub) << 8 | u32::from(bits);
    hex(&v.to_le_bytes())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The SDO writes of a configuration tool that maps `entries` into the PDO `pdo` and
/// assigns it alone to the sync manager's assignment object `assign` (ETG.1020 order:
/// clear, fill, count).
fn map(assign: u16, pdo: u16, entries: &[(u16, u8, u8)]) -> Vec<Value> {
    let mut w = vec![json!([assign, 0, "00"]), json!([pdo, 0, "00"])];
    for (k, &(index, sub, bits)) in entries.iter().enumerate() {
        w.push(json!([pdo, k + 1, entry(index, sub, bits)]));
    }
    w.push(json!([pdo, 0, hex(&[entries.len() as u8])]));
    w.push(json!([assign, 1, hex(&pdo.to_le_bytes())]));
    w.push(json!([assign, 0, "01"]));
    w
}

/// Runs `odc simulate SPECS... --interface` and soem_master.py with `devices` (the plan of
/// each device, in line order) on the other end; returns SOEM's report and what odc
/// simulate printed.
fn soem(tag: char, specs: &[String], devices: Value) -> (Value, String) {
    soem_script(tag, "soem_master.py", specs, json!({ "cycles": 1000, "devices": devices }))
}

/// [`soem`] with another script of tests/interop/python and its plan (`iface` added).
fn soem_script(tag: char, script: &str, specs: &[String], mut plan: Value) -> (Value, String) {
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    let wire = Wire::new(tag);
    let mut sim = realtime(env!("CARGO_BIN_EXE_odc"))
        .arg("simulate")
        .args(specs)
        .args(["--interface", &wire.devices, "--stop-on-eof"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    assert_eq!(first.trim(), format!("serving {} devices on {}", specs.len(), wire.devices));
    plan["iface"] = json!(wire.master);
    let mut master = Command::new("ip")
        .args(["netns", "exec", &wire.netns])
        .arg(&python)
        .arg(repo("tests/interop/python").join(script))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    master.stdin.take().unwrap().write_all(plan.to_string().as_bytes()).unwrap();
    // A watchdog: SOEM's own timeouts are seconds; two minutes is a hang.
    let deadline = Instant::now() + Duration::from_secs(120);
    while master.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = master.kill();
            let _ = sim.kill();
            panic!("{script} did not finish in 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = master.wait_with_output().unwrap();
    drop(sim.stdin.take());
    let sim_out = sim.wait_with_output().unwrap();
    let sim_err = String::from_utf8_lossy(&sim_out.stderr).into_owned();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: Value =
        stdout.lines().last().and_then(|l| serde_json::from_str(l).ok()).unwrap_or_else(|| {
            panic!("no report: {stdout}\n{}\n{sim_err}", String::from_utf8_lossy(&out.stderr))
        });
    println!("SOEM: {report}\nodc simulate: {sim_err}");
    assert_eq!(report["errors"], json!([]), "{report}");
    assert!(sim_err.contains("frames"), "{sim_err}");
    (report, sim_err)
}

/// The ServoOne's plan: it assigns no PDO (manual 8.3), so SOEM's configuration callback maps
/// cyclic synchronous position, controlword + target position out, statusword + position in;
/// then reads, writes read back, three accesses that must abort, and "shutdown" out.
fn servoone_plan() -> Value {
    let mut writes = map(0x1C12, 0x1600, &[(0x6040, 0, 16), (0x607A, 0, 32)]);
    writes.extend(map(0x1C13, 0x1A00, &[(0x6041, 0, 16), (0x6064, 0, 32)]));
    json!({
        "preop_writes": writes,
        "reads": [[0x1000, 0], [0x1018, 1], [0x6502, 0]],
        "writes": [[0x6060, 0, "08"], [0x607A, 0, hex(&1000i32.to_le_bytes())]],
        "aborts": [[0x1234, 0, null], [0x1000, 0, "00000000"], [0x1018, 9, null]],
        // Controlword 0x0006, shutdown; target position 1000.
        "outputs": hex(&[0x06, 0x00, 0xE8, 0x03, 0x00, 0x00]),
    })
}

/// What SOEM must have found of the ServoOne (`dev`, its part of the report).
fn check_servoone(dev: &Value) {
    // The ESI's identity (esi/servoone.xml: vendor, product and revision 0, as the manual
    // gives none) and name, read by SOEM from the SII.
    assert_eq!(
        (&dev["vendor"], &dev["product"], &dev["revision"]),
        (&json!(0), &json!(0), &json!(0))
    );
    assert_eq!(dev["name"], "ServoOne");
    // config_map: 6 bytes each way (INTEGER16/UNSIGNED16 + INTEGER32, CiA 402).
    assert_eq!((&dev["outputs_len"], &dev["inputs_len"]), (&json!(6), &json!(6)));
    // 0x1000 = 0x00000192 (the ESI's default), 0x1018:1 = 0, 0x6502 supported modes.
    let reads = &dev["reads"];
    assert_eq!(reads[0], json!([0x1000, 0, "92010000"]));
    assert_eq!(reads[1], json!([0x1018, 1, "00000000"]));
    assert_eq!(reads[2][2].as_str().unwrap().len(), 8, "0x6502 is UNSIGNED32");
    assert_eq!(dev["written"], json!([[0x6060, 0, "08"], [0x607A, 0, "e8030000"]]));
    // CiA 301 / ETG.1000.6 abort codes: no object, read-only, no sub-index.
    assert_eq!(
        dev["aborts"],
        json!([
            [0x1234, 0, 0x0602_0000u32],
            [0x1000, 0, 0x0601_0002u32],
            [0x1018, 9, 0x0609_0011u32]
        ])
    );
    // After "shutdown" the drive is "ready to switch on": statusword xxxx xxxx x01x 0001
    // (CiA 402 Table 30).
    let inputs = hex_bytes(dev["inputs"].as_str().unwrap());
    let statusword = u16::from_le_bytes([inputs[0], inputs[1]]);
    assert_eq!(statusword & 0x6F, 0x21, "statusword {statusword:#06x}");
}

/// 1,000 cycles whose frame came back, each with the working counter SOEM expects; frames
/// that did not come back within 20 ms (a loaded machine) are repeated and reported.
fn check_cycles(report: &Value, expected_wkc: u32) {
    assert_eq!((&report["safe_op"], &report["op"]), (&json!(true), &json!(true)));
    assert_eq!(report["expected_wkc"], expected_wkc);
    assert_eq!(report["cycles_with_expected_wkc"], 1000);
    assert_eq!(report["cycles_with_other_wkc"], json!([]));
    println!("frames lost: {}", report["frames_lost"]);
}

fn soem_finds_maps_and_runs_the_servoone() {
    let esi = repo("esi/servoone.xml").to_str().unwrap().to_owned();
    let (report, _) = soem('a', &[esi], json!([servoone_plan()]));
    assert_eq!(report["found"], 1);
    check_servoone(&report["devices"][0]);
    assert_eq!(report["io_map_size"], 12);
    // LRW: 3 for one device with outputs and inputs.
    check_cycles(&report, 3);
}

/// A device of the corpus and the process image odc computes for it from its ESI
/// (`odc_analysis::image`, the sizes of the generated `pdi` structs): (device, outputs, inputs).
fn corpus_device(file: &str, select: Option<&str>) -> (String, odc_model::Device, usize, usize) {
    use odc_analysis::image::{default_assignment, image};
    let path = odc_tests_support::corpus().join("esi").join(file);
    let mut options = odc_pipeline::Options::new();
    if let Some(s) = select {
        options = options.select(odc_pipeline::Select::Spec(s.into()));
    }
    let device = odc_pipeline::load(&path, &options).unwrap().device().unwrap().clone();
    let assignment = default_assignment(&device);
    let outputs = image(&device, &assignment, odc_model::Direction::Rx).unwrap().len();
    let inputs = image(&device, &assignment, odc_model::Direction::Tx).unwrap().len();
    let spec = match select {
        Some(s) => format!("{}@{s}", path.display()),
        None => path.display().to_string(),
    };
    (spec, device, outputs, inputs)
}

/// The ESI's identity as SOEM reports it.
fn identity(device: &odc_model::Device) -> Value {
    let ecat = device.ethercat.as_deref().unwrap();
    json!([ecat.vendor_id.unwrap_or(0), ecat.product_code.unwrap_or(0), ecat.revision.unwrap_or(0)])
}

fn soem_runs_a_line_of_three() {
    use odc_analysis::image::default_assignment;
    // The ServoOne; a Beckhoff EL2008 (8 digital outputs, fixed PDOs, no mailbox: SOEM maps
    // it from the SII's PDO categories); an Ingenia CiA 402 drive, whose ESI assigns PDOs but
    // whose dictionary starts with 0x1C12/0x1C13 empty, so SOEM's callback writes the ESI's
    // assignment as a configuration tool does.
    let (el2008, terminal, t_out, t_in) =
        corpus_device("beckhoff__Beckhoff_EL2xxx.xml", Some("EL2008"));
    let (ingenia, drive, d_out, d_in) = corpus_device("ingenia__ecat402-drive.xml", None);
    let mut assign = Vec::new();
    for (sm, pdos) in default_assignment(&drive) {
        let object = 0x1C10 + u16::from(sm);
        assign.push(json!([object, 0, "00"]));
        for (k, pdo) in pdos.iter().enumerate() {
            assign.push(json!([object, k + 1, hex(&pdo.to_le_bytes())]));
        }
        assign.push(json!([object, 0, hex(&[pdos.len() as u8])]));
    }
    let esi = repo("esi/servoone.xml").to_str().unwrap().to_owned();
    let plan = json!([
        servoone_plan(),
        { "outputs": "a5" },
        { "preop_writes": assign, "reads": [[0x1000, 0], [0x1C00, 0], [0x1C00, 3], [0x1C00, 4]] },
    ]);
    let (report, sim_err) = soem('b', &[esi, el2008, ingenia], plan);
    assert_eq!(report["found"], 3);
    let devs = &report["devices"];
    check_servoone(&devs[0]);
    for (dev, model, outputs, inputs) in
        [(&devs[1], &terminal, t_out, t_in), (&devs[2], &drive, d_out, d_in)]
    {
        let found = json!([dev["vendor"], dev["product"], dev["revision"]]);
        assert_eq!(found, identity(model), "{dev}");
        // config_map's sizes against odc's process image of the ESI.
        assert_eq!(
            (&dev["outputs_len"], &dev["inputs_len"]),
            (&json!(outputs), &json!(inputs)),
            "{dev}"
        );
    }
    // As ethercrab computes them (crates/odc-sim/tests/ethercat_ethercrab.rs): 1/0 and 11/11.
    assert_eq!((t_out, t_in, d_out, d_in), (1, 0, 11, 11));
    assert_eq!(report["io_map_size"], 12 + 1 + 22);
    // 0x1000 of the Ingenia reads as an UNSIGNED32 whose low word is the profile, 402.
    let device_type = hex_bytes(devs[2]["reads"][0][2].as_str().unwrap());
    assert_eq!(device_type[..2], [0x92, 0x01], "{}", devs[2]);
    // 0x1C00, which its ESI's dictionary leaves out and SOEM reads: 4 sync managers, SM2
    // outputs (3), SM3 inputs (4), from the ESI's `Sm` elements.
    let reads = &devs[2]["reads"];
    assert_eq!([&reads[1][2], &reads[2][2], &reads[3][2]], ["04", "03", "04"], "{}", devs[2]);
    // LRW: 2 for each of 3 devices with outputs, 1 for each of 2 with inputs.
    check_cycles(&report, 8);
    assert!(sim_err.contains("device 3:"), "{sim_err}");
}

/// SOEM reads the SII of devices whose content did not fit their `Eeprom/ByteSize`, as the
/// simulated EEPROM holds it: odc_sii leaves out optional parts (names; names, DC, FMMU and
/// PDOs; everything but the info area in a 128-byte EEPROM), or writes the ESI's own General
/// and SyncManager categories in place of its own (Elmo). SOEM's config_init must find each
/// device with the ESI's identity and take its name from string 1 where there are strings
/// (SOEM's fallback `? M:… I:…` where there are none), and the EEPROM read
/// over the ESC's interface must be odc's image byte for byte.
fn soem_reads_sii_images_fitted_to_byte_size() {
    let devices = [
        // Left out: the names of PDO entries.
        corpus_device("beckhoff__Beckhoff_EJ2xxx.xml", Some("EJ2521-0224")),
        // Left out: names, the DC, FMMU and PDO categories.
        corpus_device("beckhoff__etc-Beckhoff_EL1xxx.xml", Some("EL1258")),
        // ByteSize 128: the info area alone.
        corpus_device("beckhoff__Beckhoff_EL67xx.xml", Some("EL6720")),
        // The ESI's own General (names all index 0) and SyncManager categories.
        corpus_device("elmo__Elmo_ECAT_00010420_V11.rev_10420_only.xml", Some("0x00030924")),
    ];
    let mut plan = Vec::new();
    let mut images = Vec::new();
    for (_, device, _, _) in &devices {
        let (image, notes) = odc_sii::write_with_notes(device).unwrap();
        let left_out = notes.iter().any(|n| matches!(n, odc_sii::Note::LeftOut { .. }));
        let esi_own = notes.iter().any(|n| matches!(n, odc_sii::Note::EsiCategory { .. }));
        assert!(left_out || esi_own, "{}: {notes:?}", device.name());
        plan.push(json!({ "bytes": image.len() }));
        images.push(image);
    }
    let specs: Vec<String> = devices.iter().map(|(spec, ..)| spec.clone()).collect();
    let (report, _) = soem_script('c', "soem_sii.py", &specs, json!({ "devices": plan }));
    assert_eq!(report["found"], devices.len(), "{report}");
    for (k, ((_, device, _, _), image)) in devices.iter().zip(&images).enumerate() {
        let dev = &report["devices"][k];
        assert_eq!(dev["identity"], identity(device), "{dev}");
        assert_eq!(hex_bytes(dev["eeprom"].as_str().unwrap()), *image, "{}", device.name());
        let sii = odc_sii::read(image).unwrap();
        // SOEM's name: string 1 (SOEM keeps 40 bytes of it; odc puts the order code there),
        // or `? M:vendor I:product` without a strings category.
        let ecat = device.ethercat.as_deref().unwrap();
        let want = match sii.string(1) {
            Some(name) => name.chars().take(40).collect::<String>(),
            None => format!(
                "? M:{:08x} I:{:08x}",
                ecat.vendor_id.unwrap_or(0),
                ecat.product_code.unwrap_or(0)
            ),
        };
        assert_eq!(dev["name"], json!(want), "{dev}");
    }
}

/// A line of three devices with 4 output and 4 input bits each (tests/fixtures/nibble.xml:
/// BOOL entries 0x7000:01-04 on SM2, 0x6000:01-04 on SM3). SOEM's config_map packs them
/// bit by bit into shared bytes of its logical image (the FMMUs' logical start and stop bits,
/// ETG.1000.4): device 1 bits 0-3 and device 2 bits 4-7 of the first byte, device 3
/// bits 0-3 of the second. SOEM sends the nibbles 0x5, 0xA, 0xC and each device's firmware
/// stack takes from its SM2 buffer its own four bits into 0x7000; each device puts the nibble
/// SOEM wrote into its 0x6000 (0x9, 0x6, 0x3) into SM3, and the input image is their packing.
fn soem_packs_three_4_bit_devices() {
    let fixture = repo("crates/odc-cli/tests/fixtures/nibble.xml").to_str().unwrap().to_owned();
    let bits = |nibble: u8| -> Vec<Value> {
        (0..4u8).map(|k| json!([0x6000, k + 1, hex(&[nibble >> k & 1])])).collect()
    };
    let plan = json!({
        "inputs": [bits(0x9), bits(0x6), bits(0x3)],
        // Device 1's 0x5 in the low nibble and device 2's 0xA in the high nibble of byte 0,
        // device 3's 0xC in the low nibble of byte 1.
        "outputs": "a50c",
        "reads": [[0x7000, 1], [0x7000, 2], [0x7000, 3], [0x7000, 4]],
    });
    let specs = vec![fixture.clone(), fixture.clone(), fixture];
    let (report, _) = soem_script('d', "soem_nibbles.py", &specs, plan);
    assert_eq!(report["found"], 3, "{report}");
    assert_eq!((&report["safe_op"], &report["op"]), (&json!(true), &json!(true)), "{report}");
    // 12 bits out, 12 bits in: two bytes each way.
    assert_eq!(report["io_map_size"], 4, "{report}");
    let devs = &report["devices"];
    // FMMU 0 (outputs) and 1 (inputs): [logical start, length, start bit, stop bit].
    let fmmus: Vec<&Value> = (0..3).map(|k| &devs[k]["fmmu"]).collect();
    assert_eq!(
        fmmus,
        [
            &json!([[0, 1, 0, 3], [2, 1, 0, 3]]),
            &json!([[0, 1, 4, 7], [2, 1, 4, 7]]),
            &json!([[1, 1, 0, 3], [3, 1, 0, 3]]),
        ],
        "{report}"
    );
    // What each device took from its SM2 buffer: 0x5 = outputs 1 and 3, 0xA = 2 and 4,
    // 0xC = 3 and 4 (one BOOL byte per SDO upload).
    let read = |k: usize| -> Vec<&str> {
        devs[k]["reads"].as_array().unwrap().iter().map(|r| r[2].as_str().unwrap()).collect()
    };
    assert_eq!(read(0), ["01", "00", "01", "00"], "{report}");
    assert_eq!(read(1), ["00", "01", "00", "01"], "{report}");
    assert_eq!(read(2), ["00", "00", "01", "01"], "{report}");
    // The input image, as each device's pointer into it sees it: devices 1 and 2 share the
    // byte 0x69 (0x9 low, 0x6 high), device 3 has 0x03.
    let inputs: Vec<&Value> = (0..3).map(|k| &devs[k]["input"]).collect();
    assert_eq!(inputs, [&json!("69"), &json!("69"), &json!("03")], "{report}");
    // Each of the three devices read and wrote in the LRW: 3 each (ETG.1000.4's working
    // counter: 1 for a read, 2 for a write). SOEM (pysoem 1.1.13) expects 3 of the whole line, counting
    // the packed devices once: not odc's to follow.
    assert_eq!(report["last_wkc"], 9, "{report}");
}

/// SOEM reads the ServoOne's dictionary by SDO Information (pysoem's `od`: the object list,
/// then each object's and entry's description, in fragments where a reply is longer than the
/// 128-byte mailbox): every object of the ESI, with the ESI's names, object codes (ETG.1000.6
/// Table 44: 7 VAR, 8 ARRAY, 9 RECORD), data types (CiA 301 codes) and bit lengths.
fn soem_reads_the_dictionary_by_sdo_information() {
    let path = repo("esi/servoone.xml");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let device = loaded.device().unwrap();
    let esi = path.to_str().unwrap().to_owned();
    let (report, _) = soem_script('i', "soem_sdo_info.py", &[esi], json!({}));
    assert_eq!(report["found"], 1);
    let objects = report["objects"].as_array().unwrap();
    let indexes: Vec<u64> = objects.iter().map(|o| o["index"].as_u64().unwrap()).collect();
    let expected: Vec<u64> = device.objects.keys().map(|&i| u64::from(i)).collect();
    assert_eq!(indexes, expected);
    // SOEM keeps 40 bytes of a name (EC_MAXNAME); the device sends it whole.
    let soem_name = |name: &str| json!(name.get(..40).unwrap_or(name));
    for (o, object) in objects.iter().zip(device.objects.values()) {
        let at = format!("{:04X}", object.index);
        assert_eq!(o["name"], soem_name(&object.name), "{at}");
        let code = match object.kind {
            odc_model::ObjectKind::Var => 7,
            odc_model::ObjectKind::Array => 8,
            _ => 9,
        };
        assert_eq!(o["code"], code, "{at}");
        let entries = o["entries"].as_array().unwrap();
        for sub in object.subs.values() {
            let bits = sub.bit_size.or(sub.data_type.bit_size()).unwrap();
            let (name, data_type, bit_length) = if code == 7 {
                // SOEM keeps a VAR's one entry in the object (its name is the object's).
                (&o["name"], &o["data_type"], &o["bits"])
            } else {
                let e = &entries[usize::from(sub.sub_index)];
                assert_eq!(e[0], soem_name(&sub.name), "{at}:{}", sub.sub_index);
                (&e[0], &e[1], &e[2])
            };
            assert!(name.is_string(), "{at}:{}", sub.sub_index);
            assert_eq!(data_type, &json!(sub.data_type.code()), "{at}:{}", sub.sub_index);
            assert_eq!(bit_length, &json!(bits), "{at}:{}", sub.sub_index);
        }
    }
}

fn hex_bytes(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap()).collect()
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "soem_finds_maps_and_runs_the_servoone",
            run: soem_finds_maps_and_runs_the_servoone,
            needs: &[Need::Python(&["pysoem"]), Need::Netdevs],
        },
        Test {
            name: "soem_runs_a_line_of_three",
            run: soem_runs_a_line_of_three,
            needs: &[Need::Python(&["pysoem"]), Need::Netdevs, Need::Corpus],
        },
        Test {
            name: "soem_packs_three_4_bit_devices",
            run: soem_packs_three_4_bit_devices,
            needs: &[Need::Python(&["pysoem"]), Need::Netdevs],
        },
        Test {
            name: "soem_reads_the_dictionary_by_sdo_information",
            run: soem_reads_the_dictionary_by_sdo_information,
            needs: &[Need::Python(&["pysoem"]), Need::Netdevs],
        },
        Test {
            name: "soem_reads_sii_images_fitted_to_byte_size",
            run: soem_reads_sii_images_fitted_to_byte_size,
            needs: &[Need::Python(&["pysoem"]), Need::Netdevs, Need::Corpus],
        },
    ])
}
