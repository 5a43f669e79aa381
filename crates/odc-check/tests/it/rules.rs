//! One failing and one passing device per rule, with snapshots of the short rendering.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use crate::common;

use common::*;
use odc_model::ethercat::SmUsage;
use odc_model::{Direction, PdoMapping, Spanned, Value};

/// Asserts that `dev` trips `code` and snapshots the whole output.
macro_rules! trips {
    ($name:ident, $code:literal, $dev:expr) => {
        #[test]
        fn $name() {
            let out = run($dev);
            assert!(out.contains(concat!("[", $code, "]")), "{} not tripped:\n{out}", $code);
            insta::assert_snapshot!(stringify!($name), out);
        }
    };
}

/// Every rule has a device above or below that trips it (an `it__rules__<code>_*` snapshot
/// holding its code); the devices `base`, `io`, `drive`, `dcf` and `esi_io` pass every rule.
#[test]
fn every_rule_has_a_tripping_fixture() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/it/snapshots");
    let snaps: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    let mut missing = Vec::new();
    for r in odc_check::RULES {
        let prefix = format!("it__rules__{}_", r.info.code.to_lowercase());
        let tag = format!("[{}]", r.info.code);
        if !snaps.iter().any(|(n, text)| n.starts_with(&prefix) && text.contains(&tag)) {
            missing.push(r.info.code);
        }
    }
    assert!(missing.is_empty(), "rules without a tripping fixture: {missing:?}");
}

#[test]
fn base_device_passes_every_rule() {
    assert_eq!(run_with(base(), &all_rules_on()), "");
    assert_eq!(run_with(base().lists(), &all_rules_on()), "");
}

// C101–C105: object lists.

trips!(c101_listed_object_missing, "C101", base().lists().remove(0x1017));
trips!(c102_object_not_listed, "C102", base().lists().var(0x2000, "Unlisted", Unsigned8, Rw));
trips!(
    c103_supported_objects_count,
    "C103",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.supported_objects = Some(Spanned::synthetic(5));
        }
    })
);
trips!(
    c104_object_in_wrong_list,
    "C104",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.entries.push(Spanned::synthetic(0x1018));
            l.entries.push(Spanned::synthetic(0x0007));
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
        if let Some(l) = d.object_lists.mandatory.as_mut() {
            l.entries.retain(|e| e.value != 0x1018);
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
    })
);
trips!(
    c105_object_listed_twice,
    "C105",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.entries.push(Spanned::synthetic(0x1000));
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
    })
);

// C110–C117: structure.

fn record_2000() -> Dev {
    base().record(
        0x2000,
        "Settings",
        &[(1, "A", Unsigned16, Rw, None), (3, "C", Unsigned16, Rw, None)],
    )
}

#[test]
fn structured_objects_with_gaps_pass() {
    assert_eq!(run(record_2000()), "");
    let arr = base().array(
        0x2001,
        "Table",
        &[(1, "a", Integer16, Rw, None), (2, "b", Integer16, Rw, None)],
    );
    assert_eq!(run(arr), "");
    // 0x1003 sub 0 counts errors: 0 with subs 1..2 is fine.
    let errs = io()
        .array(0x1003, "Pre-defined error field", &[(1, "e1", Unsigned32, Ro, None)])
        .at(0x1003, 0)
        .default(u(0));
    assert_eq!(run(errs), "");
}

trips!(c110_sub_number_mismatch, "C110", record_2000().sub_number(4));
trips!(c111_sub0_type, "C111", record_2000().at(0x2000, 0).data_type(Unsigned16));
trips!(c112_sub0_value, "C112", record_2000().at(0x2000, 0).default(u(2)));
trips!(
    c113_sub_index_ff,
    "C113",
    record_2000()
        .sub(0xFF, "Structure", Unsigned32, Ro)
        .sub_number(4)
        .at(0x2000, 0)
        .default(u(0xFF))
);
trips!(
    c114_array_not_uniform,
    "C114",
    base().array(0x2001, "Table", &[(1, "a", Integer16, Rw, None), (2, "b", Integer32, Rw, None)],)
);
trips!(c115_sub_number_or_compact, "C115", record_2000().no_sub_number());
trips!(
    c116_var_with_subs,
    "C116",
    base().var(0x2002, "Var", Unsigned8, Rw).sub(1, "stray", Unsigned8, Rw)
);
trips!(c117_missing_sub0, "C117", record_2000().remove_sub(0x2000, 0).sub_number(2));
trips!(
    c118_obj_flags_reserved,
    "C118",
    base().var(0x2000, "Flags", Unsigned8, Rw).with(|d| {
        if let Some(o) = d.objects.get_mut(&0x2000) {
            o.obj_flags = Some(Spanned::synthetic(0x4));
        }
        if let Some(s) = d.objects.get_mut(&0x1018).and_then(|o| o.subs.get_mut(&1)) {
            s.rare_mut().obj_flags = Some(Spanned::synthetic(0x11));
        }
    })
);

#[test]
fn c118_defined_obj_flags_pass() {
    let d = base().var(0x2000, "Flags", Unsigned8, Rw).with(|d| {
        if let Some(o) = d.objects.get_mut(&0x2000) {
            o.obj_flags = Some(Spanned::synthetic(0x3));
        }
    });
    assert_eq!(run_with(d, &all_rules_on()), "");
}

