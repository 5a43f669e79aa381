//! The `Eeprom` element: what the ESI says the device's SII EEPROM holds (ETG.2000 `EepromType`).

use odc_model::ethercat::{EepromCategory, EepromSpans};

use super::*;

pub(super) fn lower_eeprom(e: Element<'_>, ctx: &mut Ctx<'_>) -> Eeprom {
    let [byte_size, config_data, boot_strap, data] =
        e.pick(["ByteSize", "ConfigData", "BootStrap", "Data"]);
    let spans = EepromSpans {
        byte_size: byte_size.map(|c| c.text_span()),
        config_data: config_data.map(|c| c.text_span()),
        boot_strap: boot_strap.map(|c| c.text_span()),
        data: data.map(|c| c.text_span()),
    };
    Eeprom {
        byte_size: ctx.opt_u32(byte_size, "ByteSize"),
        config_data: config_data.map(|c| ctx.hex(c)).unwrap_or_default(),
        boot_strap: boot_strap.map(|c| ctx.hex(c)).unwrap_or_default(),
        data: data.map(|c| ctx.hex(c)).unwrap_or_default(),
        categories: e.children_named("Category").filter_map(|c| category(c, ctx)).collect(),
        assign_to_pdi: ctx.attr_bool(e, "AssignToPdi"),
        spans,
        span: e.span(),
    }
}

/// One `Category`: `CatNo` and one of `Data`, `DataString`, `DataUINT`, `DataUDINT`. A category
/// without a readable `CatNo` is reported and left out (it has no place in the SII).
fn category(c: Element<'_>, ctx: &mut Ctx<'_>) -> Option<EepromCategory> {
    let [cat_no, data, string, uint, udint] =
        c.pick(["CatNo", "Data", "DataString", "DataUINT", "DataUDINT"]);
    let Some(cat_no) = cat_no else {
        ctx.missing(c, "CatNo");
        return None;
    };
    let cat_no: u16 = ctx.el_num(cat_no, "CatNo")?;
    let data = if let Some(d) = data {
        ctx.hex(d)
    } else if let Some(s) = string {
        s.text().as_bytes().to_vec()
    } else if let Some(u) = uint {
        ctx.el_num::<u16>(u, "DataUINT").map(|v| v.to_le_bytes().to_vec()).unwrap_or_default()
    } else if let Some(u) = udint {
        ctx.el_u32(u, "DataUDINT").map(|v| v.to_le_bytes().to_vec()).unwrap_or_default()
    } else {
        ctx.missing(c, "Data");
        Vec::new()
    };
    Some(EepromCategory {
        cat_no,
        data,
        preserve_online_data: ctx.attr_bool(c, "PreserveOnlineData").unwrap_or(false),
        span: c.span(),
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use odc_model::Sources;

    fn eeprom(inner: &str) -> (Option<odc_model::ethercat::Eeprom>, Vec<String>) {
        let xml = format!(
            "<EtherCATInfo><Vendor><Id>1</Id><Name>V</Name></Vendor><Descriptions><Devices>\
             <Device><Type ProductCode=\"1\" RevisionNo=\"1\">T</Type><Name>N</Name>\
             <Eeprom>{inner}</Eeprom></Device></Devices></Descriptions></EtherCATInfo>"
        );
        let p = crate::parse(&mut Sources::new(), "t.xml", xml.as_bytes());
        let ee = p.devices[0].ethercat.as_ref().unwrap().eeprom.clone();
        (ee, p.diagnostics.iter().map(|d| format!("{} {}", d.code, d.message)).collect())
    }

    #[test]
    fn category_data_forms() {
        let (ee, diags) = eeprom(
            "<ByteSize>2048</ByteSize><ConfigData>0501</ConfigData>\
             <Category PreserveOnlineData=\"1\"><CatNo>1</CatNo><Data>0A0b</Data></Category>\
             <Category><CatNo>#x800</CatNo><DataString>ab</DataString></Category>\
             <Category><CatNo>2</CatNo><DataUINT>#x1234</DataUINT></Category>\
             <Category><CatNo>3</CatNo><DataUDINT>-1</DataUDINT></Category>",
        );
        assert!(diags.is_empty(), "{diags:?}");
        let ee = ee.unwrap();
        assert_eq!(ee.byte_size, Some(2048));
        assert_eq!(ee.config_data, [5, 1]);
        let cats: Vec<(u16, Vec<u8>, bool)> = ee
            .categories
            .iter()
            .map(|c| (c.cat_no, c.data.clone(), c.preserve_online_data))
            .collect();
        assert_eq!(
            cats,
            [
                (1, vec![0x0A, 0x0B], true),
                (0x800, b"ab".to_vec(), false),
                (2, vec![0x34, 0x12], false),
                (3, vec![0xFF; 4], false),
            ]
        );
        assert!(ee.spans.config_data.is_some() && ee.spans.boot_strap.is_none());
    }

    #[test]
    fn malformed_parts_are_reported() {
        let (ee, diags) = eeprom(
            "<ByteSize>2048</ByteSize><ConfigData>0G01</ConfigData><BootStrap>123</BootStrap>\
             <Category><Data>00</Data></Category><Category><CatNo>70000</CatNo><Data>00</Data></Category>",
        );
        let ee = ee.unwrap();
        assert!(ee.config_data.is_empty() && ee.boot_strap.is_empty());
        assert!(ee.categories.is_empty());
        assert_eq!(diags.iter().filter(|d| d.starts_with("F211")).count(), 2, "{diags:?}");
        assert!(diags.iter().any(|d| d.starts_with("F209") && d.contains("CatNo")), "{diags:?}");
        assert!(diags.iter().any(|d| d.starts_with("F218")), "{diags:?}");
    }
}
