//! The initial storage image of the slave dictionary: every entry's initial value in its SDO
//! encoding, laid out as `odc::slave::Table` lays the values out (row after row, each its
//! type's encoded size). What `Table::init` would compute at run time, worked out here, so
//! that a firmware copies bytes instead of linking a typed initial value per value type.
//!
//! An integer entry with a `$NODEID` default holds its value without node-ID in the image (the
//! default taken as absent) and is listed in [`Image::node_id`], for `odc::slave::NodeIdDefault`
//! to write the sum over it. Made only when every entry's initial value is one this module can
//! order and encode; otherwise the dictionary initialises itself at run time as before.

use std::cmp::Ordering;

use odc_model::{SubObject, Value};

use crate::Ctx;
use crate::types::RustTy;

/// The initial values of a slave dictionary.
pub struct Image {
    /// The values, in `ctx.names.entries` (row) order, each its type's encoded size.
    pub bytes: Vec<u8>,
    /// The `$NODEID` defaults: where each value is in `bytes`, its length, whether it is
    /// signed, the offset added to the node-ID.
    pub node_id: Vec<(usize, usize, bool, u32)>,
}

/// The largest image written: a dictionary with more values than this is no firmware's (and
/// its literal would be megabytes of source); it initialises itself at run time.
const MAX_IMAGE: usize = 64 * 1024;

/// The image of the slave dictionary's values, or `None` when the run-time initialisation
/// must stay (see the module).
pub fn initial_image(ctx: &Ctx<'_>) -> Option<Image> {
    // A device file can declare a string of any size (a malformed one, gigabytes): measure
    // before anything is allocated.
    let size = ctx.names.entries.values().try_fold(0usize, |n, e| n.checked_add(storage_len(e.ty)));
    if size.is_none_or(|n| n > MAX_IMAGE) {
        return None;
    }
    let mut image = Image { bytes: Vec::new(), node_id: Vec::new() };
    for (&(index, sub), name) in &ctx.names.entries {
        let sub = ctx.device.objects.get(&index)?.subs.get(&sub)?;
        if let Some(offset) = node_id_offset(name.ty, sub) {
            let signed = matches!(name.ty, RustTy::Signed(_));
            image.node_id.push((image.bytes.len(), storage_len(name.ty), signed, offset));
        }
        image.bytes.extend(initial(name.ty, sub)?);
    }
    Some(image)
}

/// The offset of an integer entry's `$NODEID + offset` default, as the generated descriptor
/// keeps it (`DefaultValue::NodeIdPlus`); `None` for any other default.
fn node_id_offset(ty: RustTy, sub: &SubObject) -> Option<u32> {
    match (ty, &sub.initial_value()?.value) {
        (RustTy::Unsigned(_) | RustTy::Signed(_), Value::NodeIdPlus(off)) => {
            u32::try_from(*off).ok()
        }
        _ => None,
    }
}

/// The bytes a value of `ty` takes in the storage (`ObjValue::MAX_LEN` of the Rust type the
/// generator writes for it).
fn storage_len(ty: RustTy) -> usize {
    match ty {
        RustTy::Bool => 1,
        RustTy::Unsigned(bits) | RustTy::Signed(bits) => match bits {
            8 => 1,
            16 => 2,
            24 => 3,
            32 => 4,
            40 => 5,
            48 => 6,
            64 => 8,
            // `U56`/`I56`, as `RustTyTokens::tokens` names every other width.
            _ => 7,
        },
        RustTy::F32 => 4,
        RustTy::F64 => 8,
        RustTy::Text(n) | RustTy::Bytes(n) | RustTy::Unicode(n) => n,
        RustTy::Domain => 0,
        RustTy::TimeOfDay | RustTy::TimeDifference => 6,
        RustTy::Controlword | RustTy::Statusword => 2,
    }
}

/// The stored initial value of an entry of type `ty` on a node without node-ID: its default
/// (a `$NODEID` one taken as absent), else zero moved into its limits
/// (`odc::slave::initial`); `None` for limits of a type this module does not order.
fn initial(ty: RustTy, sub: &SubObject) -> Option<Vec<u8>> {
    let len = storage_len(ty);
    let padded = |mut b: Vec<u8>| {
        b.resize(len, 0);
        b
    };
    if let Some(d) = sub.initial_value() {
        // A default that is no value of the type is not used (as the generated descriptor
        // leaves it out); nor is `$NODEID + offset` without a node-ID (`encode` takes none).
        if let Some(b) = encode(ty, &d.value) {
            return Some(padded(b));
        }
    }
    // Limits that are no value of the type are not checked, and not used here either.
    let (low, high) = (limit(ty, sub.low_limit.as_deref()), limit(ty, sub.high_limit.as_deref()));
    if low.is_none() && high.is_none() {
        return Some(vec![0; len]);
    }
    if let Some((lo, bytes)) = low
        && zero_against(ty, lo)? == Some(Ordering::Less)
    {
        return Some(padded(bytes));
    }
    if let Some((hi, bytes)) = high
        && zero_against(ty, hi)? == Some(Ordering::Greater)
    {
        return Some(padded(bytes));
    }
    Some(vec![0; len])
}

