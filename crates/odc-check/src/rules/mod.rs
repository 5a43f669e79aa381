//! The rules, one module per area; each rule is a `const Rule` next to its check function.

mod cia402;
mod cob;
mod dcf;
mod ethercat;
mod lists;
mod pdo;
mod structure;
mod values;

use crate::Rule;

/// Declares a rule: `rule!(NAME, "C101", "kebab-name", group, Severity, Level, check_fn,
/// "summary", "explanation")`.
macro_rules! rule {
    ($id:ident, $code:literal, $name:literal, $group:literal, $sev:ident, $level:ident,
     $check:path, $summary:literal, $expl:expr $(,)?) => {
        pub(crate) const $id: $crate::Rule = $crate::Rule {
            info: odc_model::RuleInfo {
                code: $code,
                name: $name,
                group: $group,
                default: odc_model::Severity::$sev,
                summary: $summary,
                explanation: $expl,
            },
            level: $crate::Level::$level,
            check: $check,
        };
    };
}
pub(crate) use rule;

/// Every rule of this crate, in code order.
pub(crate) const ALL: &[Rule] = &[
    lists::C101,
    lists::C102,
    lists::C103,
    lists::C104,
    lists::C105,
    structure::C110,
    structure::C111,
    structure::C112,
    structure::C113,
    structure::C114,
    structure::C115,
    structure::C116,
    structure::C117,
    structure::C118,
    structure::C119,
    values::C201,
    values::C202,
    values::C203,
    values::C204,
    values::C205,
    values::C206,
    values::C207,
    values::C208,
    values::C209,
    values::C210,
    pdo::C301,
    pdo::C302,
    pdo::C303,
    pdo::C304,
    pdo::C305,
    pdo::C306,
    pdo::C307,
    pdo::C308,
    pdo::C309,
    pdo::C310,
    cob::C401,
    cob::C402,
    cob::C403,
    cob::C404,
    cob::C405,
    cob::C406,
    cob::C407,
    cob::C408,
    cob::C409,
    cob::C410,
    dcf::C501,
    dcf::C502,
    dcf::C503,
    dcf::C504,
    dcf::C505,
    dcf::C506,
    dcf::C507,
    dcf::C508,
    dcf::C509,
    cia402::D501,
    cia402::D502,
    cia402::D503,
    cia402::D504,
    cia402::D505,
    cia402::D506,
    cia402::D507,
    ethercat::T601,
    ethercat::T602,
    ethercat::T603,
    ethercat::T604,
    ethercat::T605,
    ethercat::T606,
    ethercat::T607,
    ethercat::T608,
    ethercat::T609,
    ethercat::T610,
    ethercat::T611,
    ethercat::T612,
    ethercat::T613,
    ethercat::T614,
    ethercat::T615,
    ethercat::T616,
    ethercat::T617,
    ethercat::T618,
    ethercat::T619,
    ethercat::T620,
    ethercat::T621,
    ethercat::T622,
    ethercat::T623,
    ethercat::T624,
    ethercat::T625,
    ethercat::T626,
    ethercat::T627,
    ethercat::T628,
];
