//! The typed work of one entry of a [`ModelDictionary`](crate::ModelDictionary): what the
//! generated table's `Spec<T>` does at compile time, chosen at run time from the entry's
//! [`RustTy`]. Model values become values of the entry's type by the rules the generator uses
//! for its `const` expressions: a limit or default that is no value of the type is not used.

use odc::cob::NodeId;
use odc::{DataType, DefaultValue, Entry, ObjValue, SdoAbort, ValueError};
use odc::{I24, I40, I48, I56, TimeDifference, TimeOfDay, U24, U40, U48, U56};
use odc_analysis::RustTy;
use odc_model::{SubObject, Value};

/// What the read and write paths need of an entry's type.
pub trait Slot: Send + Sync {
    /// Decodes `data` as a value of the type and checks it against the limits.
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort>;
    /// The initial value on node `node_id`, encoded into `stored` (zeroed, [`Slot::len`]).
    fn init(&self, stored: &mut [u8], node_id: Option<NodeId>);
    /// The bytes the value takes in the storage.
    fn len(&self) -> usize;
    /// The CiA 301 data type.
    fn data_type(&self) -> DataType;
    /// A DOMAIN's initial data (the file's default), kept apart from the fixed-size values.
    fn domain_default(&self) -> Option<&[u8]> {
        None
    }
}

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

/// An entry of a fixed-size type: the runtime's own `Entry<T>` with the file's limits and
/// default, so checks and initial values are the runtime's code.
struct Typed<T: 'static>(Entry<T>);

impl<T> Typed<T>
where
    T: ObjValue + FromModel + PartialOrd,
{
    /// `words`: the controlword or statusword, whose defaults are never `$NODEID`-relative.
    fn new(sub: &SubObject, words: bool) -> Self {
        let limit = |v: Option<&odc_model::Spanned<Value>>| v.and_then(|v| T::from_model(&v.value));
        let entry = Entry::new(0, 0, "", odc::Access::Rw, false)
            .with_limits(limit(sub.low_limit.as_deref()), limit(sub.high_limit.as_deref()));
        let default = sub.initial_value().and_then(|v| match v.value {
            Value::NodeIdPlus(off) if T::NODE_RELATIVE && !words => {
                u32::try_from(off).ok().map(DefaultValue::NodeIdPlus)
            }
            Value::NodeIdPlus(_) => None,
            ref other => T::from_model(other).map(DefaultValue::Value),
        });
        Typed(match default {
            Some(d) => entry.with_default(d),
            None => entry,
        })
    }
}

impl<T> Slot for Typed<T>
where
    T: ObjValue + FromModel + PartialOrd + Send + Sync,
{
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        self.0.decode_download(data).map(|_| ())
    }

    fn init(&self, stored: &mut [u8], node_id: Option<NodeId>) {
        if let Ok(zero) = T::decode(stored) {
            let _ = odc::slave::initial(&self.0, node_id, zero).encode(stored);
        }
    }

    fn len(&self) -> usize {
        T::MAX_LEN
    }

    fn data_type(&self) -> DataType {
        T::DATA_TYPE
    }
}

/// A VISIBLE_STRING of at most `cap` bytes (`VisibleString<N>` with `N` known at run time).
/// Limits compare as `VisibleString<N>` orders: the bytes zero-padded to the capacity.
struct Text {
    cap: usize,
    default: Option<Box<[u8]>>,
    low: Option<Vec<u8>>,
    high: Option<Vec<u8>>,
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

impl Slot for Text {
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        // As `VisibleString::<N>::decode`: zeros at the end pad, the rest is visible ASCII.
        let end = data.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1);
        let text = data.get(..end).ok_or(SdoAbort::InvalidValue)?;
        if core::str::from_utf8(text).is_err() {
            return Err(ValueError::Invalid.into());
        }
        if text.len() > self.cap {
            return Err(ValueError::TooLong.into());
        }
        if !text.iter().all(|b| (0x20..=0x7E).contains(b)) {
            return Err(ValueError::Invalid.into());
        }
        let mut padded = text.to_vec();
        padded.resize(self.cap, 0);
        odc::check_range(&padded, self.low.as_ref(), self.high.as_ref())
    }

    fn init(&self, stored: &mut [u8], _: Option<NodeId>) {
        if let Some(d) = &self.default {
            for (s, d) in stored.iter_mut().zip(d.iter()) {
                *s = *d;
            }
        }
    }

    fn len(&self) -> usize {
        self.cap
    }

    fn data_type(&self) -> DataType {
        DataType::VisibleString
    }
}

