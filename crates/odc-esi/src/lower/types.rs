//! Data types: the built-in ESI base types and a file's own `<DataType>`s, resolved by name.

use super::*;

/// A data type name resolved.
#[derive(Clone, Copy, Debug)]
pub(super) enum Resolved<'t> {
    /// A base type (possibly through `BaseType`), with the declared size if any.
    Simple(DataType, Option<u32>),
    /// A declared type with sub-items.
    Struct(Element<'t>, Option<u32>),
    /// A declared array type: element type, element bits, lower bound, element count.
    Array(DataType, Option<u32>, i64, u32),
}

/// The data types of one dictionary, by name.
#[derive(Default)]
pub(super) struct Types<'t> {
    by_name: HashMap<&'t str, Element<'t>>,
    /// Names already resolved: a dictionary names the same few types thousands of times, and
    /// resolving walks the type's element and its base types.
    resolved: RefCell<HashMap<&'t str, Option<Resolved<'t>>>>,
}

pub(super) fn builtin(name: &str) -> Option<DataType> {
    use DataType::*;
    let name = trim(name);
    // Upper-cased on the stack: called for every type name a dictionary mentions.
    let mut buf = [0u8; 32];
    let heap;
    let n = match buf.get_mut(..name.len()) {
        Some(b) => {
            b.copy_from_slice(name.as_bytes());
            b.make_ascii_uppercase();
            std::str::from_utf8(b).unwrap_or("")
        }
        None => {
            heap = name.to_ascii_uppercase();
            heap.as_str()
        }
    };
    Some(match n {
        "BOOL" | "BOOLEAN" => Boolean,
        "BIT" => Bit(1),
        "SINT" | "INT8" | "INTEGER8" => Integer8,
        "INT" | "INT16" | "INTEGER16" => Integer16,
        "INT24" | "INTEGER24" => Integer24,
        "DINT" | "INT32" | "INTEGER32" => Integer32,
        "INT40" | "INTEGER40" => Integer40,
        "INT48" | "INTEGER48" => Integer48,
        "INT56" | "INTEGER56" => Integer56,
        "LINT" | "INT64" | "INTEGER64" => Integer64,
        "USINT" | "BYTE" | "UINT8" | "UNSIGNED8" | "BITARR8" => Unsigned8,
        "UINT" | "WORD" | "UINT16" | "UNSIGNED16" | "BITARR16" => Unsigned16,
        "UINT24" | "UNSIGNED24" => Unsigned24,
        "UDINT" | "DWORD" | "UINT32" | "UNSIGNED32" | "BITARR32" => Unsigned32,
        "UINT40" | "UNSIGNED40" => Unsigned40,
        "UINT48" | "UNSIGNED48" => Unsigned48,
        "UINT56" | "UNSIGNED56" => Unsigned56,
        "ULINT" | "LWORD" | "UINT64" | "UNSIGNED64" => Unsigned64,
        "REAL" | "REAL32" | "FLOAT" => Real32,
        "LREAL" | "REAL64" | "DOUBLE" => Real64,
        "STRING" | "VISIBLE_STRING" => VisibleString,
        "OCTET_STRING" | "GUID" => OctetString,
        "UNICODE_STRING" | "WSTRING" => UnicodeString,
        "TIME_OF_DAY" => TimeOfDay,
        "TIME_DIFFERENCE" => TimeDifference,
        "DOMAIN" => Domain,
        _ => {
            if let Some(bits) = n.strip_prefix("BIT")
                && let Ok(b) = bits.parse::<u8>()
                && (1..=8).contains(&b)
            {
                return Some(Bit(b));
            }
            if n.starts_with("STRING(") || n.starts_with("VISIBLE_STRING(") {
                return Some(VisibleString);
            }
            if n.starts_with("OCTET_STRING(") {
                return Some(OctetString);
            }
            if n.starts_with("UNICODE_STRING(") || n.starts_with("WSTRING(") {
                return Some(UnicodeString);
            }
            if n.starts_with("ARRAY") && (n.ends_with("OF BYTE") || n.ends_with("OF USINT")) {
                return Some(OctetString);
            }
            return None;
        }
    })
}

/// The size in bits a type name says (`STRING(10)` → 80).
pub(super) fn builtin_bits(name: &str) -> Option<u32> {
    let n = trim(name);
    let open = n.find('(')?;
    let close = n.rfind(')')?;
    let count: u32 = n.get(open + 1..close)?.trim().parse().ok()?;
    Some(count.saturating_mul(8))
}

/// A plausible type for a field of `bits` with no declared type.
pub(super) fn type_for_bits(bits: u32) -> DataType {
    match bits {
        1 => DataType::Boolean,
        2..=7 => DataType::Bit(bits as u8),
        8 => DataType::Unsigned8,
        16 => DataType::Unsigned16,
        24 => DataType::Unsigned24,
        32 => DataType::Unsigned32,
        64 => DataType::Unsigned64,
        _ => DataType::OctetString,
    }
}

