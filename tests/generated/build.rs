//! Generates the code of the repository's device files (role both), and the slave side of the
//! benchmark dictionaries (`benches/slave.rs`).

use std::fmt::Write as _;
use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in ["eds/lxm23a.eds", "eds/lexium-mdrive.eds"] {
        config.device(root.join(name));
    }
    config.device(root.join("crates/odc-codegen/tests/fixtures/mini-drive.eds"));
    config.device(root.join("esi/servoone.xml"));
    config.device(root.join("crates/odc-codegen/tests/fixtures/pdi-terminal.xml"));
    // A CoE device whose ESI dictionary leaves out 0x1C00, 0x1C12/0x1C13 and the mapping
    // objects: the generated dictionary has them (odc-esi synthesises them).
    config.device(root.join("crates/odc-esi/tests/fixtures/coe_implied.xml"));
    config.compile()?;

    // Values that do not fit their types, allowed: generation leaves them out and goes on.
    let mut allow_f108 = odc_build::odc_pipeline::check_config();
    allow_f108.set_level("F108", odc_build::odc_pipeline::Level::Allow)?;
    odc_build::Config::new()
        .device(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bad-values.eds"))
        .check_config(allow_f108)
        .compile()?;

    // Only `benches/slave.rs` includes these two; the library and its tests do not compile
    // them.
    let out = std::env::var_os("OUT_DIR")
        .map(std::path::PathBuf::from)
        .ok_or(odc_build::Error::NotInBuildScript)?;
    let bench_eds = out.join("bench500.eds");
    odc_build::write_if_changed(&bench_eds, bench_500_eds().as_bytes())?;
    odc_build::Config::new()
        .role(odc_build::Role::Slave)
        .device(&bench_eds)
        .device(root.join("eds/lenze-e94aycca.eds"))
        .compile()
}

/// A made-up CiA 301 device of exactly 500 objects, for the lookup benchmark: 0x1000, 0x1001,
/// 0x1017, the identity record 0x1018, then 496 manufacturer objects from 0x2000 on, every
/// fifth a record of four sub-objects and the others variables of seven data types: 900
/// entries.
fn bench_500_eds() -> String {
    const TYPES: [(u16, &str); 7] = [
        (0x0005, "0"),      // UNSIGNED8
        (0x0006, "0x100"),  // UNSIGNED16
        (0x0007, "0x1000"), // UNSIGNED32
        (0x0003, "-1"),     // INTEGER16
        (0x0004, "100"),    // INTEGER32
        (0x0008, "0"),      // REAL32
        (0x0001, "0"),      // BOOLEAN
    ];
    let manufacturer: Vec<u16> = (0..496).map(|i| 0x2000 + i).collect();
    let mut s = String::new();
    let mut w = |text: &str| s.push_str(text);
    w("[FileInfo]\nFileName=bench500.eds\nFileVersion=1\nFileRevision=0\nEDSVersion=4.0\n\
       Description=500 objects for odc's slave lookup benchmark\n\n\
       [DeviceInfo]\nVendorName=odc\nVendorNumber=0x000001DD\nProductName=Bench 500\n\
       ProductNumber=0x00000500\nRevisionNumber=0x00010000\nOrderCode=B500\n\
       BaudRate_10=0\nBaudRate_20=0\nBaudRate_50=0\nBaudRate_125=1\nBaudRate_250=1\n\
       BaudRate_500=1\nBaudRate_800=0\nBaudRate_1000=1\nSimpleBootUpMaster=0\n\
       SimpleBootUpSlave=1\nGranularity=8\nDynamicChannelsSupported=0\nCompactPDO=0\n\
       GroupMessaging=0\nNrOfRXPDO=0\nNrOfTXPDO=0\nLSS_Supported=0\n\n\
       [DummyUsage]\nDummy0001=0\nDummy0002=0\nDummy0003=0\nDummy0004=0\nDummy0005=0\n\
       Dummy0006=0\nDummy0007=0\n\n\
       [MandatoryObjects]\nSupportedObjects=3\n1=0x1000\n2=0x1001\n3=0x1018\n\n\
       [OptionalObjects]\nSupportedObjects=1\n1=0x1017\n\n");
    let mut list = format!("[ManufacturerObjects]\nSupportedObjects={}\n", manufacturer.len());
    for (n, index) in manufacturer.iter().enumerate() {
        let _ = writeln!(list, "{}=0x{index:04X}", n + 1);
    }
    w(&list);
    w("\n[1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n\
       DefaultValue=0x00000000\nPDOMapping=0\n\n\
       [1001]\nParameterName=Error register\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\n\
       DefaultValue=0\nPDOMapping=1\n\n\
       [1017]\nParameterName=Producer heartbeat time\nObjectType=0x7\nDataType=0x0006\n\
       AccessType=rw\nDefaultValue=0\nPDOMapping=0\n\n\
       [1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=5\n\n\
       [1018sub0]\nParameterName=Highest sub-index supported\nObjectType=0x7\n\
       DataType=0x0005\nAccessType=const\nDefaultValue=4\nPDOMapping=0\n\n");
    for (sub, name, value) in [
        (1, "Vendor-ID", "0x000001DD"),
        (2, "Product code", "0x00000500"),
        (3, "Revision number", "0x00010000"),
        (4, "Serial number", "0"),
    ] {
        let _ = write!(
            s,
            "[1018sub{sub}]\nParameterName={name}\nObjectType=0x7\nDataType=0x0007\n\
             AccessType=ro\nDefaultValue={value}\nPDOMapping=0\n\n"
        );
    }
    for (n, &index) in manufacturer.iter().enumerate() {
        if n % 5 == 4 {
            let _ = write!(
                s,
                "[{index:04X}]\nParameterName=Record {n}\nObjectType=0x9\nSubNumber=5\n\n\
                 [{index:04X}sub0]\nParameterName=Highest sub-index supported\nObjectType=0x7\n\
                 DataType=0x0005\nAccessType=const\nDefaultValue=4\nPDOMapping=0\n\n"
            );
            for (sub, (ty, default)) in [1, 2, 4, 6].into_iter().map(|t| TYPES[t]).enumerate() {
                let sub = sub + 1;
                let _ = write!(
                    s,
                    "[{index:04X}sub{sub:X}]\nParameterName=Field {sub}\nObjectType=0x7\n\
                     DataType=0x{ty:04X}\nAccessType=rw\nDefaultValue={default}\nPDOMapping=1\n\n"
                );
            }
        } else {
            let (ty, default) = TYPES[n % TYPES.len()];
            let access = if n % 3 == 0 { "ro" } else { "rw" };
            let limits = if ty == 0x0004 { "LowLimit=-1000\nHighLimit=1000\n" } else { "" };
            let _ = write!(
                s,
                "[{index:04X}]\nParameterName=Parameter {n}\nObjectType=0x7\nDataType=0x{ty:04X}\n\
                 AccessType={access}\nDefaultValue={default}\n{limits}PDOMapping=0\n\n"
            );
        }
    }
    s
}