/// An OCTET_STRING of exactly `len` bytes (`OctetString<N>`); limits compare bytewise.
struct Octets {
    len: usize,
    default: Option<Box<[u8]>>,
    low: Option<Vec<u8>>,
    high: Option<Vec<u8>>,
}

impl Slot for Octets {
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        match data.len() {
            n if n < self.len => Err(ValueError::TooShort.into()),
            n if n > self.len => Err(ValueError::TooLong.into()),
            _ => odc::check_range(&data.to_vec(), self.low.as_ref(), self.high.as_ref()),
        }
    }

    fn init(&self, stored: &mut [u8], _: Option<NodeId>) {
        if let Some(d) = &self.default {
            for (s, d) in stored.iter_mut().zip(d.iter()) {
                *s = *d;
            }
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn data_type(&self) -> DataType {
        DataType::OctetString
    }
}

/// The slot of `sub` stored as `ty`.
pub fn slot(sub: &SubObject, ty: RustTy) -> Box<dyn Slot> {
    fn typed<T>(sub: &SubObject) -> Box<dyn Slot>
    where
        T: ObjValue + FromModel + PartialOrd + Send + Sync + 'static,
    {
        Box::new(Typed::<T>::new(sub, false))
    }
    let default = sub.initial_value().map(|v| &v.value);
    match ty {
        RustTy::Bool => typed::<bool>(sub),
        RustTy::Unsigned(8) => typed::<u8>(sub),
        // The controlword and statusword are UNSIGNED16 on the wire and order by that value.
        RustTy::Controlword | RustTy::Statusword => Box::new(Typed::<u16>::new(sub, true)),
        RustTy::Unsigned(16) => typed::<u16>(sub),
        RustTy::Unsigned(24) => typed::<U24>(sub),
        RustTy::Unsigned(32) => typed::<u32>(sub),
        RustTy::Unsigned(40) => typed::<U40>(sub),
        RustTy::Unsigned(48) => typed::<U48>(sub),
        RustTy::Unsigned(56) => typed::<U56>(sub),
        RustTy::Unsigned(_) => typed::<u64>(sub),
        RustTy::Signed(8) => typed::<i8>(sub),
        RustTy::Signed(16) => typed::<i16>(sub),
        RustTy::Signed(24) => typed::<I24>(sub),
        RustTy::Signed(32) => typed::<i32>(sub),
        RustTy::Signed(40) => typed::<I40>(sub),
        RustTy::Signed(48) => typed::<I48>(sub),
        RustTy::Signed(56) => typed::<I56>(sub),
        RustTy::Signed(_) => typed::<i64>(sub),
        RustTy::F32 => typed::<f32>(sub),
        RustTy::F64 => typed::<f64>(sub),
        RustTy::TimeOfDay => typed::<TimeOfDay>(sub),
        RustTy::TimeDifference => typed::<TimeDifference>(sub),
        RustTy::Text(cap) => {
            let limit = |v: Option<&odc_model::Spanned<Value>>| text_value(&v?.value, cap);
            Box::new(Text {
                cap,
                default: default.and_then(|v| text_value(v, cap)).map(Into::into),
                low: limit(sub.low_limit.as_deref()),
                high: limit(sub.high_limit.as_deref()),
            })
        }
        RustTy::Unicode(cap) => {
            let default = match default {
                Some(Value::Unicode(u)) if u.len() * 2 <= cap => {
                    Some(u.iter().flat_map(|c| c.to_le_bytes()).collect())
                }
                _ => None,
            };
            Box::new(Unicode { cap, default })
        }
        RustTy::Domain => Box::new(DomainSlot {
            default: default.and_then(|v| odc_model::wire::encode(v, odc_model::DataType::Domain)),
        }),
        RustTy::Bytes(len) => {
            let limit = |v: Option<&odc_model::Spanned<Value>>| octet_value(&v?.value, len);
            Box::new(Octets {
                len,
                default: default.and_then(|v| octet_value(v, len)).map(Into::into),
                low: limit(sub.low_limit.as_deref()),
                high: limit(sub.high_limit.as_deref()),
            })
        }
    }
}

/// UNICODE_STRING of at most `cap` bytes, as the runtime's `UnicodeString<N>`.
struct Unicode {
    cap: usize,
    default: Option<Vec<u8>>,
}

impl Slot for Unicode {
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        // As `UnicodeString::<N>::decode`: whole code units, zero units at the end pad.
        if data.len() & 1 != 0 {
            return Err(ValueError::Invalid.into());
        }
        let mut end = data.len();
        while end >= 2 && data.get(end - 2..end) == Some(&[0, 0]) {
            end -= 2;
        }
        if end > self.cap {
            return Err(ValueError::TooLong.into());
        }
        Ok(())
    }

    fn init(&self, stored: &mut [u8], _: Option<NodeId>) {
        if let Some(d) = &self.default {
            for (s, d) in stored.iter_mut().zip(d.iter()) {
                *s = *d;
            }
        }
    }

    fn len(&self) -> usize {
        self.cap
    }

    fn data_type(&self) -> DataType {
        DataType::UnicodeString
    }
}

