//! Value readers: numbers, booleans, access and data types, typed values, limits, and the
//! values a later entry replaced (read for their diagnostics only).

use super::*;

impl<'r, 'a> Lower<'r, 'a> {
    // ----- value readers -------------------------------------------------------------------

    pub(super) fn warn(
        &mut self,
        code: &'static str,
        msg: impl Into<String>,
        span: Span,
        label: &str,
    ) {
        self.diags.push(Diagnostic::warning(code, msg).with_label(span, label));
    }

    /// Warns about how an integer was written, if [`num::WARN_FLAGS`] says there is anything
    /// to say (rarely: the check is inlined, the warnings are not).
    #[inline(always)]
    pub(super) fn int_flags(&mut self, flags: u8, e: &Entry<'_>) {
        if flags & num::WARN_FLAGS != 0 {
            self.int_flag_warnings(flags, e);
        }
    }

    pub(super) fn int_flag_warnings(&mut self, flags: u8, e: &Entry<'_>) {
        let span = self.span(e.value_pos);
        if flags & num::OCTAL != 0 {
            self.warn(
                codes::OCTAL_NUMBER,
                format!("`{}` has a leading zero and is read as octal", e.value),
                span,
                "read as octal",
            );
        }
        if flags & num::SUFFIX != 0 {
            self.warn(
                codes::INTEGER_SUFFIX,
                format!("C integer suffix in `{}` ignored", e.value),
                span,
                "suffix ignored",
            );
        }
        if flags & num::NODEID_ORDER != 0 {
            self.warn(
                codes::NODEID_ORDER,
                format!("`{}`: write `$NODEID` first", e.value),
                span,
                "read as $NODEID+offset",
            );
        }
    }

    /// Runs `read` on the value; when it fails and the value has a trailing comment, runs it on
    /// the value without the comment (with a warning).
    pub(super) fn with_comment_fallback<T>(
        &mut self,
        e: &Entry<'_>,
        mut read: impl FnMut(&str) -> Option<T>,
    ) -> Option<T> {
        if let Some(v) = read(e.value) {
            return Some(v);
        }
        let stripped = num::strip_inline_comment(e.value)?;
        let v = read(stripped)?;
        self.warn(
            codes::INLINE_COMMENT,
            format!("comment after the value of `{}`", e.key),
            self.span(e.value_pos),
            "comment ignored",
        );
        Some(v)
    }

    /// Reads an unsigned header number of at most `max`. `Ok(None)`: empty (warned);
    /// `Err(())`: unreadable (reported; the caller keeps the raw entry).
    pub(super) fn uint(&mut self, e: &Entry<'_>, max: u64) -> Result<Option<Spanned<u64>>, ()> {
        if e.value.is_empty() {
            self.empty(e);
            return Ok(None);
        }
        let span = self.span(e.value_pos);
        let Some((v, flags)) = self.with_comment_fallback(e, num::parse_plain) else {
            let sev = if self.soft { Severity::Warning } else { Severity::Error };
            self.diags.push(
                Diagnostic::new(
                    sev,
                    codes::INVALID_VALUE,
                    format!("`{}` is not a number", e.value),
                )
                .with_label(span, format!("expected a number for `{}`", e.key))
                .with_note("numbers are decimal, 0x-hex or 0-octal"),
            );
            return Err(());
        };
        if v < 0 || v > i128::from(max) {
            self.diags.push(
                Diagnostic::new(
                    if self.soft { Severity::Warning } else { Severity::Error },
                    codes::OUT_OF_RANGE,
                    format!("`{}` does not fit `{}` (0..={max})", e.value, e.key),
                )
                .with_label(span, "out of range"),
            );
            return Err(());
        }
        self.int_flags(flags, e);
        Ok(Some(Spanned::new(v as u64, span)))
    }