/// A limit and its encoding, when it is a value of `ty`.
fn limit(ty: RustTy, v: Option<&odc_model::Spanned<Value>>) -> Option<(&Value, Vec<u8>)> {
    let v = &v?.value;
    Some((v, encode(ty, v)?))
}

/// How the zero of `ty` orders against `v` (a value of the type): `Some(None)` when they
/// have no order (NaN), `None` for a type this module does not order.
fn zero_against(ty: RustTy, v: &Value) -> Option<Option<Ordering>> {
    Some(match (ty, v) {
        (RustTy::Bool, Value::Bool(b)) => Some(false.cmp(b)),
        (RustTy::Bool, Value::Unsigned(u)) => Some(0.cmp(u)),
        (RustTy::Unsigned(_), Value::Unsigned(u)) => Some(0.cmp(u)),
        (RustTy::Unsigned(_), Value::Signed(i)) | (RustTy::Signed(_), Value::Signed(i)) => {
            Some(0.cmp(i))
        }
        (RustTy::Signed(_), Value::Unsigned(u)) => Some(0.cmp(u)),
        (RustTy::F32, Value::Real32(b)) => 0f32.partial_cmp(&f32::from_bits(*b)),
        (RustTy::F64, Value::Real64(b)) => 0f64.partial_cmp(&f64::from_bits(*b)),
        _ => return None,
    })
}

