//! One entry of a device file as a row of the runtime's [`TableBuilder`]: the entry's
//! [`RustTy`] picks the runtime type, and model values become values of that type by the rules
//! the generator uses for its `const` expressions (a limit or default that is no value of the
//! type is not used). The row's checks and initial value are then the runtime's own code.

use odc::slave::TableBuilder;
use odc::{DefaultValue, Entry, ObjValue, ObjectAddr};
use odc::{I24, I40, I48, I56, TimeDifference, TimeOfDay, U24, U40, U48, U56};
use odc_analysis::RustTy;
use odc_model::{SubObject, Value};

/// A model value as a value of a runtime type, by the generator's rules.
trait FromModel: Sized {
    fn from_model(v: &Value) -> Option<Self>;
    /// Whether `$NODEID`-relative defaults apply (integer types only).
    const NODE_RELATIVE: bool = false;
}

macro_rules! unsigned {
    ($($t:ty),*) => {$(
        impl FromModel for $t {
            const NODE_RELATIVE: bool = true;
            fn from_model(v: &Value) -> Option<Self> {
                match *v {
                    Value::Unsigned(u) => <$t as ObjValue>::from_u64(u),
                    Value::Signed(i) if i >= 0 => <$t as ObjValue>::from_u64(i.unsigned_abs()),
                    _ => None,
                }
            }
        }
    )*};
}
unsigned!(u8, u16, u32, u64, U24, U40, U48, U56);

/// The model's signed value, or an unsigned one that fits an `i64`.
fn signed_value(v: &Value) -> Option<i64> {
    match *v {
        Value::Signed(i) => Some(i),
        Value::Unsigned(u) => i64::try_from(u).ok(),
        _ => None,
    }
}

macro_rules! signed {
    ($($t:ty),*) => {$(
        impl FromModel for $t {
            const NODE_RELATIVE: bool = true;
            fn from_model(v: &Value) -> Option<Self> {
                <$t>::try_from(signed_value(v)?).ok()
            }
        }
    )*};
}
signed!(i8, i16, i32, i64);

macro_rules! odd_signed {
    ($($t:ty: $inner:ty),*) => {$(
        impl FromModel for $t {
            const NODE_RELATIVE: bool = true;
            fn from_model(v: &Value) -> Option<Self> {
                <$t>::new(<$inner>::try_from(signed_value(v)?).ok()?)
            }
        }
    )*};
}
odd_signed!(I24: i32, I40: i64, I48: i64, I56: i64);

impl FromModel for bool {
    fn from_model(v: &Value) -> Option<Self> {
        match *v {
            Value::Bool(b) => Some(b),
            Value::Unsigned(u @ (0 | 1)) => Some(u == 1),
            _ => None,
        }
    }
}

impl FromModel for f32 {
    fn from_model(v: &Value) -> Option<Self> {
        match *v {
            Value::Real32(b) => Some(f32::from_bits(b)),
            _ => None,
        }
    }
}