    pub(super) fn boolean(&mut self, e: &Entry<'_>) -> Result<Option<Spanned<bool>>, ()> {
        if e.value.is_empty() {
            self.empty(e);
            return Ok(None);
        }
        let span = self.span(e.value_pos);
        match self.with_comment_fallback(e, num::parse_bool) {
            Some(b) => Ok(Some(Spanned::new(b, span))),
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::INVALID_VALUE,
                        format!("`{}` is not a boolean", e.value),
                    )
                    .with_label(span, format!("expected 0 or 1 for `{}`", e.key)),
                );
                Err(())
            }
        }
    }

    pub(super) fn empty(&mut self, e: &Entry<'_>) {
        self.warn(
            codes::EMPTY_VALUE,
            concat(&["`", e.key, "=` has no value; treated as absent"]),
            self.span(e.line_pos),
            "empty value",
        );
    }

    pub(super) fn text(&self, e: &Entry<'_>) -> Spanned<String> {
        Spanned::new(e.value.to_owned(), self.span(e.value_pos))
    }

    /// Reads a value typed by `dt`.
    pub(super) fn value(&mut self, e: &Entry<'_>, dt: DataType) -> Option<Spanned<Value>> {
        let span = self.span(e.value_pos);
        let class = dt.class();
        if e.value.is_empty() {
            return match class {
                ValueClass::Text => Some(Spanned::new(Value::Text(Box::default()), span)),
                ValueClass::Bytes => Some(Spanned::new(Value::Bytes(Box::default()), span)),
                ValueClass::Unicode => Some(Spanned::new(Value::Unicode(Box::default()), span)),
                _ => {
                    self.empty(e);
                    None
                }
            };
        }
        let mut problem = Problem::Invalid;
        let read = |s: &str, problem: &mut Problem| read_value(s, dt, problem);
        let got = match read(e.value, &mut problem) {
            Some(v) => Some(v),
            None if problem == Problem::Invalid => {
                let mut p2 = Problem::Invalid;
                let r = num::strip_inline_comment(e.value).and_then(|s| read(s, &mut p2));
                if r.is_some() {
                    self.warn(
                        codes::INLINE_COMMENT,
                        format!("comment after the value of `{}`", e.key),
                        span,
                        "comment ignored",
                    );
                }
                r
            }
            None => None,
        };
        match got {
            Some((v, flags)) => {
                self.int_flags(flags, e);
                if class == ValueClass::Bytes && num::hex_has_odd_group(e.value) {
                    self.odd_hex(e, &v, dt);
                }
                Some(Spanned::new(v, span))
            }
            None => {
                let d = match problem {
                    Problem::Range => Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        format!("`{}` does not fit {}", e.value, dt.name()),
                    )
                    .with_label(span, format!("out of range for {}", dt.name())),
                    Problem::Invalid => Diagnostic::new(
                        if class == ValueClass::Bytes {
                            Severity::Warning
                        } else {
                            Severity::Error
                        },
                        codes::INVALID_VALUE,
                        format!("`{}` is not a valid {} value", e.value, dt.name()),
                    )
                    .with_label(span, format!("expected {}", expected(class))),
                };
                self.diags.push(d.with_note(KEPT_AS_WRITTEN));
                Some(Spanned::new(Value::Invalid(e.value.into()), span))
            }
        }
    }

    /// Warns that an OCTET_STRING/DOMAIN value has a group of an odd number of hex digits,
    /// saying how it was read (a zero nibble in front of the group: `ABC` is `0A BC`). No note:
    /// CANopenNode files write `DefaultValue=0` on every DOMAIN, and the message says it all.
    #[cold]
    pub(super) fn odd_hex(&mut self, e: &Entry<'_>, v: &Value, dt: DataType) {
        let read = match v {
            Value::Bytes(b) => b.iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" "),
            _ => return,
        };
        self.diags.push(
            Diagnostic::warning(
                codes::ODD_HEX_DIGITS,
                format!(
                    "`{}` has an odd number of hex digits for {}; read as `{read}`",
                    e.value,
                    dt.name()
                ),
            )
            .with_label(self.span(e.value_pos), format!("read as `{read}`")),
        );
    }

    /// Reads a `LowLimit`/`HighLimit`: an empty one is absent whatever the type (with
    /// [`codes::EMPTY_VALUE`], as for numbers); only a value is the empty string.
    pub(super) fn limit(&mut self, e: &Entry<'_>, dt: DataType) -> Option<Box<Spanned<Value>>> {
        if e.value.is_empty() {
            self.empty(e);
            return None;
        }
        self.value(e, dt).map(Box::new)
    }

    pub(super) fn data_type(&mut self, e: &Entry<'_>) -> Result<Option<DataType>, ()> {
        if let Some(dt) = type_by_name(e.value) {
            self.diags.push(
                Diagnostic::error(
                    codes::INVALID_VALUE,
                    format!("DataType `{}` is a name, not a data type index", e.value),
                )
                .with_label(self.span(e.value_pos), format!("did you mean 0x{:04X}?", dt.code()))
                .with_note(format!(
                    "DataType is the index of the type's object: {} is 0x{:04X}",
                    dt.name(),
                    dt.code()
                )),
            );
            return Err(());
        }
        let Some(v) = self.uint(e, 0xFFFF)? else { return Ok(None) };
        // CiA 301 §7.4.7: data types are the objects 0x0001..=0x025F.
        if v.value == 0 || v.value > 0x025F {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("`{}` is not a data type index (0x0001..=0x025F)", e.value),
                )
                .with_label(v.span, "kept as written"),
            );
            return Err(());
        }
        let dt = DataType::from_code(v.value as u16);
        if let DataType::Profile(code) = dt
            && self.defined_types.binary_search(&code).is_err()
        {
            let what = match code {
                0x0040..=0x005F => "a manufacturer-specific data type",
                0x0060..=0x025F => "a device-profile data type",
                _ => "reserved",
            };
            self.diags.push(
                Diagnostic::warning(
                    codes::NOT_A_DATA_TYPE,
                    format!("`{}` is not a data type index", e.value),
                )
                .with_label(v.span, "not a data type")
                .with_note(format!(
                    "CiA 301 defines no data type 0x{code:04X} ({what}), and the file has no \
                     object [{code:04X}] defining one; values are read as plain numbers or text"
                )),
            );
        }
        Ok(Some(dt))
    }

    pub(super) fn access(&mut self, e: &Entry<'_>) -> Option<Access> {
        let span = self.span(e.value_pos);
        if e.value.is_empty() {
            self.empty(e);
            return None;
        }
        let read = |s: &str| -> Option<(Access, bool)> {
            if let Some(a) = Access::parse(s) {
                Some((a, false))
            } else if s.trim().eq_ignore_ascii_case("r") {
                Some((Access::Ro, true))
            } else {
                None
            }
        };
        match self.with_comment_fallback(e, read) {
            Some((a, nonstandard)) => {
                if nonstandard {
                    self.warn(
                        codes::NONSTANDARD_ACCESS,
                        format!("AccessType `{}` is not CiA 306; read as `ro`", e.value),
                        span,
                        "read as ro",
                    );
                }
                Some(a)
            }
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::UNKNOWN_ACCESS,
                        format!("unknown AccessType `{}`", e.value),
                    )
                    .with_label(span, "expected ro, wo, rw, rwr, rww or const")
                    .with_note("assumed ro"),
                );
                None
            }
        }
    }

    /// Reads the values that a later entry of the same key replaced (see [`Keys::shadowed`])
    /// for their diagnostics only: each diagnostic gets a note and a label at the entry that
    /// replaced the value; only errors are kept. Values typed by the data type are read with
    /// `dt` when it is known.
    #[cold]
    pub(super) fn check_shadowed(&mut self, keys: &mut Keys<'r, 'a>, dt: Option<DataType>) {
        for (k, e, by) in std::mem::take(&mut keys.shadowed) {
            let outer = std::mem::take(&mut self.diags);
            match k {
                K::DataType => {
                    let _ = self.data_type(e);
                }
                K::AccessType => {
                    let _ = self.access(e);
                }
                K::PdoMapping => {
                    let _ = self.boolean(e);
                }
                K::ObjectType => {
                    let _ = self.object_kind(e);
                }
                K::ObjFlags => {
                    let _ = self.uint(e, u64::from(u32::MAX));
                }
                K::SubNumber => {
                    let _ = self.uint(e, 0xFFFF);
                }
                K::CompactSubObj => {
                    let _ = self.uint(e, 0xFF);
                }
                K::DefaultValue | K::ParameterValue => {
                    if let Some(dt) = dt {
                        let _ = self.value(e, dt);
                    }
                }
                K::LowLimit | K::HighLimit => {
                    if let Some(dt) = dt {
                        let _ = self.limit(e, dt);
                    }
                }
                K::ParameterName
                | K::Denotation
                | K::UploadFile
                | K::DownloadFile
                | K::Count
                | K::ObjExtend => {}
            }
            let found = std::mem::replace(&mut self.diags, outer).finish();
            let by = self.span(by.key_pos);
            // Errors only: how a replaced value was written (octal, a suffix) is noise.
            for mut d in found.into_iter().filter(Diagnostic::is_error) {
                d.notes.retain(|n| n != KEPT_AS_WRITTEN);
                self.diags.push(
                    d.with_secondary(by, "replaced by this later value").with_note(format!(
                        "the value is not used: a later `{}=` replaces it",
                        e.key
                    )),
                );
            }
        }
    }
}