trips!(
    c119_pdo_comm_record,
    "C119",
    io().sub_of(0x1400, 6, "SYNC start value", Unsigned8, Rw)
        .at(0x1400, 2)
        .data_type(Unsigned16)
        .at(0x1400, 0)
        .default(u(6))
        .sub_number(4)
        .remove_sub(0x1800, 1)
        .at(0x1800, 0)
        .sub_number(2)
);

#[test]
fn c119_full_pdo_comm_records_pass() {
    let d = io()
        .sub_of(0x1800, 3, "Inhibit time", Unsigned16, Rw)
        .sub(4, "Reserved", Unsigned8, Rw)
        .sub(5, "Event timer", Unsigned16, Rw)
        .sub(6, "SYNC start value", Unsigned8, Rw)
        .at(0x1800, 0)
        .default(u(6))
        .sub_number(7)
        .sub_of(0x1400, 5, "Event timer", Unsigned16, Rw)
        .at(0x1400, 0)
        .default(u(5))
        .sub_number(4);
    assert_eq!(run_with(d, &all_rules_on()), "");
}

// C201–C208: values.

#[test]
fn values_within_limits_pass() {
    let d = base()
        .var(0x2000, "Speed", Integer16, Rw)
        .low(i(-100))
        .high(i(100))
        .default(i(-5))
        .var(0x2001, "Node-relative", Unsigned16, Rw)
        .default(node(0x100))
        .low(node(0x80))
        .high(node(0x200))
        .var(0x2002, "Flag", Boolean, Rw)
        .default(u(1));
    assert_eq!(run(d), "");
}

trips!(
    c201_value_out_of_type_range,
    "C201",
    base()
        .var(0x2000, "Small", Unsigned8, Rw)
        .default(u(300))
        .var(0x2001, "Neg", Unsigned16, Rw)
        .default(i(-1))
);
trips!(
    c202_limits_inverted,
    "C202",
    base().var(0x2000, "x", Integer16, Rw).low(i(10)).high(i(-10))
);
trips!(
    c203_value_outside_limits,
    "C203",
    base()
        .var(0x2000, "x", Integer16, Rw)
        .low(i(0))
        .high(i(10))
        .default(i(11))
        .param(i(-1))
        .with(|d| d.format = Some(odc_model::Format::Dcf))
);
trips!(
    c204_nodeid_value_out_of_range,
    "C204",
    base().var(0x2000, "x", Unsigned8, Rw).default(node(0xF0))
);
trips!(c205_missing_mandatory_object, "C205", base().remove(0x1001));
trips!(
    c206_wrong_object_type,
    "C206",
    base().remove(0x1017).var(0x1017, "Producer heartbeat time", Unsigned32, Rw)
);
trips!(
    c207_identity_mismatch,
    "C207",
    base().with(|d| {
        d.device_info.vendor_number = Some(Spanned::synthetic(0x1234));
        d.device_info.product_number = Some(Spanned::synthetic(0x43));
    })
);
trips!(c208_limits_on_non_numeric, "C208", base().var(0x2000, "Name", VisibleString, Ro).low(u(0)));

fn with_files(d: Dev, index: u16, upload: Option<&str>, download: Option<&str>) -> Dev {
    d.with(|d| {
        if let Some(s) = d.objects.get_mut(&index).and_then(|o| o.subs.get_mut(&0)) {
            s.rare_mut().upload_file = upload.map(|f| Spanned::synthetic(f.into()));
            s.rare_mut().download_file = download.map(|f| Spanned::synthetic(f.into()));
        }
    })
}

trips!(
    c209_upload_download_file,
    "C209",
    with_files(
        with_files(base().var(0x2000, "Program", Domain, Rw), 0x2000, Some("prog.bin"), None)
            .var(0x2001, "Setting", Unsigned32, Wo),
        0x2001,
        None,
        Some("setting.bin")
    )
);

#[test]
fn c209_domain_files_with_matching_access_pass() {
    let d = with_files(base().var(0x2000, "Image", Domain, Const), 0x2000, Some("a.bin"), None);
    let d = with_files(d.var(0x2001, "Log", Domain, Wo), 0x2001, None, Some("b.bin"));
    assert_eq!(run_with(d, &all_rules_on()), "");
}

trips!(
    c210_visible_string_not_visible,
    "C210",
    base()
        .var(0x2000, "Unit", VisibleString, Ro)
        .default(Value::Text("\u{b5}m".into()))
        .var(0x2001, "Label", VisibleString, Rw)
        .default(Value::Text("a\tb".into()))
);

#[test]
fn c210_visible_ascii_passes() {
    let d = base().var(0x2000, "Unit", VisibleString, Ro).default(Value::Text(" um ~".into()));
    assert_eq!(run_with(d, &all_rules_on()), "");
}

// C301–C309: PDO mapping.

fn io() -> Dev {
    base()
        .var(0x6000, "Inputs", Unsigned8, Ro)
        .mappable()
        .var(0x6200, "Outputs", Unsigned16, Rww)
        .mappable()
        .var(0x2100, "Name", VisibleString, Rw)
        .mappable()
        .var(0x2101, "Config", Unsigned32, Rw)
        .var(0x1014, "COB-ID EMCY", Unsigned32, Ro)
        .default(node(0x80))
        .record(
            0x1200,
            "SDO server",
            &[
                (1, "COB-ID client->server", Unsigned32, Ro, Some(node(0x600))),
                (2, "COB-ID server->client", Unsigned32, Ro, Some(node(0x580))),
            ],
        )
        .with(|d| {
            d.dummy_usage.insert(0x0005, Spanned::synthetic(true));
            d.device_info.nr_of_rx_pdo = Some(Spanned::synthetic(1));
            d.device_info.nr_of_tx_pdo = Some(Spanned::synthetic(1));
        })
        .pdo(true, 1, node(0x180), &[0x6000_0008, 0x0005_0008, 0x1001_0008])
        .pdo(false, 1, node(0x200), &[0x6200_0010])
}