/// DOMAIN: any bytes; the dictionary keeps them apart from the fixed-size values, the file's
/// default (CiA 306 hex bytes) as the data after a reset.
struct DomainSlot {
    default: Option<Vec<u8>>,
}

impl Slot for DomainSlot {
    fn check(&self, _: &[u8]) -> Result<(), SdoAbort> {
        Ok(())
    }

    fn init(&self, _: &mut [u8], _: Option<NodeId>) {}

    fn len(&self) -> usize {
        0
    }

    fn data_type(&self) -> DataType {
        DataType::Domain
    }

    fn domain_default(&self) -> Option<&[u8]> {
        self.default.as_deref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use odc::{Entry, OctetString, VisibleString};
    use odc_model::{Access, DataType, Span, Spanned};

    fn spanned(v: Value) -> Option<Box<Spanned<Value>>> {
        Some(Box::new(Spanned::new(v, Span::DUMMY)))
    }

    /// A VISIBLE_STRING default with a tab and '€' (as canopensocket's basicDevice.eds
    /// 0x2120:07 has) is the dictionary's value after reset, byte for byte, as
    /// `VisibleString::from_default` keeps it in generated code; a master's write of the same
    /// text is refused, as `VisibleString::decode` refuses it.
    #[test]
    fn a_string_default_with_a_tab_and_utf8_is_kept() {
        let text = "tab '\t', euro '\u{20AC}'";
        let mut sub = SubObject::new(0, "String", DataType::VisibleString, Access::Rw);
        sub.default = Some(Spanned::new(Value::Text(text.into()), Span::DUMMY));
        let ours = slot(&sub, RustTy::Text(32));
        let mut stored = [0u8; 32];
        ours.init(&mut stored, None);
        assert_eq!(&stored[..text.len()], text.as_bytes());
        assert!(stored[text.len()..].iter().all(|&b| b == 0));
        let theirs = odc::VisibleString::<32>::from_default(text).unwrap();
        let mut buf = [0u8; 32];
        assert_eq!(theirs.encode(&mut buf), Ok(text.len()));
        assert_eq!(buf, stored);
        let want = VisibleString::<32>::decode(text.as_bytes()).map(|_| ());
        assert_eq!(ours.check(text.as_bytes()), want.map_err(SdoAbort::from));
        assert!(want.is_err());
    }

    /// String and octet limits behave as the runtime's `VisibleString<N>`/`OctetString<N>`
    /// descriptors with the same limits (no device file of eds/ has any, so the differential
    /// test does not reach them).
    #[test]
    fn string_limits_as_the_runtime_types() {
        let mut sub = SubObject::new(0, "Name", DataType::VisibleString, Access::Rw);
        sub.low_limit = spanned(Value::Text("B".into()));
        sub.high_limit = spanned(Value::Text("M".into()));
        let ours = slot(&sub, RustTy::Text(4));
        let theirs = Entry::<VisibleString<4>>::new(0x2000, 0, "Name", odc::Access::Rw, false)
            .with_limits(VisibleString::new("B"), VisibleString::new("M"));
        for data in [&b"A"[..], b"B", b"BA", b"M", b"MA", b"Z", b"", b"ABCDE", b"C\0\0", b"\x01"] {
            let want = theirs.decode_download(data).map(|_| ());
            assert_eq!(ours.check(data), want, "{data:?}");
        }
        let mut sub = SubObject::new(0, "Key", DataType::OctetString, Access::Rw);
        sub.low_limit = spanned(Value::Bytes(vec![0x10, 0x00].into()));
        sub.high_limit = spanned(Value::Bytes(vec![0x20, 0xFF].into()));
        let ours = slot(&sub, RustTy::Bytes(2));
        let theirs = Entry::<OctetString<2>>::new(0x2001, 0, "Key", odc::Access::Rw, false)
            .with_limits(Some(OctetString([0x10, 0x00])), Some(OctetString([0x20, 0xFF])));
        for data in
            [&[0x0F, 0xFF][..], &[0x10, 0x00], &[0x20, 0xFF], &[0x21, 0x00], &[0x15], &[1, 2, 3]]
        {
            let want = theirs.decode_download(data).map(|_| ());
            assert_eq!(ours.check(data), want, "{data:02X?}");
        }
    }
}
