//! C101–C105: the object lists (`[MandatoryObjects]`, `[OptionalObjects]`,
//! `[ManufacturerObjects]`) against the objects (CiA 306 §4.5.1).

use std::collections::BTreeMap;

use odc_model::{Device, ObjectList, Origin, Span, Spanned};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx};

/// The three lists with their names, those present.
fn lists(dev: &Device) -> impl Iterator<Item = (&'static str, &ObjectList)> {
    let l = &dev.object_lists;
    [
        ("MandatoryObjects", &l.mandatory),
        ("OptionalObjects", &l.optional),
        ("ManufacturerObjects", &l.manufacturer),
    ]
    .into_iter()
    .filter_map(|(name, list)| list.as_ref().map(|list| (name, list)))
}

rule!(
    C101,
    "C101",
    "listed-object-missing",
    "cia301",
    Warning,
    Warn,
    listed_object_missing,
    "an object list names an object the file does not define",
    "An entry of [MandatoryObjects], [OptionalObjects] or [ManufacturerObjects] names an index \
     for which the file has no object section. CiA 306 §4.5.1 says the lists enumerate the \
     objects the device implements, so a tool that trusts the list will expect an object that is \
     not described (and cannot know its type or access). Fix: add the object's section, or \
     remove the entry and renumber the list (and its SupportedObjects)."
);

fn listed_object_missing(dev: &Device, ctx: &mut Ctx) {
    for (name, list) in lists(dev) {
        for e in &list.entries {
            if !dev.objects.contains_key(&e.value) {
                ctx.report(
                    e.value,
                    None,
                    first_span([e.span, list.span]),
                    format!("[{name}] lists {} but the file has no such object", idx(e.value)),
                );
            }
        }
    }
}

rule!(
    C102,
    "C102",
    "object-not-listed",
    "cia301",
    Warning,
    Warn,
    object_not_listed,
    "an object is defined but not named in any object list",
    "The file defines an object section that none of the three object lists names. CiA 306 \
     §4.5.1 requires every object of the dictionary to be listed in exactly one of \
     [MandatoryObjects], [OptionalObjects] and [ManufacturerObjects]; tools that build the \
     dictionary from the lists (several do) will silently drop the object. Fix: add the index to \
     the list its range belongs to (0x1000/0x1001/0x1018: mandatory; 0x2000–0x5FFF: \
     manufacturer; others: optional) and update SupportedObjects. Only checked when the file has \
     object lists at all."
);

fn object_not_listed(dev: &Device, ctx: &mut Ctx) {
    if lists(dev).next().is_none() {
        return;
    }
    for o in dev.objects.values() {
        if o.origin != Origin::File {
            continue;
        }
        if !lists(dev).any(|(_, l)| l.entries.iter().any(|e| e.value == o.index)) {
            ctx.report(
                o.index,
                None,
                o.span,
                format!("object {} is not named in any object list", idx(o.index)),
            );
        }
    }
}

rule!(
    C103,
    "C103",
    "supported-objects-count",
    "cia301",
    Warning,
    Warn,
    supported_objects_count,
    "SupportedObjects disagrees with the entries of its object list",
    "Each object list starts with SupportedObjects=N followed by the entries 1=…, …, N=…. \
     CiA 306 §4.5.1 makes N the number of entries. When they disagree, readers that loop from 1 \
     to N miss objects or look for entries that are not there. Fix: set SupportedObjects to the \
     number of entries, or add the missing entries."
);

fn supported_objects_count(dev: &Device, ctx: &mut Ctx) {
    for (name, list) in lists(dev) {
        let n = list.entries.len();
        match &list.supported_objects {
            Some(Spanned { value, span }) if usize::from(*value) != n => {
                ctx.report_device(
                    *span,
                    format!(
                        "[{name}] SupportedObjects={value} but the list has {n} entr{}",
                        if n == 1 { "y" } else { "ies" }
                    ),
                );
            }
            None => {
                ctx.report_device(list.span, format!("[{name}] has no SupportedObjects"));
            }
            _ => {}
        }
    }
}

rule!(
    C104,
    "C104",
    "object-in-wrong-list",
    "cia301",
    Warning,
    Warn,
    object_in_wrong_list,
    "an object is listed in the object list of another index range",
    "CiA 306 §4.5.1 sorts objects into lists by index: [MandatoryObjects] holds exactly \
     0x1000, 0x1001 and 0x1018; [ManufacturerObjects] holds the manufacturer range \
     0x2000–0x5FFF; [OptionalObjects] holds everything else from 0x1000 up (communication \
     profile, device profile 0x6000–0x9FFF, 0xA000–0xFFFF). Indexes below 0x1000 are data \
     types and belong in no list. Tools that pick the list by range disagree with a file that \
     does not. Fix: move the entry to the right list and renumber both lists."
);

fn object_in_wrong_list(dev: &Device, ctx: &mut Ctx) {
    for (name, list) in lists(dev) {
        for e in &list.entries {
            let i = e.value;
            let right = if i < 0x1000 {
                None
            } else if matches!(i, 0x1000 | 0x1001 | 0x1018) {
                Some("MandatoryObjects")
            } else if (0x2000..=0x5FFF).contains(&i) {
                Some("ManufacturerObjects")
            } else {
                Some("OptionalObjects")
            };
            match right {
                None => {
                    ctx.report(
                        i,
                        None,
                        first_span([e.span, list.span]),
                        format!("[{name}] lists {}, a data-type index (below 0x1000)", idx(i)),
                    );
                }
                Some(right) if right != name => {
                    ctx.report(
                        i,
                        None,
                        first_span([e.span, list.span]),
                        format!("[{name}] lists {}, which belongs in [{right}]", idx(i)),
                    );
                }
                _ => {}
            }
        }
    }
}

rule!(
    C105,
    "C105",
    "object-listed-twice",
    "cia301",
    Warning,
    Warn,
    object_listed_twice,
    "an object is named twice in the object lists",
    "An index appears twice in one object list, or in two lists. CiA 306 §4.5.1 lists each \
     object once; a duplicate makes SupportedObjects count one object twice and may make tools \
     create the object twice. Fix: remove the extra entry and renumber the list."
);

fn object_listed_twice(dev: &Device, ctx: &mut Ctx) {
    let mut first: BTreeMap<u16, (&str, Span)> = BTreeMap::new();
    for (name, list) in lists(dev) {
        for e in &list.entries {
            match first.get(&e.value) {
                Some(&(first_name, first_span_)) => {
                    ctx.report(
                        e.value,
                        None,
                        first_span([e.span, list.span]),
                        format!("{} is listed again in [{name}]", idx(e.value)),
                    )
                    .labels
                    .push(odc_model::Label {
                        span: first_span_,
                        message: format!("first listed in [{first_name}]"),
                        primary: false,
                    });
                }
                None => {
                    first.insert(e.value, (name, e.span));
                }
            }
        }
    }
}