#[test]
fn io_device_passes_every_rule() {
    assert_eq!(run_with(io(), &all_rules_on()), "");
}

trips!(c301_pdo_mapped_object_missing, "C301", io().pdo(true, 1, node(0x180), &[0x6001_0008]));
trips!(
    c302_pdo_mapping_direction,
    "C302",
    io().pdo(true, 1, node(0x180), &[0x6200_0010, 0x2101_0020])
);
trips!(c303_pdo_entry_length, "C303", io().pdo(false, 1, node(0x200), &[0x6200_0008, 0x0005_0010]));
trips!(
    c304_pdo_too_long,
    "C304",
    io().var(0x6400, "Big", Unsigned64, Ro).mappable().pdo(
        true,
        1,
        node(0x180),
        &[0x6400_0040, 0x6000_0008]
    )
);
trips!(c305_pdo_too_many_entries, "C305", io().at(0x1A00, 0).default(u(65)));
trips!(
    c306_pdo_dummy_not_enabled,
    "C306",
    io().pdo(false, 1, node(0x200), &[0x6200_0010, 0x0006_0010])
);
trips!(c307_pdo_variable_length, "C307", io().pdo(true, 1, node(0x180), &[0x2100_0008]));
trips!(
    c308_pdo_count_mismatch,
    "C308",
    io().with(|d| d.device_info.nr_of_tx_pdo = Some(Spanned::synthetic(4)))
);
trips!(c309_pdo_mapping_entry_missing, "C309", io().remove_sub(0x1A00, 2));

fn granularity(d: Dev, g: u8) -> Dev {
    d.with(|d| d.device_info.granularity = Some(Spanned::synthetic(g)))
}

trips!(
    c310_pdo_granularity,
    "C310",
    granularity(io().var(0x6001, "Switch", Boolean, Ro).mappable(), 8).pdo(
        true,
        1,
        node(0x180),
        &[0x6000_0008, 0x6001_0001]
    )
);

#[test]
fn c310_granularity_zero_and_out_of_range() {
    assert_eq!(
        run(granularity(io(), 0)),
        "warning[C310]: Granularity=0 says the PDO mapping is not modifiable, but 0x1600:01 is \
         writable (rw)\n"
    );
    assert_eq!(run(granularity(io(), 65)), "warning[C310]: Granularity=65 is above 64 bits\n");
}

#[test]
fn c310_fitting_granularity_passes() {
    assert_eq!(run_with(granularity(io(), 8), &all_rules_on()), "");
    assert_eq!(run_with(granularity(io(), 1), &all_rules_on()), "");
    // A fixed mapping (read-only mapping objects) on a device whose mapping is not modifiable.
    let fixed = granularity(io(), 0).with(|d| {
        for o in d.objects.range_mut(0x1600..=0x1BFF).map(|(_, o)| o) {
            for s in o.subs.values_mut() {
                s.access = Ro;
            }
        }
    });
    assert_eq!(run_with(fixed, &all_rules_on()), "");
}

// C401–C408: COB-IDs and communication objects.

trips!(
    c401_restricted_cob_id,
    "C401",
    io().at(0x1800, 1).default(node(0x700)).at(0x1400, 1).default(u(0x7E5))
);
trips!(
    c402_cob_id_reserved_bits,
    "C402",
    io().at(0x1800, 1).default(u(0x40181)).at(0x1014, 0).default(node(0x4000_0080))
);
trips!(
    c403_cob_id_not_predefined,
    "C403",
    io().at(0x1800, 1).default(u(0x1A1)).pdo(true, 5, node(0x190), &[0x6000_0008]).with(|d| {
        d.device_info.nr_of_tx_pdo = Some(Spanned::synthetic(2));
    })
);
trips!(c404_duplicate_cob_id, "C404", io().at(0x1400, 1).default(node(0x180)));
trips!(
    c405_sync_objects,
    "C405",
    io().at(0x1800, 2).default(u(1)).var(0x1006, "Cycle period", Unsigned32, Rw)
);
trips!(
    c406_emcy_object,
    "C406",
    io().remove(0x1014).var(0x1015, "Inhibit time EMCY", Unsigned16, Rw)
);
trips!(
    c407_no_error_control,
    "C407",
    io().remove(0x1017).var(0x100C, "Guard time", Unsigned16, Rw)
);
trips!(
    c408_sdo_server_cob_id,
    "C408",
    io().at(0x1200, 1).default(node(0x601)).at(0x1200, 2).default(u(0x581))
);

fn guarding(d: Dev, guard: u64, life: u64) -> Dev {
    d.var(0x100C, "Guard time", Unsigned16, Rw)
        .default(u(guard))
        .var(0x100D, "Life time factor", Unsigned8, Rw)
        .default(u(life))
}

trips!(c409_heartbeat_and_guarding, "C409", guarding(base().at(0x1017, 0).default(u(100)), 100, 3));

#[test]
fn c409_one_error_control_configured_passes() {
    // Both supported, one configured.
    assert_eq!(run_with(guarding(base().at(0x1017, 0).default(u(100)), 0, 3), &all_rules_on()), "");
    assert_eq!(run_with(guarding(base(), 100, 3), &all_rules_on()), "");
}

