//! The HTML page rendered by a real browser: headless Chromium loads the page of each device
//! file in `eds/` and `esi/` (and, with the corpus, of a Beckhoff terminal with a default
//! process image) from a `file://` URL. From the DOM Chromium built: every object and
//! sub-object of the model has its anchor, and every PDO and process image with entries has
//! its SVG with one field per entry. From its screenshot: the page is not blank. The pages
//! and screenshots stay in `target/tmp/odc-doc-browser/` for a person to look at.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use odc_model::Device;

/// The flags a headless Chromium needs here: no sandbox (root), no GPU, and none of its
/// background connections (a closed network refuses them, slowly).
const FLAGS: [&str; 9] = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
];

fn out_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("odc-doc-browser");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn chromium(profile: &Path, args: &[String]) -> std::process::Output {
    // Unset when the build script found no browser: the tests are then ignored, and run by
    // hand (`--ignored`) they name what is missing.
    let out = Command::new(odc_tests_support::chromium())
        .args(FLAGS)
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .output()
        .expect("chromium runs (install Debian's `chromium`, or set ODC_CHROMIUM)");
    assert!(out.status.success(), "chromium failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// The part of `dom` from the opening tag with `id="{id}"` to the next `</svg>`.
fn svg<'d>(dom: &'d str, id: &str) -> Option<&'d str> {
    let at = dom.find(&format!("id=\"{id}\""))?;
    let end = dom[at..].find("</svg>")?;
    Some(&dom[at..at + end])
}

/// Checks the page of one device; returns (anchors, diagrams, fields) checked.
fn check_page(name: &str, loaded: &odc_pipeline::Loaded, device: &Device) -> (usize, usize, usize) {
    let input = odc_doc::Input {
        device,
        file: &loaded.name,
        sources: Some(&loaded.sources),
        diagnostics: &loaded.diagnostics,
        schemes: &loaded.codegen.scheme,
    };
    let html = odc_doc::render_html(&input);
    let dir = out_dir();
    let page = dir.join(format!("{name}.html"));
    std::fs::write(&page, &html).unwrap();
    let url = format!("file://{}", page.display());
    let profile = dir.join(format!("profile-{name}"));
    let dom =
        String::from_utf8(chromium(&profile, &["--dump-dom".into(), url.clone()]).stdout).unwrap();
    assert!(dom.contains("id=\"filter\""), "{name}: no filter box in the DOM");

    // Every object and sub-object has its row, by the anchor scheme the page documents.
    let mut anchors = 0;
    for o in device.objects.values() {
        let mut ids = vec![format!("o{:04X}", o.index)];
        if o.kind.has_subs() {
            ids.extend(o.subs.keys().map(|s| format!("o{:04X}-{s:02X}", o.index)));
        }
        for id in ids {
            assert!(dom.contains(&format!("id=\"{id}\"")), "{name}: no row {id}");
            anchors += 1;
        }
    }
    // Every PDO with entries, and each direction of an EtherCAT image: one field per entry.
    let mut expected: Vec<(String, usize)> = device
        .pdos
        .iter()
        .filter(|p| !p.entries.is_empty())
        .map(|p| (format!("svg-pdo-{:04X}", p.mapping_index), p.entries.len()))
        .collect();
    if device.ethercat.is_some()
        && let Ok((outputs, inputs)) = odc_analysis::image::default_images(device)
    {
        for (image, id) in [(outputs, "svg-image-out"), (inputs, "svg-image-in")] {
            let n: usize = image.segments.iter().map(|s| s.entries.len()).sum();
            if n > 0 {
                expected.push((id.to_owned(), n));
            }
        }
    }
    let mut fields = 0;
    for (id, n) in &expected {
        let svg = svg(&dom, id).unwrap_or_else(|| panic!("{name}: no {id} in the DOM"));
        assert_eq!(svg.matches("class=\"field").count(), *n, "{name}: fields of {id}");
        fields += n;
    }
    assert_eq!(dom.matches("<svg").count(), expected.len(), "{name}: diagrams");

    // A screenshot tall enough for the whole page; not blank.
    let height = 1200 + 26 * anchors + 260 * expected.len();
    let shot = dir.join(format!("{name}.png"));
    chromium(
        &profile,
        &[format!("--window-size=1280,{height}"), format!("--screenshot={}", shot.display()), url],
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let px = info.color_type.samples();
    let pixels = &buf[..info.buffer_size()];
    let (mut ink, mut total) = (0usize, 0usize);
    let mut colours = std::collections::BTreeSet::new();
    for p in pixels.chunks_exact(px) {
        total += 1;
        if p.iter().take(3).any(|&c| c < 200) {
            ink += 1;
        }
        if colours.len() < 64 {
            colours.insert(p.iter().take(3).copied().collect::<Vec<u8>>());
        }
    }
    assert!(colours.len() >= 8, "{name}: screenshot of {} colours", colours.len());
    assert!(ink * 200 > total, "{name}: screenshot nearly blank ({ink} of {total} pixels)");
    println!(
        "{name}: {anchors} object anchors, {} diagrams with {fields} fields; screenshot {} ({}x{})",
        expected.len(),
        shot.display(),
        info.width,
        info.height
    );
    (anchors, expected.len(), fields)
}

fn pages_render_in_chromium() {
    let mut shipped = vec![
        "eds/lxm23a.eds",
        "eds/lexium-mdrive.eds",
        "eds/servoone.eds",
        "eds/lenze-e94aycca.eds",
        "eds/linmot-e1200.eds",
        "esi/servoone.xml",
    ];
    let mut totals = (0, 0, 0);
    for file in shipped.drain(..) {
        let loaded = common::load(file);
        let name = Path::new(file).file_name().unwrap().to_string_lossy().replace('.', "_");
        let (a, d, f) = check_page(&name, &loaded, &loaded.devices[0]);
        totals = (totals.0 + a, totals.1 + d, totals.2 + f);
    }
    // The LXM23A: 6 PDOs with entries (RPDO1-3, TPDO1-3); the manual's default mappings.
    let lxm = common::load("eds/lxm23a.eds");
    assert_eq!(lxm.devices[0].pdos.iter().filter(|p| !p.entries.is_empty()).count(), 6);
    println!("total: {} anchors, {} diagrams, {} fields", totals.0, totals.1, totals.2);
}

fn an_ethercat_terminal_with_its_process_image() {
    let file = odc_tests_support::corpus().join("esi/beckhoff__Beckhoff_EL15xx.xml");
    let options = odc_pipeline::Options::new()
        .select(odc_pipeline::Select::Spec("0x05DE3052:0x00160000".into()));
    let loaded = odc_pipeline::load(&file, &options).unwrap();
    let (_, diagrams, fields) = check_page("EL1502", &loaded, &loaded.devices[0]);
    // Its PDOs with entries and both directions of the image.
    assert!(diagrams >= 2 && fields > 0, "{diagrams} diagrams, {fields} fields");
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "an_ethercat_terminal_with_its_process_image",
            run: an_ethercat_terminal_with_its_process_image,
            needs: &[Need::Chromium, Need::Corpus],
        },
        Test {
            name: "pages_render_in_chromium",
            run: pages_render_in_chromium,
            needs: &[Need::Chromium],
        },
    ])
}