/// The type a `DataType` value names when it is written as a name (`UNSIGNED16`,
/// `visible_string`) instead of an index; case and `_` are ignored.
pub(super) fn type_by_name(s: &str) -> Option<DataType> {
    let s = s.trim();
    if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        return None;
    }
    let same = |name: &str| {
        let mut a = s.bytes().filter(|&c| c != b'_');
        let mut b = name.bytes().filter(|&c| c != b'_');
        loop {
            match (a.next(), b.next()) {
                (None, None) => return true,
                (Some(x), Some(y)) if x.eq_ignore_ascii_case(&y) => {}
                _ => return false,
            }
        }
    };
    (0x0001..=0x0023)
        .map(DataType::from_code)
        .filter(|dt| !matches!(dt, DataType::Profile(_)))
        .find(|dt| same(&dt.name()))
}

/// The pieces joined into one exactly sized string: for the messages of diagnostics that real
/// files trigger by the thousand (`F112`), cheaper than `format!`.
pub(super) fn concat(parts: &[&str]) -> String {
    let mut s = String::with_capacity(parts.iter().map(|p| p.len()).sum());
    parts.iter().for_each(|p| s.push_str(p));
    s
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Problem {
    Invalid,
    Range,
}

pub(super) fn expected(class: ValueClass) -> &'static str {
    match class {
        ValueClass::Bool => "0 or 1",
        ValueClass::Unsigned(_) | ValueClass::Signed(_) => {
            "a decimal, 0x-hex or 0-octal number, optionally $NODEID+"
        }
        ValueClass::Real32 | ValueClass::Real64 => "a decimal float or a 0x bit pattern",
        ValueClass::Bytes => "hex bytes",
        ValueClass::Time => "milliseconds and days",
        _ => "a value",
    }
}