fn consumers(entries: &[u64]) -> Dev {
    let subs: Vec<_> = entries
        .iter()
        .enumerate()
        .map(|(k, &v)| (k as u8 + 1, "Consumer heartbeat time", Unsigned32, Rw, Some(u(v))))
        .collect();
    base().array(0x1016, "Consumer heartbeat time", &subs)
}

trips!(
    c410_heartbeat_consumer_entry,
    "C410",
    consumers(&[0x0005_0064, 0x0005_00C8, 0x0080_0064, 0x0000_0064, 0x0105_0000])
);

#[test]
fn c410_well_formed_consumers_pass() {
    // Unused entries (time 0) may repeat a node-ID or name none.
    let d = consumers(&[0x0005_0064, 0x0006_00C8, 0x0005_0000, 0x0000_0000, 0x007F_0001]);
    assert_eq!(run_with(d, &all_rules_on()), "");
}

#[test]
fn sync_producer_with_period_passes() {
    let d = io()
        .at(0x1800, 2)
        .default(u(1))
        .var(0x1005, "COB-ID SYNC", Unsigned32, Rw)
        .default(u(0x4000_0080))
        .var(0x1006, "Cycle period", Unsigned32, Rw)
        .default(u(1000));
    assert_eq!(run(d), "");
    // Node guarding with both objects is error control too.
    let d = io().remove(0x1017).var(0x100C, "Guard time", Unsigned16, Rw).var(
        0x100D,
        "Life time factor",
        Unsigned8,
        Rw,
    );
    assert_eq!(run(d), "");
}

// C501–C508: DCF, modules, object links.

/// A DCF of a modular device: commissioning, LastEDS, a configured value, one module that
/// extends 0x6000 and adds 0x6100, plugged into slot 1, and a link 0x1018 -> 0x1000.
fn dcf() -> Dev {
    base().var(0x6000, "Inputs", Unsigned8, Ro).at(0x1017, 0).param(u(100)).with(|d| {
        d.format = Some(odc_model::Format::Dcf);
        d.file_info.file_name = Some(Spanned::synthetic("node5.dcf".into()));
        d.file_info.extra.push(odc_model::RawEntry {
            key: "LastEDS".into(),
            value: "device.eds".into(),
            span: odc_model::Span::DUMMY,
        });
        d.device_info.baud_rates = vec![250, 500];
        d.commissioning = Some(odc_model::Commissioning {
            node_id: Some(Spanned::synthetic(5)),
            baudrate: Some(Spanned::synthetic(500)),
            ..Default::default()
        });
        let template = odc_model::SubObject::new(1, "Channel", Unsigned8, Ro);
        let mut m = odc_model::Module { number: 1, has_info: true, ..Default::default() };
        m.sub_extends.insert(
            0x6000,
            odc_model::SubExtend {
                template,
                count: Some(Spanned::synthetic("2".into())),
                obj_extend: None,
            },
        );
        std::sync::Arc::make_mut(&mut m.fixed_objects).insert(
            0x6100,
            odc_model::Object::new(
                0x6100,
                "Module object",
                odc_model::ObjectKind::Record,
                odc_model::Span::DUMMY,
            ),
        );
        m.sub_extends.insert(
            0x6101,
            odc_model::SubExtend {
                template: odc_model::SubObject::new(1, "x", Unsigned8, Ro),
                count: Some(Spanned::synthetic("1;4".into())),
                obj_extend: Some(Spanned::synthetic(0x6100)),
            },
        );
        d.modules.supported.push(m);
        d.modules.nr_of_entries = Some(Spanned::synthetic(1));
        d.modules.connected.push(Spanned::synthetic(1));
        if let Some(o) = d.objects.get_mut(&0x1018) {
            o.links.push(Spanned::synthetic(0x1000));
        }
    })
}

#[test]
fn dcf_passes_every_rule() {
    assert_eq!(run_with(dcf(), &all_rules_on()), "");
    // LSS "not configured" is a node-ID a DCF may hold.
    let lss = dcf().with(|d| {
        if let Some(c) = d.commissioning.as_mut() {
            c.node_id = Some(Spanned::synthetic(255));
        }
    });
    assert_eq!(run(lss), "");
}

trips!(
    c509_supported_modules,
    "C509",
    dcf().with(|d| {
        // NrOfEntries=3: module 2 has no sections at all, module 3 only [M3FixedObjects];
        // module 4 lies beyond the count.
        d.modules.nr_of_entries = Some(Spanned::synthetic(3));
        d.modules.supported.push(odc_model::Module { number: 3, ..Default::default() });
        d.modules.supported.push(odc_model::Module {
            number: 4,
            has_info: true,
            ..Default::default()
        });
    })
);

#[test]
fn c509_modules_without_supported_modules() {
    let d = dcf().with(|d| d.modules.nr_of_entries = None);
    assert_eq!(
        run(d),
        "error[C509]: the file describes 1 module(s) but has no [SupportedModules] NrOfEntries\n"
    );
}

trips!(
    c501_dcf_only_keys,
    "C501",
    dcf().with(|d| d.file_info.file_name = Some(Spanned::synthetic("device.eds".into())))
);

#[test]
fn c501_denotation_in_an_eds() {
    let d = base().with(|d| {
        if let Some(o) = d.objects.get_mut(&0x1018) {
            o.denotation = Some(Spanned::synthetic("Identity of axis 1".into()));
        }
    });
    assert_eq!(run(d), "note[C501]: the EDS has a Denotation in 0x1018\n");
}