pub(super) fn collect_types<'t>(
    dict: Element<'t>,
    types: &mut Types<'t>,
    out: &mut Vec<EsiDataType>,
    ctx: &mut Ctx<'_>,
) {
    let Some(dts) = dict.child("DataTypes") else { return };
    // New declarations may change what a name resolves to.
    types.resolved.get_mut().clear();
    for dt in dts.children_named("DataType") {
        let [name, index, base_type, bit_size] = dt.pick(["Name", "Index", "BaseType", "BitSize"]);
        let Some(name) = name else {
            ctx.missing(dt, "Name");
            continue;
        };
        let name_text = name.text();
        if types.by_name.insert(name_text, dt).is_some() {
            // Same name declared twice (several profiles declare the base types): the later
            // declaration wins, the model lists each once.
            out.retain(|t| t.name != name_text);
        }
        let mut m = EsiDataType {
            name: name_text.into(),
            index: ctx.opt_u32(index, "Index"),
            base_type: base_type.map(|b| Name::from(b.text())),
            bit_size: ctx.opt_u32(bit_size, "BitSize"),
            span: dt.span(),
            ..EsiDataType::default()
        };
        for a in dt.children_named("ArrayInfo") {
            m.array_info.push(ArrayInfo {
                lbound: ctx.child_num(a, "LBound").unwrap_or(0),
                elements: ctx.child_u32(a, "Elements").unwrap_or(0),
            });
        }
        m.sub_items.reserve_exact(dt.children_named("SubItem").count());
        for s in dt.children_named("SubItem") {
            let [sub_idx, name, type_name, bit_size, bit_offset, flags] =
                s.pick(["SubIdx", "Name", "Type", "BitSize", "BitOffs", "Flags"]);
            let [access, pdo_mapping] =
                flags.map_or([None; 2], |f| f.pick(["Access", "PdoMapping"]));
            let text = |e: Option<Element<'_>>| e.map(|e| Name::from(e.text()));
            m.sub_items.push(EsiSubItem {
                sub_idx: ctx.opt_u32(sub_idx, "SubIdx"),
                name: text(name).unwrap_or_default(),
                type_name: text(type_name).unwrap_or_default(),
                bit_size: ctx.opt_u32(bit_size, "BitSize"),
                bit_offset: ctx.opt_u32(bit_offset, "BitOffs"),
                access: text(access),
                pdo_mapping: text(pdo_mapping),
            });
        }
        for e in dt.children_named("EnumInfo") {
            let text = e.child("Text").map(|t| t.text().to_string()).unwrap_or_default();
            if let Some(value) = e.child("Enum").and_then(|v| ctx.el_num::<i64>(v, "Enum")) {
                m.enum_info.push(EnumItem { text, value });
            }
        }
        out.push(m);
    }
}

impl<'t> Types<'t> {
    /// Resolves a type name; `None` when it is neither declared nor built in.
    /// A module's types: the file's, to which the module's own dictionary adds.
    pub(super) fn inherit(outer: &Types<'t>) -> Types<'t> {
        Types { by_name: outer.by_name.clone(), ..Types::default() }
    }

    pub(super) fn resolve(&self, name: &'t str) -> Option<Resolved<'t>> {
        if let Some(r) = self.resolved.borrow().get(name) {
            return *r;
        }
        let r = self.resolve_at(name, 0);
        self.resolved.borrow_mut().insert(name, r);
        r
    }

    fn resolve_at(&self, name: &str, depth: u32) -> Option<Resolved<'t>> {
        let name = trim(name);
        if depth > 16 {
            return None;
        }
        if let Some(&dt) = self.by_name.get(name) {
            let bits = dt.child("BitSize").and_then(|b| num::parse_int(b.text()));
            let bits = bits.and_then(|b| u32::try_from(b).ok());
            if dt.child("SubItem").is_some() {
                return Some(Resolved::Struct(dt, bits));
            }
            let base = dt.child("BaseType").map(|b| b.text());
            // `ARRAY [0..1] OF BYTE`, `STRING(10)`: declared with ArrayInfo, but one octet or
            // visible string sub-object, not an array of sub-objects.
            if let Some(b) = builtin(name) {
                return Some(Resolved::Simple(b, bits.or_else(|| builtin_bits(name))));
            }
            if let Some(ai) = dt.child("ArrayInfo") {
                let lbound = ai.child("LBound").and_then(|x| num::parse_int(x.text())).unwrap_or(0);
                let elements =
                    ai.child("Elements").and_then(|x| num::parse_int(x.text())).unwrap_or(0);
                let elements = u32::try_from(elements).unwrap_or(0);
                let (elem_ty, elem_bits) = match base.and_then(|b| self.resolve_at(b, depth + 1)) {
                    Some(Resolved::Simple(t, b)) => (t, b.or_else(|| t.bit_size())),
                    _ => {
                        let eb = bits.and_then(|b| b.checked_div(elements));
                        (eb.map(type_for_bits).unwrap_or(DataType::Unsigned8), eb)
                    }
                };
                return Some(Resolved::Array(elem_ty, elem_bits, lbound as i64, elements));
            }
            if let Some(base) = base
                && trim(base) != name
            {
                return match self.resolve_at(base, depth + 1)? {
                    Resolved::Simple(t, b) => Some(Resolved::Simple(t, bits.or(b))),
                    other => Some(other),
                };
            }
            // Enumerations and opaque types without a base type: guess from the size.
            return Some(Resolved::Simple(type_for_bits(bits.unwrap_or(8)), bits));
        }
        builtin(name).map(|t| Resolved::Simple(t, builtin_bits(name)))
    }
}