/// Reads `s` as a value of `dt`. `flags` are [`num`] warning flags.
pub(crate) fn read_value(s: &str, dt: DataType, problem: &mut Problem) -> Option<(Value, u8)> {
    let s = trim(s);
    match dt.class() {
        ValueClass::Bool => num::parse_bool(s).map(|b| (Value::Bool(b), 0)),
        ValueClass::Unsigned(bits) => {
            let n = num::parse_int(s)?;
            if n.node_id {
                let v = i64::try_from(n.value).ok()?;
                return Some((Value::NodeIdPlus(v), n.flags));
            }
            let max = if bits >= 64 { u128::from(u64::MAX) } else { (1u128 << bits) - 1 };
            if n.value < 0 || n.value as u128 > max {
                *problem = Problem::Range;
                return None;
            }
            Some((Value::Unsigned(n.value as u64), n.flags & !num::HEX))
        }
        ValueClass::Signed(bits) => {
            let n = num::parse_int(s)?;
            if n.node_id {
                let v = i64::try_from(n.value).ok()?;
                return Some((Value::NodeIdPlus(v), n.flags));
            }
            let bits = bits.min(64);
            let smax = (1i128 << (bits - 1)) - 1;
            let smin = -(1i128 << (bits - 1));
            let umax = (1i128 << bits) - 1;
            let mut v = n.value;
            if n.flags & num::HEX != 0 && v > smax && v <= umax {
                v -= 1i128 << bits; // two's complement bit pattern
            }
            if v < smin || v > smax {
                *problem = Problem::Range;
                return None;
            }
            Some((Value::Signed(v as i64), n.flags & !num::HEX))
        }
        ValueClass::Real32 => {
            if is_hex(s) {
                let (v, flags) = num::parse_plain(s)?;
                if !(0..=i128::from(u32::MAX)).contains(&v) {
                    *problem = Problem::Range;
                    return None;
                }
                Some((Value::Real32(v as u32), flags & !num::HEX))
            } else {
                let (s, flags) = strip_float_suffix(s);
                num::parse_f32(s).map(|f| (Value::Real32(f.to_bits()), flags))
            }
        }
        ValueClass::Real64 => {
            if is_hex(s) {
                let (v, flags) = num::parse_plain(s)?;
                if !(0..=i128::from(u64::MAX)).contains(&v) {
                    *problem = Problem::Range;
                    return None;
                }
                Some((Value::Real64(v as u64), flags & !num::HEX))
            } else {
                let (s, flags) = strip_float_suffix(s);
                num::parse_f64(s).map(|f| (Value::Real64(f.to_bits()), flags))
            }
        }
        ValueClass::Text => Some((Value::Text(s.into()), 0)),
        ValueClass::Bytes => {
            num::parse_hex_bytes(s).map(|b| (Value::Bytes(b.into_boxed_slice()), 0))
        }
        ValueClass::Unicode => Some((Value::Unicode(s.encode_utf16().collect()), 0)),
        ValueClass::Time => {
            let mut it = s.split_ascii_whitespace();
            let a = it.next()?;
            match (it.next(), it.next()) {
                (None, _) => {
                    let (v, flags) = num::parse_plain(a)?;
                    if !(0..=0xFFFF_FFFF_FFFF).contains(&v) {
                        *problem = Problem::Range;
                        return None;
                    }
                    let v = v as u64;
                    Some((Value::Time { ms: v as u32, days: (v >> 32) as u16 }, flags & !num::HEX))
                }
                (Some(b), None) => {
                    let (days, f1) = num::parse_plain(a)?;
                    let (ms, f2) = num::parse_plain(b)?;
                    let ms = u32::try_from(ms).ok()?;
                    let days = u16::try_from(days).ok()?;
                    Some((Value::Time { ms, days }, (f1 | f2) & !num::HEX))
                }
                _ => None,
            }
        }
        ValueClass::Structured => match num::parse_int(s) {
            Some(n) if n.node_id => {
                Some((Value::NodeIdPlus(i64::try_from(n.value).ok()?), n.flags))
            }
            Some(n) if n.value >= 0 => Some((Value::Unsigned(n.value as u64), n.flags & !num::HEX)),
            Some(n) => Some((Value::Signed(i64::try_from(n.value).ok()?), n.flags & !num::HEX)),
            None => Some((Value::Text(s.into()), 0)),
        },
    }
}

/// Cuts a C float suffix (`1.0f`, `2.5F`, `1.0L`).
pub(super) fn strip_float_suffix(s: &str) -> (&str, u8) {
    match s.strip_suffix(['f', 'F', 'l', 'L']) {
        Some(t) if t.ends_with(|c: char| c.is_ascii_digit() || c == '.') => (t, num::SUFFIX),
        _ => (s, 0),
    }
}

pub(super) fn is_hex(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() > 2 && b[0] == b'0' && (b[1] == b'x' || b[1] == b'X')
}
