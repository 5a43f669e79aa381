//! Vendor parameter schemes: the module generated from a `[[scheme]]`, and the `G604`
//! diagnostics for rules that cannot be generated.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use crate::common;

use odc_codegen::{Options, Overlay, generate};

fn with_schemes(toml: &str) -> Options {
    let overlay = Overlay::from_toml(toml).expect("overlay parses");
    Options { source_name: "mini-drive.eds".into(), overlay, ..Options::default() }
}

/// The text of `pub mod <name> { ... }` in generated code.
fn module<'a>(code: &'a str, name: &str) -> &'a str {
    let start = code.find(&format!("\npub mod {name} {{")).expect("module generated");
    let end = code[start + 1..].find("\n}\n").map_or(code.len(), |e| start + 1 + e + 3);
    &code[start + 1..end]
}

#[test]
fn element_scheme_module() {
    // The mini drive's only manufacturer object is 0x2000, "type": parameter 0 of this rule.
    let opts = with_schemes(
        r#"
        [[scheme]]
        module = "vendor"
        function = "param"
        doc = "Parameters P n at 0x2000 + n."
        index = "0x2000 + n"
        args = [{ name = "n", range = "0..=0x1FFF" }]
        const-name = "P{n:03}"
        element = { name = "e", range = "0..=9", offset = 1 }
        "#,
    );
    let code = generate(&common::drive(), &opts).expect("generates");
    insta::assert_snapshot!(module(&code, "vendor"));
}

#[test]
fn selector_scheme_module() {
    let opts = with_schemes(
        r#"
        [[scheme]]
        module = "upid"
        function = "param"
        index = "0x2000 + 2 * id - 2"
        args = [{ name = "id", range = "1..=100" }]
        exclude = ["0x2002"]
        selector = { type = "Op", arg = "op", values = [{ name = "ram", sub = 1, doc = "RAM value" }, { name = "rom", sub = 2 }] }
        "#,
    );
    let code = generate(&common::drive(), &opts).expect("generates");
    insta::assert_snapshot!(module(&code, "upid"));
}

/// `write-size` gives the module the width its device takes every write at.
#[test]
fn write_size_constant() {
    let rule = "[[scheme]]\nmodule = \"v\"\nfunction = \"f\"\nindex = \"0x2000 + n\"\nargs = [{ name = \"n\", range = \"0..=9\" }]\n";
    let code = generate(&common::drive(), &with_schemes(&format!("{rule}write-size = 4\n")))
        .expect("generates");
    let code = code.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(code.contains("pub const WRITE_SIZE: usize = 4;"), "{code}");
    let plain = generate(&common::drive(), &with_schemes(rule)).expect("generates");
    assert!(!plain.contains("WRITE_SIZE"));
    let errors = generate(&common::drive(), &with_schemes(&format!("{rule}write-size = 8\n")))
        .expect_err("wider than an expedited transfer");
    assert!(errors[0].message.contains("write-size"), "{}", errors[0].message);
}

#[test]
fn bad_schemes_are_g604_errors() {
    let cases = [
        ("index = \"0x2000 + n * m\"", "linear"),
        ("index = \"0x2000 + k\"", "no argument"),
        ("index = \"0xFFFF + n\"", "beyond 0..=0xFFFF"),
        ("index = \"0x2000 + n\"\nconst-name = \"p{n}\"", "upper-case"),
        ("index = \"0x2000 + n\"\nconst-name = \"P{q}\"", "no argument `q`"),
    ];
    for (rule, expected) in cases {
        let toml = format!(
            "[[scheme]]\nmodule = \"v\"\nfunction = \"f\"\n{rule}\nargs = [{{ name = \"n\", range = \"0..=9\" }}]\n"
        );
        let errors = generate(&common::drive(), &with_schemes(&toml)).expect_err(rule);
        assert_eq!(errors.len(), 1, "{rule}");
        assert_eq!(errors[0].code, "G604");
        assert!(errors[0].message.contains(expected), "{rule}: {}", errors[0].message);
    }
    let twice = "[[scheme]]\nmodule = \"v\"\nfunction = \"f\"\nindex = \"n\"\nargs = [{ name = \"n\", range = \"0..=9\" }]\n";
    let errors = generate(&common::drive(), &with_schemes(&format!("{twice}{twice}")))
        .expect_err("two modules of one name");
    assert!(errors[0].message.contains("two schemes"), "{}", errors[0].message);
}

#[test]
fn process_data_module() {
    let opts = with_schemes(
        r#"
        [[process-data]]
        name = "RxPdo1"
        cob-id = "0x200"
        doc = "RxPDO 1 as the manual lays it out."
        fields = [
            { name = "control_word", type = "u16", doc = "Control Word." },
            { name = "offset", type = "i8" },
            { name = "position", type = "i32" },
        ]
        "#,
    );
    let code = generate(&common::drive(), &opts).expect("generates");
    insta::assert_snapshot!(module(&code, "process"));
}

#[test]
fn bad_process_data_is_g605() {
    let cases = [
        ("{ name = \"a\", type = \"f32\" }", "not u8..i32"),
        ("{ name = \"a b\", type = \"u8\" }", "not a Rust identifier"),
        (
            "{ name = \"a\", type = \"u32\" }, { name = \"b\", type = \"u32\" }, { name = \"c\", type = \"u8\" }",
            "72 bits",
        ),
    ];
    for (fields, expected) in cases {
        let toml =
            format!("[[process-data]]\nname = \"P\"\ncob-id = \"0x180\"\nfields = [{fields}]\n");
        let errors = generate(&common::drive(), &with_schemes(&toml)).expect_err(fields);
        assert_eq!(errors[0].code, "G605");
        assert!(errors[0].message.contains(expected), "{fields}: {}", errors[0].message);
    }
}