#[test]
fn c502_dcf_last_eds() {
    let d = || dcf().with(|d| d.file_info.extra.clear());
    // Off by default.
    assert_eq!(run(d()), "");
    let out = run_with(d(), &all_rules_on());
    assert!(out.contains("[C502]"), "{out}");
    insta::assert_snapshot!("c502_dcf_last_eds", out);
}

trips!(
    c503_dcf_node_id,
    "C503",
    dcf().with(|d| {
        if let Some(c) = d.commissioning.as_mut() {
            c.node_id = Some(Spanned::synthetic(0));
        }
    })
);
trips!(
    c504_dcf_baudrate,
    "C504",
    dcf().with(|d| {
        if let Some(c) = d.commissioning.as_mut() {
            c.baudrate = Some(Spanned::synthetic(1000));
        }
    })
);

#[test]
fn c504_bit_rate_that_is_none() {
    let d = dcf().with(|d| {
        if let Some(c) = d.commissioning.as_mut() {
            c.baudrate = Some(Spanned::synthetic(0));
        }
    });
    assert_eq!(run(d), "warning[C504]: Baudrate=0 is not a CiA 301 bit rate (kbit/s)\n");
}

trips!(
    c505_module_sub_extend_parent,
    "C505",
    dcf().with(|d| {
        if let Some(ext) = d.modules.supported[0].sub_extends.get_mut(&0x6101) {
            ext.obj_extend = Some(Spanned::synthetic(0x6200));
        }
    })
);
trips!(
    c506_module_count,
    "C506",
    dcf().with(|d| {
        let m = &mut d.modules.supported[0];
        if let Some(ext) = m.sub_extends.get_mut(&0x6000) {
            ext.count = Some(Spanned::synthetic("2;3;4".into()));
        }
        if let Some(ext) = m.sub_extends.get_mut(&0x6101) {
            ext.count = None;
        }
    })
);
trips!(
    c507_connected_module_unknown,
    "C507",
    dcf().with(|d| d.modules.connected.push(Spanned::synthetic(3)))
);
trips!(
    c508_object_link_missing,
    "C508",
    dcf().with(|d| {
        if let Some(o) = d.objects.get_mut(&0x1018) {
            o.links.push(Spanned::synthetic(0x2000));
        }
    })
);

// D501–D507: CiA 402.

/// A two-axis csp/pp drive that passes every rule.
fn drive() -> Dev {
    let mut d = base().at(0x1000, 0).default(u(0x0002_0192));
    for base in [0u16, 0x800] {
        d = d
            .var(0x6040 + base, "Controlword", Unsigned16, Rww)
            .mappable()
            .var(0x6041 + base, "Statusword", Unsigned16, Ro)
            .mappable()
            .var(0x6060 + base, "Modes of operation", Integer8, Rww)
            .mappable()
            .var(0x6061 + base, "Modes of operation display", Integer8, Ro)
            .mappable()
            .var(0x6064 + base, "Position actual value", Integer32, Ro)
            .mappable()
            .var(0x607A + base, "Target position", Integer32, Rww)
            .mappable()
            .var(0x6081 + base, "Profile velocity", Unsigned32, Rw)
            .var(0x6083 + base, "Profile acceleration", Unsigned32, Rw)
            .var(0x6502 + base, "Supported drive modes", Unsigned32, Ro)
            .default(u(0x81));
    }
    d
}

#[test]
fn drive_passes_every_rule() {
    assert_eq!(run_with(drive(), &all_rules_on()), "");
    // Without profile 402 in 0x1000 none of the D rules apply.
    assert_eq!(run(drive().at(0x1000, 0).default(u(0x191)).remove(0x6040)), "");
}

trips!(d501_cia402_controlword_statusword, "D501", drive().remove(0x6041).remove(0x6840));
trips!(d502_cia402_object_type, "D502", drive().at(0x6060, 0).data_type(Unsigned8));
trips!(
    d503_cia402_pdo_mappable,
    "D503",
    drive().remove(0x6040).var(0x6040, "Controlword", Unsigned16, Ro).mappable()
);
trips!(d504_cia402_mode_objects, "D504", drive().at(0x6502, 0).default(u(0x3A5)));
trips!(
    d505_cia402_cyclic_mappable,
    "D505",
    drive().remove(0x6064).var(0x6064, "Position actual value", Integer32, Ro)
);
trips!(d506_cia402_modes_of_operation, "D506", drive().remove(0x6060).remove(0x6861));
trips!(d507_cia402_axis_offset, "D507", drive().at(0x6881, 0).data_type(Integer32));

/// The drive as an ESI whose profile, not 0x1000, says 402.
fn esi_drive(profile: odc_model::ethercat::Profile) -> Dev {
    drive().remove(0x1000).esi().ethercat(|e| e.profiles.push(profile))
}

fn profile_402() -> odc_model::ethercat::Profile {
    odc_model::ethercat::Profile { profile_no: Some(402), ..Default::default() }
}

#[test]
fn esi_profile_402_makes_a_drive() {
    assert_eq!(run(esi_drive(profile_402())), "");
    let out = run(esi_drive(profile_402()).remove(0x6041));
    assert!(out.contains("error[D501]: CiA 402 drive has no statusword 0x6041"), "{out}");
    // 0x1000 decides when it has a value: 5001 (modular device) is not a drive.
    let mdp = esi_drive(profile_402()).var(0x1000, "Device type", Unsigned32, Ro).default(u(5001));
    assert_eq!(run(mdp.remove(0x6041)), "");
    // Without 0x1000 and without profile 402, the D rules do not run.
    let other = odc_model::ethercat::Profile { profile_no: Some(5001), ..Default::default() };
    assert_eq!(run(esi_drive(other).remove(0x6041)), "");
}

