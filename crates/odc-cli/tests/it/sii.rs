//! `odc sii` and `odc info` of an SII image, as a user runs them.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

fn repo_file(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path).display().to_string()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odc-cli-sii-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn sii_writes_the_image_and_info_reads_it_back() {
    let dir = temp_dir("servoone");
    let bin = dir.join("servoone.bin");
    let out = odc(&["sii", &repo_file("esi/servoone.xml"), "-o", bin.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let image = std::fs::read(&bin).unwrap();
    // The ESI's `Eeprom/ByteSize` is 2048.
    assert_eq!(image.len(), 2048);
    let out = odc(&["info", bin.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(out.status.code(), Some(0), "{text}");
    // servoone.xml: Sm MBoxOut at #x1000, MBoxIn at #x1080, DefaultSize 128; CoE, FoE, EoE.
    assert!(text.contains("checksum 0x") && text.contains("(ok)"), "{text}");
    assert!(text.contains("standard mailbox: receive 0x1000+128  send 0x1080+128"), "{text}");
    assert!(text.contains("EoE CoE FoE"), "{text}");
    assert!(text.contains("SM2 Outputs"), "{text}");
    // Found by content under another extension too.
    let other = dir.join("image.dat");
    std::fs::copy(&bin, &other).unwrap();
    let out = odc(&["info", other.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("SII image, 2048 bytes"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// servoone.xml with another `Eeprom/ByteSize`, and its overlay beside it (the copy's gate
/// stays the original's).
fn servoone_with_byte_size(dir: &Path, name: &str, byte_size: u32) -> PathBuf {
    let esi = std::fs::read_to_string(repo_file("esi/servoone.xml")).unwrap();
    let path = dir.join(format!("{name}.xml"));
    let replaced =
        esi.replace("<ByteSize>2048</ByteSize>", &format!("<ByteSize>{byte_size}</ByteSize>"));
    std::fs::write(&path, replaced).unwrap();
    let _ = std::fs::copy(repo_file("esi/servoone.odc.toml"), dir.join(format!("{name}.odc.toml")));
    path
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn what_does_not_fit_byte_size_is_left_out_with_a_warning_that_can_be_denied() {
    let dir = temp_dir("small");
    let small = servoone_with_byte_size(&dir, "small", 256);
    let bin = dir.join("small.bin");
    let out = odc(&["sii", small.to_str().unwrap(), "-o", bin.to_str().unwrap()]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert_eq!(std::fs::read(&bin).unwrap().len(), 256, "the ESI's ByteSize");
    assert!(text.contains("warning[S702]"), "{text}");
    // servoone.xml has DC op modes and PDOs; 256 bytes leave room for neither.
    assert!(text.contains("left out: the DC category (2 op modes)"), "{text}");
    assert!(text.contains("left out: the TxPDO and RxPDO categories"), "{text}");
    // Denied, the omission refuses the image and leaves the old file.
    std::fs::write(&bin, b"previous").unwrap();
    let out = odc(&["sii", small.to_str().unwrap(), "-o", bin.to_str().unwrap(), "-D", "S702"]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("error[S702]") && text.contains("-A S702"), "{text}");
    assert_eq!(std::fs::read(&bin).unwrap(), b"previous");
    // `--grow`: nothing left out, a larger EEPROM.
    let out = odc(&["sii", small.to_str().unwrap(), "-o", bin.to_str().unwrap(), "--grow"]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(!text.contains("S702") && text.contains("note[S703]"), "{text}");
    let grown = std::fs::read(&bin).unwrap();
    assert!(grown.len() > 256 && grown.len().is_power_of_two(), "{}", grown.len());
    let out = odc(&["info", bin.to_str().unwrap()]);
    let info = String::from_utf8_lossy(&out.stdout).into_owned();
    let n = grown.len();
    assert!(info.starts_with(&format!("SII image, {n} bytes (size word: {n} bytes)")), "{info}");
    assert!(info.contains("TxPDO 0x1A00"), "{info}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_eeprom_smaller_than_the_info_area_is_refused_unless_s701_is_allowed() {
    let dir = temp_dir("tiny");
    let tiny = servoone_with_byte_size(&dir, "tiny", 100);
    let bin = dir.join("tiny.bin");
    std::fs::write(&bin, b"previous").unwrap();
    let out = odc(&["sii", tiny.to_str().unwrap(), "-o", bin.to_str().unwrap()]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("error[S701]") && text.contains("`Eeprom/ByteSize` is 100"), "{text}");
    assert!(text.contains("(on the command line `-A S701`)"), "{text}");
    assert_eq!(std::fs::read(&bin).unwrap(), b"previous", "the old file stays");
    for level in [["-W", "S701"], ["-A", "sii-does-not-fit"]] {
        let out =
            odc(&["sii", tiny.to_str().unwrap(), "-o", bin.to_str().unwrap(), level[0], level[1]]);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(0), "{level:?}: {text}");
        assert_eq!(text.contains("warning[S701]"), level[0] == "-W", "{text}");
        let image = std::fs::read(&bin).unwrap();
        assert!(image.len() >= 256 && image.len().is_power_of_two(), "{}", image.len());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_eds_has_no_sii_image() {
    let dir = temp_dir("eds");
    let bin = dir.join("x.bin");
    let out = odc(&["sii", &repo_file("eds/lxm23a.eds"), "-o", bin.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("needs an ESI device"), "{text}");
    assert!(!bin.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
