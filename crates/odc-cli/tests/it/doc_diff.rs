//! `odc doc` and `odc diff` from the command line: files written, exit codes, formats.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

fn repo(file: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file).display().to_string()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odc-docdiff-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(o: &[u8]) -> String {
    String::from_utf8_lossy(o).into_owned()
}

#[test]
fn doc_writes_a_page_and_a_markdown_file() {
    let dir = scratch("both");
    let out = odc(&["doc", &repo("eds/lxm23a.eds"), "-o", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (html, md) = (dir.join("lxm23a.html"), dir.join("lxm23a.md"));
    // It says what it wrote.
    assert_eq!(text(&out.stdout), format!("{}\n{}\n", html.display(), md.display()));
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>"));
    // Self-contained: nothing fetched from elsewhere.
    for outside in ["<link", "src=\"http", "href=\"http", "@import", "url("] {
        assert!(!page.contains(outside), "{outside}");
    }
    // The six default PDOs with entries of the LXM23A, drawn.
    assert_eq!(page.matches("<svg").count(), 6);
    assert!(std::fs::read_to_string(&md).unwrap().starts_with("# LXM23A\n"));
    let only_md = scratch("md");
    let out =
        odc(&["doc", &repo("eds/lxm23a.eds"), "-o", only_md.to_str().unwrap(), "--format", "md"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(only_md.join("lxm23a.md").is_file() && !only_md.join("lxm23a.html").exists());
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&only_md);
}

#[test]
fn doc_links_a_warning_to_its_object() {
    // The MDrive's TPDO1 maps an object the file lacks (C301), allowed down to a warning.
    let dir = scratch("warning");
    let text_in = std::fs::read_to_string(repo("eds/lexium-mdrive.eds")).unwrap();
    let broken = text_in.replacen("DefaultValue=0x60410010", "DefaultValue=0x2FFF0010", 1);
    assert_ne!(text_in, broken);
    let file = dir.join("mdrive.eds");
    std::fs::write(&file, broken).unwrap();
    let out = odc(&["doc", file.to_str().unwrap(), "-o", dir.to_str().unwrap(), "-W", "C301"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let md = std::fs::read_to_string(dir.join("mdrive.md")).unwrap();
    let row = md.lines().find(|l| l.starts_with("| warning | C301 |")).expect("the C301 row");
    // Linked to the mapping entry that names the missing object.
    assert!(row.contains("](#o1A00-01)"), "{row}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn diff_exit_codes_and_formats() {
    let lxm = repo("eds/lxm23a.eds");
    let out = odc(&["diff", &lxm, &lxm]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(text(&out.stdout), "no differences\n");

    // The ServoOne's EDS against its ESI: the same drive, another format and fieldbus.
    let (eds, esi) = (repo("eds/servoone.eds"), repo("esi/servoone.xml"));
    let out = odc(&["diff", &eds, &esi, "--color", "never"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let human = text(&out.stdout);
    assert!(human.starts_with("identity\n"), "{human}");
    assert!(human.contains("  ~ format: EDS → ESI\n"), "{human}");
    assert!(!human.contains('\x1b'));
    let n: usize = human.lines().last().unwrap().split(' ').next().unwrap().parse().unwrap();
    let out = odc(&["diff", &eds, &esi, "--format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let list = json.as_array().unwrap();
    assert_eq!(list.len(), n, "the same differences in both formats");
    assert!(
        list.iter().any(|c| c["in"] == "identity" && c["field"] == "format" && c["b"] == "ESI")
    );
    // Colour on request.
    let out = odc(&["diff", &eds, &esi, "--color", "always"]);
    assert!(text(&out.stdout).contains("\x1b[33m~"));
    // Fewer with names left out.
    let out = odc(&["diff", &eds, &esi, "--format", "json", "--ignore-names"]);
    let fewer: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(fewer.as_array().unwrap().len() < n);

    // A missing file is an error (2), not a difference.
    let out = odc(&["diff", &lxm, "/nonexistent/x.eds"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
}

/// The Markdown sheet shows HTML in a device file's names as text (a renderer would otherwise
/// run it), and names the input by its file name, not the absolute path it was made from.
#[test]
fn doc_markdown_escapes_html_and_names_the_file() {
    let dir = scratch("escape");
    let text_in = std::fs::read_to_string(repo("eds/lxm23a.eds")).unwrap();
    let evil = text_in.replacen(
        "ParameterName=Profile velocity",
        "ParameterName=<script>alert(1)</script> & <b>velocity</b>",
        1,
    );
    assert_ne!(text_in, evil);
    let file = dir.join("evil.eds");
    std::fs::write(&file, evil).unwrap();
    std::fs::copy(repo("eds/lxm23a.odc.toml"), dir.join("evil.odc.toml")).unwrap();
    let abs = file.canonicalize().unwrap();
    let out = odc(&["doc", abs.to_str().unwrap(), "-o", dir.to_str().unwrap(), "--format", "md"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let md = std::fs::read_to_string(dir.join("evil.md")).unwrap();
    assert!(!md.contains("<script>") && !md.contains("<b>"), "raw HTML in the sheet");
    assert!(
        md.contains("&lt;script&gt;alert(1)&lt;/script&gt; &amp; &lt;b&gt;velocity&lt;/b&gt;"),
        "{md}"
    );
    assert!(md.starts_with("# LXM23A\n\n`evil.eds`\n"), "{}", &md[..80.min(md.len())]);
    assert!(!md.contains(dir.to_str().unwrap()), "the sheet names the directory it was made in");
    let _ = std::fs::remove_dir_all(&dir);
}