/// The SDO encoding of `value` as a value of `ty`, or `None` when it is none (it does not
/// fit, or has another kind): the values the generator's `const` expressions accept
/// (`types::value_expr`), encoded as their `ObjValue::encode` does.
fn encode(ty: RustTy, value: &Value) -> Option<Vec<u8>> {
    let len = storage_len(ty);
    Some(match (ty, value) {
        (RustTy::Bool, Value::Bool(b)) => vec![u8::from(*b)],
        (RustTy::Bool, Value::Unsigned(u @ (0 | 1))) => vec![*u as u8],
        (RustTy::Unsigned(bits), Value::Unsigned(u)) => {
            if bits < 64 && *u >> bits != 0 {
                return None;
            }
            u.to_le_bytes().get(..len)?.to_vec()
        }
        (RustTy::Unsigned(_), Value::Signed(i)) if *i >= 0 => {
            return encode(ty, &Value::Unsigned(i.unsigned_abs()));
        }
        (RustTy::Signed(bits), Value::Signed(i)) => {
            let (min, max) = (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1);
            if i128::from(*i) < min || i128::from(*i) > max {
                return None;
            }
            i.to_le_bytes().get(..len)?.to_vec()
        }
        (RustTy::Signed(_), Value::Unsigned(u)) => {
            return encode(ty, &Value::Signed(i64::try_from(*u).ok()?));
        }
        (RustTy::F32, Value::Real32(b)) => b.to_le_bytes().to_vec(),
        (RustTy::F64, Value::Real64(b)) => b.to_le_bytes().to_vec(),
        // As `VisibleString::from_default`: the file's text kept, tabs and UTF-8 too.
        (RustTy::Text(n), Value::Text(s)) if s.len() <= n && !s.bytes().any(|b| b == 0) => {
            s.as_bytes().to_vec()
        }
        (RustTy::Bytes(n), Value::Bytes(b)) if b.len() == n => b.to_vec(),
        (RustTy::Unicode(n), Value::Unicode(units)) if units.len() * 2 <= n => {
            units.iter().flat_map(|u| u.to_le_bytes()).collect()
        }
        (RustTy::Controlword | RustTy::Statusword, Value::Unsigned(u)) => {
            u16::try_from(*u).ok()?.to_le_bytes().to_vec()
        }
        (RustTy::Controlword | RustTy::Statusword, Value::Signed(i)) if *i >= 0 => {
            return encode(ty, &Value::Unsigned(i.unsigned_abs()));
        }
        // A time whose milliseconds do not fit 28 bits is a value of the type that
        // `encode` refuses: the storage keeps its zeros.
        (RustTy::TimeOfDay | RustTy::TimeDifference, Value::Time { ms, days }) => {
            if ms >> 28 != 0 {
                vec![0; 6]
            } else {
                let mut b = ms.to_le_bytes().to_vec();
                b.extend_from_slice(&days.to_le_bytes());
                b
            }
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use odc_model::{Access, DataType, Span, Spanned};

    fn sub(
        dt: DataType,
        default: Option<Value>,
        low: Option<Value>,
        high: Option<Value>,
    ) -> SubObject {
        let mut s = SubObject::new(0, "x", dt, Access::Rw);
        let spanned = |v: Option<Value>| v.map(|v| Box::new(Spanned::new(v, Span::DUMMY)));
        s.default = default.map(|v| Spanned::new(v, Span::DUMMY));
        s.low_limit = spanned(low);
        s.high_limit = spanned(high);
        s
    }

    #[test]
    fn defaults_are_encoded_little_endian_and_padded() {
        let u32t = RustTy::Unsigned(32);
        let s = sub(DataType::Unsigned32, Some(Value::Unsigned(0x1234_5678)), None, None);
        assert_eq!(initial(u32t, &s), Some(vec![0x78, 0x56, 0x34, 0x12]));
        let s = sub(DataType::Integer24, Some(Value::Signed(-2)), None, None);
        assert_eq!(initial(RustTy::Signed(24), &s), Some(vec![0xFE, 0xFF, 0xFF]));
        let s = sub(DataType::VisibleString, Some(Value::Text("ab".into())), None, None);
        assert_eq!(initial(RustTy::Text(4), &s), Some(vec![b'a', b'b', 0, 0]));
        let s = sub(DataType::Real32, Some(Value::Real32(0x3FC0_0000)), None, None);
        assert_eq!(initial(RustTy::F32, &s), Some(vec![0, 0, 0xC0, 0x3F]));
        let time = Value::Time { ms: 0x0102_0304, days: 0x0506 };
        let s = sub(DataType::TimeOfDay, Some(time), None, None);
        assert_eq!(initial(RustTy::TimeOfDay, &s), Some(vec![4, 3, 2, 1, 6, 5]));
    }

    #[test]
    fn without_default_zero_moves_into_the_limits() {
        let u8t = RustTy::Unsigned(8);
        let s = sub(DataType::Unsigned8, None, Some(Value::Unsigned(3)), Some(Value::Unsigned(9)));
        assert_eq!(initial(u8t, &s), Some(vec![3]));
        let i16t = RustTy::Signed(16);
        let s = sub(DataType::Integer16, None, Some(Value::Signed(-9)), Some(Value::Signed(-3)));
        assert_eq!(initial(i16t, &s), Some(vec![0xFD, 0xFF]));
        let s = sub(DataType::Integer16, None, Some(Value::Signed(-9)), Some(Value::Signed(9)));
        assert_eq!(initial(i16t, &s), Some(vec![0, 0]));
        // A default that does not fit the type is not used: the limits decide.
        let s =
            sub(DataType::Unsigned8, Some(Value::Unsigned(300)), Some(Value::Unsigned(7)), None);
        assert_eq!(initial(u8t, &s), Some(vec![7]));
    }

    #[test]
    fn node_id_defaults_are_listed_over_their_value_without_node_id() {
        // Without node-ID, the default is absent: zero, or the limit nearest to it.
        let s = sub(DataType::Unsigned32, Some(Value::NodeIdPlus(0x180)), None, None);
        assert_eq!(initial(RustTy::Unsigned(32), &s), Some(vec![0; 4]));
        assert_eq!(node_id_offset(RustTy::Unsigned(32), &s), Some(0x180));
        let lo = Some(Value::Unsigned(0x81));
        let s = sub(DataType::Unsigned16, Some(Value::NodeIdPlus(0x80)), lo, None);
        assert_eq!(initial(RustTy::Unsigned(16), &s), Some(vec![0x81, 0]));
        // Not an integer: the descriptor has no default, so no `$NODEID` to apply.
        let s = sub(DataType::Real32, Some(Value::NodeIdPlus(1)), None, None);
        assert_eq!(node_id_offset(RustTy::F32, &s), None);
        assert_eq!(initial(RustTy::F32, &s), Some(vec![0; 4]));
    }

    #[test]
    fn what_the_run_time_initialisation_keeps() {
        // A string with limits: not ordered here.
        let lo = Some(Value::Text("b".into()));
        let s = sub(DataType::VisibleString, None, lo, None);
        assert_eq!(initial(RustTy::Text(2), &s), None);
    }
}
