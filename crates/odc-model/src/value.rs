//! Values of sub-objects: defaults, limits, parameter values.

use serde::Serialize;

/// A value typed by the data type of the sub-object that holds it.
///
/// `$NODEID` stays symbolic ([`Value::NodeIdPlus`]) until a node-ID is known (a DCF's
/// commissioning data, or run time). Reals are kept as bit patterns so that the model has a total
/// equality and a value read as a hex pattern writes back to the same bits.
///
/// The variants that own text or bytes hold boxed slices, not `String`/`Vec`: a value is never
/// grown after it is read, and without the capacity word the enum is 24 bytes instead of 32.
/// A sub-object holds four optional values, and a CANopen master's DCF implies thousands of
/// sub-objects, so those bytes are moved and dropped often enough to show in parse time.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Value {
    /// BOOLEAN, BITn.
    Bool(bool),
    /// UNSIGNEDn.
    Unsigned(u64),
    /// INTEGERn.
    Signed(i64),
    /// REAL32, as its IEEE 754 bit pattern.
    Real32(u32),
    /// REAL64, as its IEEE 754 bit pattern.
    Real64(u64),
    /// VISIBLE_STRING.
    Text(Box<str>),
    /// OCTET_STRING, DOMAIN.
    Bytes(Box<[u8]>),
    /// UNICODE_STRING as UTF-16 code units.
    Unicode(Box<[u16]>),
    /// TIME_OF_DAY / TIME_DIFFERENCE: milliseconds after midnight, days since 1984-01-01.
    Time {
        /// Milliseconds (28 bits used).
        ms: u32,
        /// Days.
        days: u16,
    },
    /// `$NODEID + offset`: resolved once the node-ID is known.
    NodeIdPlus(i64),
    /// Text that does not read as a value of the type. A diagnostic said so; the text is kept so
    /// that nothing is lost when the file is written back.
    Invalid(Box<str>),
}

impl Value {
    /// The value as an integer (for comparisons), with `$NODEID` taken as `node_id`.
    pub fn as_i128(&self, node_id: u8) -> Option<i128> {
        match *self {
            Value::Bool(b) => Some(i128::from(b)),
            Value::Unsigned(u) => Some(i128::from(u)),
            Value::Signed(i) => Some(i128::from(i)),
            Value::NodeIdPlus(n) => Some(i128::from(n) + i128::from(node_id)),
            _ => None,
        }
    }

    /// The value as an unsigned integer, if it is one (`$NODEID` excluded).
    pub fn as_u64(&self) -> Option<u64> {
        match *self {
            Value::Unsigned(u) => Some(u),
            Value::Signed(i) => u64::try_from(i).ok(),
            Value::Bool(b) => Some(u64::from(b)),
            _ => None,
        }
    }

    /// The value as a float, for REAL types.
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::Real32(bits) => Some(f64::from(f32::from_bits(bits))),
            Value::Real64(bits) => Some(f64::from_bits(bits)),
            Value::Unsigned(u) => Some(u as f64),
            Value::Signed(i) => Some(i as f64),
            _ => None,
        }
    }

    /// Whether the value depends on the node-ID.
    pub fn is_node_relative(&self) -> bool {
        matches!(self, Value::NodeIdPlus(_))
    }
}
