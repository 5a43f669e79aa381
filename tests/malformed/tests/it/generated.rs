//! The generated hostile inputs (see `odc_tests_malformed::generated`): each gets its
//! diagnostic, snapshotted; human rendering stays small however long the line.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test code: a panic is a failure report

#[test]
fn generated_inputs() {
    for g in odc_tests_malformed::generated() {
        let outcome = odc_tests_malformed::run(g.name, &(g.make)(), g.xml, false);
        insta::assert_snapshot!(g.name, outcome.report());
        let human = odc_model::diag::render_human(&outcome.sources, &outcome.diagnostics, false);
        assert!(human.len() < 4_000_000, "{}: {} bytes of human output", g.name, human.len());
    }
}

#[test]
fn a_10mb_line_is_not_quoted() {
    let g = odc_tests_malformed::generated().into_iter().next().unwrap();
    let outcome = odc_tests_malformed::run(g.name, &(g.make)(), g.xml, false);
    let human = odc_model::diag::render_human(&outcome.sources, &outcome.diagnostics, false);
    insta::assert_snapshot!(human);
}