impl FromModel for f64 {
    fn from_model(v: &Value) -> Option<Self> {
        match *v {
            Value::Real64(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }
}

macro_rules! time {
    ($($t:ident),*) => {$(
        impl FromModel for $t {
            fn from_model(v: &Value) -> Option<Self> {
                match *v {
                    Value::Time { ms, days } => Some($t { ms, days }),
                    _ => None,
                }
            }
        }
    )*};
}
time!(TimeOfDay, TimeDifference);

/// The runtime's `Entry<T>` at `addr` with the file's limits, default and PDO mapping flag;
/// `words`: the controlword or statusword, whose defaults are never `$NODEID`-relative.
fn entry<T>(sub: &SubObject, addr: ObjectAddr, access: odc::Access, words: bool) -> Entry<T>
where
    T: ObjValue + FromModel + PartialOrd,
{
    let limit = |v: Option<&odc_model::Spanned<Value>>| v.and_then(|v| T::from_model(&v.value));
    let mappable = sub.pdo_mapping.is_mappable();
    let entry = Entry::new(addr.index, addr.sub, "", access, mappable)
        .with_limits(limit(sub.low_limit.as_deref()), limit(sub.high_limit.as_deref()));
    let default = sub.initial_value().and_then(|v| match v.value {
        Value::NodeIdPlus(off) if T::NODE_RELATIVE && !words => {
            u32::try_from(off).ok().map(DefaultValue::NodeIdPlus)
        }
        Value::NodeIdPlus(_) => None,
        ref other => T::from_model(other).map(DefaultValue::Value),
    });
    match default {
        Some(d) => entry.with_default(d),
        None => entry,
    }
}

/// `s` as a value of `VisibleString<cap>`, padded: at most `cap` bytes without NUL, the file's
/// text kept as `VisibleString::from_default` keeps it (tabs and UTF-8 too).
fn text_value(v: &Value, cap: usize) -> Option<Vec<u8>> {
    match v {
        Value::Text(s) if s.len() <= cap && !s.bytes().any(|b| b == 0) => {
            let mut padded = s.as_bytes().to_vec();
            padded.resize(cap, 0);
            Some(padded)
        }
        _ => None,
    }
}

/// `b` as a value of `OctetString<len>` (exactly `len` bytes).
fn octet_value(v: &Value, len: usize) -> Option<Vec<u8>> {
    match v {
        Value::Bytes(b) if b.len() == len => Some(b.to_vec()),
        _ => None,
    }
}

/// Adds `sub`, stored as `ty`, at `addr` with `access` to `table`.
pub fn push(
    table: &mut TableBuilder,
    addr: ObjectAddr,
    access: odc::Access,
    sub: &SubObject,
    ty: RustTy,
) {
    fn typed<T>(t: &mut TableBuilder, sub: &SubObject, addr: ObjectAddr, access: odc::Access)
    where
        T: ObjValue + FromModel + PartialOrd + Send + Sync + 'static,
    {
        t.push(&entry::<T>(sub, addr, access, false));
    }
    let (t, a, x) = (table, addr, access);
    let m = sub.pdo_mapping.is_mappable();
    let default = sub.initial_value().map(|v| &v.value);
    match ty {
        RustTy::Bool => typed::<bool>(t, sub, a, x),
        RustTy::Unsigned(8) => typed::<u8>(t, sub, a, x),
        // The controlword and statusword are UNSIGNED16 on the wire and order by that value.
        RustTy::Controlword | RustTy::Statusword => {
            t.push(&entry::<u16>(sub, a, x, true));
        }
        RustTy::Unsigned(16) => typed::<u16>(t, sub, a, x),
        RustTy::Unsigned(24) => typed::<U24>(t, sub, a, x),
        RustTy::Unsigned(32) => typed::<u32>(t, sub, a, x),
        RustTy::Unsigned(40) => typed::<U40>(t, sub, a, x),
        RustTy::Unsigned(48) => typed::<U48>(t, sub, a, x),
        RustTy::Unsigned(56) => typed::<U56>(t, sub, a, x),
        RustTy::Unsigned(_) => typed::<u64>(t, sub, a, x),
        RustTy::Signed(8) => typed::<i8>(t, sub, a, x),
        RustTy::Signed(16) => typed::<i16>(t, sub, a, x),
        RustTy::Signed(24) => typed::<I24>(t, sub, a, x),
        RustTy::Signed(32) => typed::<i32>(t, sub, a, x),
        RustTy::Signed(40) => typed::<I40>(t, sub, a, x),
        RustTy::Signed(48) => typed::<I48>(t, sub, a, x),
        RustTy::Signed(56) => typed::<I56>(t, sub, a, x),
        RustTy::Signed(_) => typed::<i64>(t, sub, a, x),
        RustTy::F32 => typed::<f32>(t, sub, a, x),
        RustTy::F64 => typed::<f64>(t, sub, a, x),
        RustTy::TimeOfDay => typed::<TimeOfDay>(t, sub, a, x),
        RustTy::TimeDifference => typed::<TimeDifference>(t, sub, a, x),
        RustTy::Text(cap) => {
            let v = |v: Option<&Value>| v.and_then(|v| text_value(v, cap));
            let (d, lo, hi) = (
                v(default),
                v(sub.low_limit.as_deref().map(|s| &s.value)),
                v(sub.high_limit.as_deref().map(|s| &s.value)),
            );
            t.push_text(a, x, m, cap, d.as_deref(), (lo.as_deref(), hi.as_deref()));
        }
        RustTy::Unicode(cap) => {
            let d: Option<Vec<u8>> = match default {
                Some(Value::Unicode(u)) => Some(u.iter().flat_map(|c| c.to_le_bytes()).collect()),
                _ => None,
            };
            t.push_unicode(a, x, m, cap, d.as_deref());
        }
        RustTy::Domain => {
            t.push_domain(a, x, m);
        }
        RustTy::Bytes(len) => {
            let v = |v: Option<&Value>| v.and_then(|v| octet_value(v, len));
            let (d, lo, hi) = (
                v(default),
                v(sub.low_limit.as_deref().map(|s| &s.value)),
                v(sub.high_limit.as_deref().map(|s| &s.value)),
            );
            t.push_octets(a, x, m, len, d.as_deref(), (lo.as_deref(), hi.as_deref()));
        }
    }
}