#[test]
fn esi_channels_give_the_axes() {
    // Channel 0 is MDP, channel 1 a 402 axis: only axis 2 (0x6800..) is checked.
    let channels = odc_model::ethercat::Profile {
        channel_profiles: vec![Some(5001), Some(402)],
        ..Default::default()
    };
    let out = run(esi_drive(channels.clone()).remove(0x6840).remove(0x6040));
    assert_eq!(out, "error[D501]: CiA 402 drive (axis 2) has no controlword 0x6840\n");
    // ChannelCount 3 of profile 402: axis 3 (0x7000..) must exist too.
    let three = odc_model::ethercat::Profile { channel_count: Some(3), ..profile_402() };
    let out = run(esi_drive(three));
    assert!(out.contains("(axis 3) has no controlword 0x7040"), "{out}");
}

#[test]
fn esi_without_dictionary_is_not_checked_as_a_drive() {
    let d = esi_drive(profile_402()).remove(0x6041).ethercat(|e| e.dictionary_synthesised = true);
    assert_eq!(run(d), "");
}

// T601–T628: EtherCAT.

#[test]
fn esi_device_passes_every_rule() {
    assert_eq!(run_with(esi_io(), &all_rules_on()), "");
}

trips!(
    t601_esi_pdo_entry_not_in_dictionary,
    "T601",
    esi_io().remove(0x6000).var(0x6001, "Other", Unsigned16, Ro)
);
trips!(t602_esi_pdo_entry_bit_length, "T602", esi_io().at(0x6000, 0).data_type(Unsigned32));
trips!(
    t603_esi_pdo_entry_direction,
    "T603",
    esi_io().at(0x7000, 0).mapping(PdoMapping::Tx).at(0x7001, 0).mapping(PdoMapping::No)
);

#[test]
fn fixed_pdos_are_not_checked_for_direction() {
    let d = esi_io().at(0x7000, 0).mapping(PdoMapping::No).edit_pdo(0x1600, |p| p.fixed = true);
    assert_eq!(run(d.edit_pdo(0x1602, |p| p.fixed = true)), "");
}

trips!(
    t604_esi_pdo_sync_manager,
    "T604",
    esi_io().edit_pdo(0x1600, |p| p.sync_manager = Some(3)).edit_pdo(0x1A00, |p| {
        p.sync_manager = Some(7);
    })
);

#[test]
fn sync_managers_without_a_type_are_judged_by_their_control_byte() {
    // IgH's `ethercat xml` writes <Sm> elements without text.
    let untyped = |d: Dev| {
        d.edit_sm(2, |s| s.usage = SmUsage::Other(String::new()))
            .edit_sm(3, |s| s.usage = SmUsage::Other(String::new()))
    };
    assert_eq!(run(untyped(esi_io())), "");
    let out =
        run(untyped(esi_io()).edit_sm(2, |s| s.control_byte = Some(Spanned::synthetic(0x20))));
    assert!(out.contains("[T604]"), "{out}");
}

trips!(
    t605_esi_sm_pdo_size,
    "T605",
    esi_io().edit_sm(2, |s| s.max_size = Some(1)).edit_sm(3, |s| s.min_size = Some(4))
);
trips!(
    t606_esi_sm_size_range,
    "T606",
    esi_io()
        .edit_sm(0, |s| s.min_size = Some(256))
        .edit_sm(1, |s| s.max_size = Some(64))
        .edit_sm(2, |s| s.min_size = Some(16))
);
trips!(
    t607_esi_pdo_assign_unknown,
    "T607",
    esi_io().remove(0x1C12).array(
        0x1C12,
        "RxPDO assign",
        &[
            (1, "SubIndex 001", Unsigned16, Rw, Some(u(0x1600))),
            (2, "SubIndex 002", Unsigned16, Rw, Some(u(0x1605))),
            (3, "SubIndex 003", Unsigned16, Rw, Some(u(0x1A00))),
        ],
    )
);
trips!(
    t608_esi_pdo_assign_default,
    "T608",
    esi_io()
        .at(0x1C13, 1)
        .default(u(0))
        .remove(0x1C12)
        .array(
            0x1C12,
            "RxPDO assign",
            &[
                (1, "SubIndex 001", Unsigned16, Rw, Some(u(0x1601))),
                (2, "SubIndex 002", Unsigned16, Rw, Some(u(0x1600))),
            ],
        )
        .edit_pdo(0x1601, |p| p.sync_manager = Some(2))
);
trips!(
    t609_esi_pdo_exclude_unknown,
    "T609",
    esi_io().edit_pdo(0x1600, |p| p.excludes = vec![0x1610])
);
trips!(t610_esi_pdo_exclude_asymmetric, "T610", esi_io().edit_pdo(0x1602, |p| p.excludes.clear()));
trips!(
    t611_esi_default_pdos_excluded,
    "T611",
    esi_io()
        .edit_pdo(0x1601, |p| p.mandatory = true)
        .edit_pdo(0x1602, |p| p.sync_manager = Some(2))
        .edit_sm(2, |s| s.max_size = None)
);
trips!(
    t612_esi_mailbox_sync_managers,
    "T612",
    esi_io().ethercat(|e| {
        e.sync_managers.swap(0, 1);
        e.sync_managers.truncate(1);
    })
);
trips!(
    t613_esi_mailbox_size,
    "T613",
    esi_io().edit_sm(0, |s| s.default_size = Some(8)).edit_sm(1, |s| s.default_size = None)
);
trips!(
    t614_esi_sm_control_byte,
    "T614",
    esi_io()
        .edit_sm(0, |s| s.control_byte = Some(Spanned::synthetic(0x24)))
        .edit_sm(1, |s| s.control_byte = Some(Spanned::synthetic(0x26)))
        .edit_sm(3, |s| s.control_byte = Some(Spanned::synthetic(0x2B)))
);

