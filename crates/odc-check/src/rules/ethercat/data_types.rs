//! Structured `<DataType>`s: their SubItems (T619, T620).

use super::*;

rule!(
    T619,
    "T619",
    "esi-subitem-duplicate",
    "etg",
    Warning,
    Warn,
    subitem_duplicate,
    "two SubItems of one dictionary DataType share a Name or a SubIdx",
    "The SubItems of a structured <DataType> are the sub-objects of every object of that type. \
     ETG.2000 makes SubItem/Name a key within its DataType: an object's <Info><SubItem> values \
     are matched to the type's SubItems by that name, so with two of one name the defaults go \
     to one of them at random (tools differ). Two SubItems with one SubIdx describe two \
     sub-objects at one sub-index. Fix: give each SubItem its own Name and SubIdx."
);

pub(super) fn subitem_duplicate(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for t in &ec.data_types {
        for (k, s) in t.sub_items.iter().enumerate() {
            let earlier = &t.sub_items[..k];
            let why = if !s.name.is_empty() && earlier.iter().any(|e| e.name == s.name) {
                format!("two SubItems are named `{}`", s.name)
            } else if let Some(i) =
                s.sub_idx.filter(|&i| earlier.iter().any(|e| e.sub_idx == Some(i)))
            {
                format!("two SubItems have SubIdx {i}")
            } else {
                continue;
            };
            ctx.report_device(t.span, format!("DataType `{}`: {why}", t.name));
        }
    }
}

rule!(
    T620,
    "T620",
    "esi-subitem-layout",
    "etg",
    Warning,
    Warn,
    subitem_layout,
    "a DataType's SubItems overlap or reach past its BitSize",
    "Each SubItem of a structured <DataType> occupies BitSize bits from BitOffs on; together \
     they make the object's CompleteAccess image (ETG.1000.6 SDO complete access) of the \
     type's BitSize bits. SubItems that overlap, or that end past the type's BitSize, describe \
     no possible image: a master reading or writing the object with CompleteAccess splits the \
     bytes differently from the device. Fix: correct BitOffs/BitSize of the SubItems or the \
     type's BitSize."
);

pub(super) fn subitem_layout(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for t in &ec.data_types {
        let mut items: Vec<(BitRange, &str)> = t
            .sub_items
            .iter()
            .filter_map(|s| Some((BitRange::new(s.bit_offset?, s.bit_size?), s.name.as_str())))
            .filter(|(range, _)| range.bits > 0)
            .collect();
        items.sort_by_key(|&(range, _)| range);
        let past = t.bit_size.and_then(|total| {
            items.iter().enumerate().find_map(|(i, &(range, name))| {
                odc_layout::check_limit(&range, i, total).err().map(|_| {
                    let (from, to) = (range.offset, range.end());
                    format!("SubItem `{name}` (bits {from}..{to}) ends past BitSize {total}")
                })
            })
        });
        let ranges: Vec<BitRange> = items.iter().map(|&(range, _)| range).collect();
        let overlap = odc_layout::find_overlap(&ranges).map(|(i, j)| {
            let ((a, a_name), (b, b_name)) = (items[i], items[j]);
            format!(
                "SubItems `{a_name}` (bits {}..{}) and `{b_name}` (from bit {}) overlap",
                a.offset,
                a.end(),
                b.offset
            )
        });
        if let Some(why) = past.or(overlap) {
            ctx.report_device(t.span, format!("DataType `{}`: {why}", t.name));
        }
    }
}
