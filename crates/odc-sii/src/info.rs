//! The few values of the ESI's `Device/Info` and `Device/Image16x14` the General category needs.
//! The ESI front-end keeps these elements as raw XML ([`odc_model::ethercat::RawXml`]); this
//! reads just those values back out of it.

use odc_model::ethercat::EtherCat;
use quick_xml::Reader;
use quick_xml::events::Event;

/// Values from `Device/Info` and the device image.
#[derive(Debug, Default)]
pub(crate) struct InfoValues {
    /// `Info/Electrical/EBusCurrent` in mA (negative: the device feeds the E-bus).
    pub ebus_current: Option<i64>,
    /// `Info/IdentificationAdo`: the ESC register that holds the identification value.
    pub identification_ado: Option<i64>,
    /// `Info/IdentificationReg134`: identification through AL status code (register 0x134).
    pub identification_reg134: bool,
    /// `Image16x14`: the image's name.
    pub image: Option<String>,
}

pub(crate) fn info_values(ec: &EtherCat) -> InfoValues {
    let mut out = InfoValues::default();
    for raw in &ec.raw {
        match raw.path.as_str() {
            "Device/Info" => read_info(&raw.xml, &mut out),
            "Device/Image16x14" => {
                out.image = element_texts(&raw.xml).into_iter().next().map(|(_, t)| t);
            }
            _ => {}
        }
    }
    out
}

fn read_info(xml: &str, out: &mut InfoValues) {
    for (path, text) in element_texts(xml) {
        match path.as_str() {
            "Info/Electrical/EBusCurrent" => out.ebus_current = parse_int(&text),
            "Info/IdentificationAdo" => out.identification_ado = parse_int(&text),
            "Info/IdentificationReg134" => {
                out.identification_reg134 = matches!(text.trim(), "1" | "true");
            }
            _ => {}
        }
    }
}

/// The text of every element of `xml` with the path of its element (`Info/Electrical/...`).
/// The XML was well-formed when the front-end read it; a text that cannot be read is skipped
/// (its field then takes the ETG.2010 default, as when absent).
fn element_texts(xml: &str) -> Vec<(String, String)> {
    let mut reader = Reader::from_str(xml);
    let mut path: Vec<String> = Vec::new();
    let mut text = String::new();
    let mut out = Vec::new();
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) => {
                path.push(e.local_name().into_inner().to_string());
                text.clear();
            }
            Ok(Event::End(_)) => {
                if !text.trim().is_empty() {
                    out.push((path.join("/"), text.trim().to_string()));
                }
                text.clear();
                path.pop();
            }
            Ok(Event::Text(t)) => text.push_str(t.as_ref()),
            Ok(Event::CData(t)) => text.push_str(&t),
            Ok(Event::GeneralRef(r)) => match r.resolve_char_ref() {
                Ok(Some(c)) => text.push(c),
                _ => text.push_str(match &*r {
                    "amp" => "&",
                    "lt" => "<",
                    "gt" => ">",
                    "quot" => "\"",
                    "apos" => "'",
                    _ => "",
                }),
            },
            Ok(Event::Eof) | Err(_) => break,
            Ok(_) => {}
        }
    }
    out
}

/// An ETG.2000 `HexDecValue`: decimal or `#x` hex, optionally signed.
fn parse_int(text: &str) -> Option<i64> {
    let t = text.trim();
    let (neg, t) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t),
    };
    let v = match t.strip_prefix("#x").or_else(|| t.strip_prefix("#X")) {
        Some(hex) => i64::from_str_radix(hex, 16).ok()?,
        None => t.parse().ok()?,
    };
    Some(if neg { -v } else { v })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use odc_model::ethercat::RawXml;

    #[test]
    fn reads_info_values() {
        let ec = EtherCat {
            raw: vec![
                RawXml {
                    path: "Device/Info".into(),
                    xml: "<Info><Electrical><EBusCurrent>-250</EBusCurrent></Electrical>\
                          <IdentificationAdo>#x1000</IdentificationAdo>\
                          <IdentificationReg134>true</IdentificationReg134></Info>"
                        .into(),
                    span: Default::default(),
                },
                RawXml {
                    path: "Device/Image16x14".into(),
                    xml: "<Image16x14>DRIVE &amp; CO</Image16x14>".into(),
                    span: Default::default(),
                },
            ],
            ..EtherCat::default()
        };
        let v = info_values(&ec);
        assert_eq!(v.ebus_current, Some(-250));
        assert_eq!(v.identification_ado, Some(0x1000));
        assert!(v.identification_reg134);
        assert_eq!(v.image.as_deref(), Some("DRIVE & CO"));
    }
}