#[test]
fn process_data_may_use_mailbox_mode() {
    // A single-buffered (mailbox-mode) process-data sync manager is legal.
    let d = esi_io().edit_sm(2, |s| s.control_byte = Some(Spanned::synthetic(0x26)));
    assert_eq!(run(d), "");
}

trips!(
    t615_esi_sm_overlap,
    "T615",
    // SM 2 (outputs, 2 bytes, three buffers) occupies 0x1100..0x1106.
    esi_io().edit_sm(3, |s| s.start_address = Some(Spanned::synthetic(0x1104)))
);

#[test]
fn sync_managers_on_the_digital_io_registers_may_touch() {
    let d = esi_io()
        .edit_sm(2, |s| s.start_address = Some(Spanned::synthetic(0x0F00)))
        .edit_sm(3, |s| s.start_address = Some(Spanned::synthetic(0x0F01)));
    assert_eq!(run(d), "");
}

trips!(
    t616_esi_dc_assign_activate,
    "T616",
    esi_io().ethercat(|e| {
        if let Some(dc) = e.dc.as_mut() {
            dc.op_modes.push(op_mode("Sync0NoCyclic", 0x200));
            dc.op_modes.push(op_mode("Reserved", 0x0302));
            dc.op_modes.push(op_mode("TooWide", 0x10300));
        }
    })
);
trips!(
    t617_esi_dc_op_mode_name,
    "T617",
    esi_io().ethercat(|e| {
        if let Some(dc) = e.dc.as_mut() {
            dc.op_modes.push(op_mode(" ", 0x700));
        }
    })
);
trips!(
    t618_esi_sm_type_object,
    "T618",
    esi_io().at(0x1C00, 3).default(u(4)).at(0x1C00, 4).default(u(3))
);

trips!(
    t619_esi_subitem_duplicate,
    "T619",
    esi_io().ethercat(|e| {
        let items = &mut e.data_types[0].sub_items;
        items[2].name = "Vendor ID".into();
        let mut again = items[1].clone();
        again.name = "Revision".into();
        items.push(again);
    })
);
trips!(
    t620_esi_subitem_layout,
    "T620",
    esi_io().ethercat(|e| {
        let t = &mut e.data_types[0];
        t.sub_items[2].bit_offset = Some(40);
        let mut copy = t.clone();
        copy.name = "DT1018B".into();
        copy.sub_items[2].bit_offset = Some(128);
        e.data_types.push(copy);
    })
);
trips!(
    t621_esi_pdo_entry_alignment,
    "T621",
    esi_io().edit_pdo(0x1A00, |p| {
        p.entries.insert(0, esi_pdo(Direction::Tx, 0, None, &[(0, 0, 4)]).entries.remove(0));
    })
);

/// `esi_io` with a mapping object `index` in its dictionary listing `words`.
fn with_mapping(d: Dev, index: u16, words: &[u32]) -> Dev {
    let subs: Vec<_> = (1u8..)
        .zip(words)
        .map(|(k, &w)| (k, "SubIndex", Unsigned32, Ro, Some(u(u64::from(w)))))
        .collect();
    d.remove(index).array(index, "PDO mapping", &subs)
}

#[test]
fn mapping_objects_that_agree_with_their_pdos_pass() {
    let d = with_mapping(esi_io(), 0x1600, &[0x7000_0010]);
    let d = with_mapping(d, 0x1A00, &[0x6000_0010, 0]);
    let d = with_mapping(d, 0x1602, &[0x7000_0010, 0x7001_0020]);
    assert_eq!(run_with(d, &all_rules_on()), "");
}

trips!(
    t622_esi_pdo_mapping_default,
    "T622",
    // 0x1A00 maps 0x6000 with 8 bits, its TxPdo 16; 0x1600 lists two entries, its RxPdo one.
    with_mapping(
        with_mapping(esi_io(), 0x1A00, &[0x6000_0008]),
        0x1600,
        &[0x7000_0010, 0x7001_0020]
    )
);

#[test]
fn a_run_of_gaps_agrees_with_one_gap_of_their_bits() {
    let d = || {
        esi_io().edit_pdo(0x1A00, |p| {
            let gaps = [(0, 0, 4), (0, 0, 4), (0x6000, 0, 16)];
            p.entries = esi_pdo(Direction::Tx, 0, None, &gaps).entries;
        })
    };
    let out = run(with_mapping(d(), 0x1A00, &[0x0000_0008, 0x6000_0010]));
    assert!(!out.contains("[T622]"), "{out}");
    let out = run(with_mapping(d(), 0x1A00, &[0x0000_0004, 0x6000_0010]));
    assert!(out.contains("sub 2 is 0x6000:00/16 where entry 2 of the TxPdo is gap/4"), "{out}");
}

trips!(
    t623_esi_pdo_mapping_count,
    "T623",
    // The entries agree with the RxPdo's, but sub 0 counts none of them.
    with_mapping(esi_io(), 0x1600, &[0x7000_0010]).at(0x1600, 0).default(u(0))
);
trips!(t624_esi_mailbox_sm_disabled, "T624", esi_io().edit_sm(1, |s| s.enable = false));

#[test]
fn disabled_mailbox_sync_managers_of_a_device_without_mailbox_pass() {
    let d = esi_io().edit_sm(1, |s| s.enable = false).ethercat(|e| e.mailbox = None);
    assert!(!run(d).contains("[T624]"));
}

trips!(
    t625_esi_identity_revision,
    "T625",
    // 0x1018:03 defaults to 0x00010000.
    esi_io().with(|d| d.device_info.revision_number = Some(Spanned::synthetic(0x0002_0000)))
);

trips!(
    t626_esi_pdo_assign_zero,
    "T626",
    // Sub 0 counts two PDOs; the second is 0x0000 (rt-labs' xmc4 dynpdo slave has six such).
    esi_io().remove(0x1C13).array(
        0x1C13,
        "TxPDO assign",
        &[
            (1, "SubIndex 001", Unsigned16, Rw, Some(u(0x1A00))),
            (2, "SubIndex 002", Unsigned16, Rw, Some(u(0))),
        ],
    )
);
trips!(
    t627_esi_sm_default_size,
    "T627",
    // SM 2's default PDO 0x1600 takes 2 bytes; SM 3's one (0x1A00) takes 2 too.
    esi_io().edit_sm(2, |s| s.default_size = Some(8)).edit_sm(3, |s| s.default_size = Some(2))
);
trips!(
    t628_esi_device_emulation_mailbox,
    "T628",
    // ConfigData 8003…: PDI 0x80 (on-chip bus), 0x0141 = 0x03 (bit 0: device emulation).
    esi_io().ethercat(|e| {
        e.eeprom = Some(odc_model::ethercat::Eeprom {
            config_data: vec![0x80, 0x03, 0x00, 0x00],
            ..Default::default()
        });
    })
);

#[test]
fn device_emulation_without_a_mailbox_passes() {
    let d = esi_io().ethercat(|e| {
        e.mailbox = None;
        e.eeprom = Some(odc_model::ethercat::Eeprom {
            config_data: vec![0x05, 0x01, 0x00, 0x00],
            ..Default::default()
        });
    });
    assert!(!run(d).contains("[T628]"));
}

#[test]
fn t625_names_a_byte_swapped_revision() {
    let d =
        esi_io().with(|d| d.device_info.revision_number = Some(Spanned::synthetic(0x0000_0100)));
    let diags = odc_check::check(&d.build(), &odc_check::Config::in_registry(odc_check::rules()));
    let t625: Vec<_> = diags.iter().filter(|d| d.code == "T625").collect();
    assert_eq!(t625.len(), 1, "{diags:?}");
    assert!(t625[0].notes.iter().any(|n| n.contains("bytes are reversed")), "{t625:?}");
}

#[test]
fn an_agreeing_revision_passes() {
    let d =
        esi_io().with(|d| d.device_info.revision_number = Some(Spanned::synthetic(0x0001_0000)));
    assert_eq!(run_with(d, &all_rules_on()), "");
}

#[test]
fn bit_fields_padded_to_a_byte_are_aligned() {
    let d = esi_io().edit_pdo(0x1A00, |p| {
        let gap = esi_pdo(Direction::Tx, 0, None, &[(0, 0, 4), (0, 0, 4)]).entries;
        p.entries.splice(0..0, gap);
    });
    assert_eq!(run(d), "");
}

#[test]
fn c207_notes_byte_swapped_identity_in_an_esi() {
    let d = esi_io().with(|d| d.device_info.vendor_number = Some(Spanned::synthetic(0x3412_0000)));
    let device = d.build();
    let diags = odc_check::check(&device, &odc_check::Config::in_registry(odc_check::rules()));
    let c207: Vec<_> = diags.iter().filter(|d| d.code == "C207").collect();
    assert_eq!(c207.len(), 1, "{diags:?}");
    assert!(c207[0].notes.iter().any(|n| n.contains("bytes are reversed")), "{c207:?}");
}

#[test]
fn objects_synthesised_from_pdo_entries_are_not_checked_as_the_files() {
    // An ESI without a dictionary: odc made 0x603F (entries :00 of 16 bits and :01) and a
    // mapping object at 0x1018 (SoE PDO indexes are IDNs) from the PDO entries.
    let d = esi_io()
        .record(0x603F, "error_code", &[(1, "detail", Unsigned16, Ro, None)])
        .at(0x603F, 0)
        .data_type(Unsigned16)
        .remove(0x1018)
        .record(0x1018, "MDT 2", &[(1, "SubIndex 001", Unsigned32, Ro, Some(u(0x0086_0010)))])
        .with(|d| {
            d.device_info.vendor_number = Some(Spanned::synthetic(0x1234));
            for i in [0x603F, 0x1018] {
                if let Some(o) = d.objects.get_mut(&i) {
                    o.origin = odc_model::Origin::PdoEntry;
                }
            }
        });
    assert_eq!(run(d), "");
}

#[test]
fn esi_rules_do_not_run_on_canopen_devices() {
    let mut d = esi_io().edit_pdo(0x1600, |p| p.sync_manager = Some(7)).build();
    d.format = Some(odc_model::Format::Eds);
    d.pdos.clear();
    let out = odc_model::diag::render_short(
        &odc_model::Sources::new(),
        &odc_check::check(&d, &odc_check::Config::in_registry(odc_check::rules())),
    );
    assert!(!out.contains("[T6"), "{out}");
}
