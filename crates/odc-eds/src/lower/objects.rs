//! Object sections: sub-objects from their keys, objects with their compact and companion
//! sections, and the modules of a modular device.

use super::*;

impl<'r, 'a> Lower<'r, 'a> {
    /// Fills a sub-object from known keys; leftovers go to `extra`.
    pub(super) fn sub_from_keys(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub_index: u8,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) -> SubObject {
        let mut sub = blank_sub(sub_index);
        self.fill_sub(keys, &mut sub, header, default_dt, what);
        sub
    }

    /// Fills `sub` (fresh from [`blank_sub`]) from known keys; leftovers go to its `extra`.
    /// In place: a sub-object is large, and building it elsewhere to move it into its
    /// object's vector was a copy per sub-object.
    pub(super) fn fill_sub(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub: &mut SubObject,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) {
        let sub_index = sub.sub_index;
        let what_is_null = std::mem::take(&mut self.null_object);
        let file = self.file;
        sub.name = match keys.take(K::ParameterName) {
            Some(e) => Name::from(e.value),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("{what} has no ParameterName"),
                    header,
                    "here",
                );
                Name::default()
            }
        };
        let mut extra_entries: Vec<&Entry<'_>> = Vec::new();
        let mut unreadable = None;
        let data_type = match keys.take(K::DataType) {
            Some(e) => match self.data_type(e) {
                Ok(Some(dt)) => {
                    sub.data_type_span = self.span(e.line_pos);
                    Some(dt)
                }
                Ok(None) => None,
                Err(()) => {
                    extra_entries.push(e);
                    unreadable = Some(self.span(e.value_pos));
                    None
                }
            },
            None => None,
        };
        let data_type = match data_type.or(default_dt) {
            Some(dt) => dt,
            None => {
                let d = match unreadable {
                    Some(at) => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no readable DataType"),
                    )
                    .with_label(at, "not a DataType"),
                    None => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no DataType"),
                    )
                    .with_label(header, "DataType missing"),
                };
                self.diags.push(d.with_note("assumed DOMAIN"));
                DataType::Domain
            }
        };
        let access = match keys.take(K::AccessType) {
            Some(e) => self.access(e).unwrap_or_else(|| {
                if !e.value.is_empty() {
                    extra_entries.push(e);
                }
                Access::Ro
            }),
            None if default_dt == Some(DataType::Domain) && sub_index == 0 && what_is_null => {
                Access::Ro
            }
            None => {
                self.warn(
                    codes::MISSING_ACCESS_TYPE,
                    format!("{what} has no AccessType; assumed ro"),
                    header,
                    "AccessType missing",
                );
                Access::Ro
            }
        };
        let pdo_mapping = match keys.take(K::PdoMapping) {
            Some(e) => match self.boolean(e) {
                Ok(Some(b)) => {
                    if b.value {
                        PdoMapping::Yes
                    } else {
                        PdoMapping::No
                    }
                }
                Ok(None) => PdoMapping::No,
                Err(()) => {
                    extra_entries.push(e);
                    PdoMapping::No
                }
            },
            None => PdoMapping::No,
        };
        sub.data_type = data_type;
        sub.access = access;
        sub.pdo_mapping = pdo_mapping;
        sub.span = header;
        if let Some(e) = keys.take(K::ObjectType) {
            match self.object_kind(e) {
                Some(k) => sub.kind = Some(k),
                None => extra_entries.push(e),
            }
        }
        sub.default = keys.take(K::DefaultValue).and_then(|e| self.value(e, data_type));
        sub.low_limit = keys.take(K::LowLimit).and_then(|e| self.limit(e, data_type));
        sub.high_limit = keys.take(K::HighLimit).and_then(|e| self.limit(e, data_type));
        sub.parameter_value = keys.take(K::ParameterValue).and_then(|e| self.value(e, data_type));
        let denotation = keys.take(K::Denotation).map(|e| self.text(e));
        let mut obj_flags = None;
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => extra_entries.push(e),
            }
        }
        let upload_file = keys.take(K::UploadFile).map(|e| self.text(e));
        let download_file = keys.take(K::DownloadFile).map(|e| self.text(e));
        for k in [K::SubNumber, K::CompactSubObj, K::Count, K::ObjExtend] {
            keys.move_to_extra(k);
        }
        if !keys.shadowed.is_empty() {
            self.check_shadowed(keys, Some(data_type));
        }
        let has_extra = !(extra_entries.is_empty() && keys.extra.is_empty());
        let has_rare = denotation.is_some()
            || obj_flags.is_some()
            || upload_file.is_some()
            || download_file.is_some()
            || has_extra;
        // Most sub-objects have none of these: no box is made for them.
        if has_rare || !sub.rare().is_empty() {
            let r = sub.rare_mut();
            r.denotation = denotation;
            r.obj_flags = obj_flags;
            r.upload_file = upload_file;
            r.download_file = download_file;
            if has_extra {
                r.extra = extra_entries
                    .into_iter()
                    .chain(keys.extra.drain(..))
                    .map(|e| raw_entry(e, file))
                    .collect();
            }
        }
    }

    pub(super) fn object_kind(&mut self, e: &Entry<'_>) -> Option<ObjectKind> {
        let span = self.span(e.value_pos);
        let v = self.uint(e, 0xFF).ok().flatten()?;
        match ObjectKind::from_code(v.value as u8) {
            Some(k) => Some(k),
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::INVALID_OBJECT_TYPE,
                        format!("ObjectType `{}` is not a CiA 301 object code", e.value),
                    )
                    .with_label(span, "expected 0x0, 0x2, 0x5, 0x6, 0x7, 0x8 or 0x9"),
                );
                None
            }
        }
    }

    pub(super) fn object(
        &mut self,
        index: u16,
        b: &ObjB,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Option<Object> {
        let main = b.main?;
        let file = self.file;
        let header = self.span(self.sec(main).header_pos);
        let mut keys = self.keys(main);
        let mut obj_extra: Vec<&Entry<'_>> = Vec::new();
        let kind = match keys.take(K::ObjectType) {
            Some(e) => self.object_kind(e).unwrap_or_else(|| {
                obj_extra.push(e);
                // Sub-objects, explicit or implied by CompactSubObj, make it a RECORD (the writer
                // may turn explicit ones into implied ones).
                if b.subs.is_empty() && keys.get(K::CompactSubObj).is_none() {
                    ObjectKind::Var
                } else {
                    ObjectKind::Record
                }
            }),
            None => ObjectKind::Var,
        };
        let name = match keys.get(K::ParameterName) {
            Some(e) => e.value.to_owned(),
            // A VAR's sub-object 0 reports the missing name.
            None if !kind.has_subs() => String::new(),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("object {index:04X} has no ParameterName"),
                    header,
                    "here",
                );
                String::new()
            }
        };
        let mut obj = Object::new(index, name, kind, header);
        if let Some(e) = keys.take(K::SubNumber) {
            match self.uint(e, 0xFFFF) {
                Ok(v) => obj.sub_number = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj.obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if kind.has_subs() {
            obj.denotation = keys.take(K::Denotation).map(|e| self.text(e));
            let compact = match keys.take(K::CompactSubObj) {
                Some(e) => match self.uint(e, 0xFF) {
                    Ok(v) => v.map(|v| Spanned::new(v.value as u8, v.span)),
                    Err(()) => {
                        obj_extra.push(e);
                        None
                    }
                },
                None => None,
            };
            obj.compact_sub_obj = compact.clone();
            let compact = compact.filter(|n| {
                self.implied_subs += usize::from(n.value);
                let over = self.implied_subs > crate::MAX_IMPLIED_SUB_OBJECTS;
                // Reported at the first object past the limit.
                if over
                    && self.implied_subs - usize::from(n.value) <= crate::MAX_IMPLIED_SUB_OBJECTS
                {
                    self.diags.push(
                        Diagnostic::error(
                            codes::COMPACT_LIMIT,
                            format!(
                                "more than {} sub-objects implied by CompactSubObj in this file; \
                                 this object and the later ones are not expanded",
                                crate::MAX_IMPLIED_SUB_OBJECTS
                            ),
                        )
                        .with_label(n.span, "the limit is crossed here"),
                    );
                }
                !over
            });
            match compact.filter(|n| n.value > 0) {
                Some(n) => self.compact_subs(&mut obj, &mut keys, n, b),
                None => obj.subs.reserve_exact(b.subs.len()),
            }
            keys.take(K::ParameterName);
            // Keys that only a VAR or a compact object uses are kept as written.
            for k in [
                K::DataType,
                K::AccessType,
                K::PdoMapping,
                K::DefaultValue,
                K::LowLimit,
                K::HighLimit,
                K::ParameterValue,
                K::UploadFile,
                K::DownloadFile,
                K::Count,
                K::ObjExtend,
            ] {
                keys.move_to_extra(k);
            }
            for (s, si) in b.subs.iter() {
                let sheader = self.span(self.sec(si).header_pos);
                let mut skeys = self.keys(si);
                let implied = obj.subs.contains_key(&s);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                if implied {
                    *sub = blank_sub(s);
                }
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
                if implied {
                    self.warn(
                        codes::COMPACT_CONFLICT,
                        format!(
                            "[{}] overrides a sub-object implied by CompactSubObj",
                            self.sec(si).name
                        ),
                        self.span(self.sec(si).name_pos),
                        "explicit section wins",
                    );
                }
            }
        } else {
            keys.move_to_extra(K::CompactSubObj);
            self.null_object = kind == ObjectKind::Null;
            let default_dt = match kind {
                ObjectKind::Domain => Some(DataType::Domain),
                ObjectKind::Null => Some(DataType::Domain),
                ObjectKind::DefType => Some(DataType::Unsigned32),
                _ => None,
            };
            obj.subs.reserve_exact(1 + b.subs.len());
            let sub = obj.subs.entry(0).or_insert_with(|| blank_sub(0));
            self.fill_sub(&mut keys, sub, header, default_dt, &format_args!("object {index:04X}"));
            sub.kind = None;
            // Unknown keys of a VAR section belong to the object.
            if !sub.rare().extra.is_empty() {
                obj.extra.append(&mut sub.rare_mut().extra);
            }
            for (s, si) in b.subs.iter() {
                let sec = self.sec(si);
                self.warn(
                    codes::SUBS_ON_VAR,
                    format!("[{}] belongs to a {:?} object", sec.name, kind),
                    self.span(sec.name_pos),
                    "kept as a sub-object",
                );
                if s == 0 {
                    extra.push((si, self.raw_section(si)));
                    continue;
                }
                let sheader = self.span(sec.header_pos);
                let mut skeys = self.keys(si);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
            }
        }
        if let Some(li) = b.links {
            for (e, _) in self.list_section(li, "ObjectLinks", extra) {
                match self.uint(e, 0xFFFF) {
                    Ok(Some(v)) => obj.links.push(Spanned::new(v.value as u16, v.span)),
                    Ok(None) => {}
                    Err(()) => {}
                }
            }
        }
        self.companions(&mut obj, b);
        if !keys.shadowed.is_empty() {
            // A structured object's own keys (a VAR's went through `fill_sub`); values typed
            // by the object's DataType are those of a compact object's sub-objects.
            let dt = obj.sub(1).filter(|_| obj.compact_sub_obj.is_some()).map(|s| s.data_type);
            self.check_shadowed(&mut keys, dt);
        }
        let mut all_extra: Vec<RawEntry> =
            obj_extra.into_iter().chain(keys.extra.drain(..)).map(|e| raw_entry(e, file)).collect();
        all_extra.append(&mut obj.extra);
        obj.extra = all_extra;
        Some(obj)
    }

    pub(super) fn compact_subs(
        &mut self,
        obj: &mut Object,
        keys: &mut Keys<'r, 'a>,
        n: Spanned<u8>,
        b: &ObjB,
    ) {
        let what = format!("compact object {:04X}", obj.index);
        // The template: DataType, AccessType, PDOMapping and values of the object section.
        let mut tkeys = Keys { k: [None; N_KEYS], extra: Vec::new(), shadowed: Vec::new() };
        for k in COMPACT_TEMPLATE {
            tkeys.k[k as usize] = keys.take(k);
        }
        tkeys.k[K::ParameterName as usize] = keys.get(K::ParameterName);
        let mut template = self.sub_from_keys(&mut tkeys, 1, obj.span, None, &what);
        // Every implied sub-object gets its own name: do not clone the template's.
        template.name = Name::default();
        template.span = n.span;
        let mut sub0 = SubObject::new(0, COMPACT_SUB0_NAME, DataType::Unsigned8, Access::Ro);
        sub0.default = Some(Spanned::new(Value::Unsigned(u64::from(n.value)), n.span));
        sub0.span = n.span;
        // Explicit sub sections are read after this, so `obj.subs` is empty here.
        obj.subs.reserve_exact(1 + b.subs.len());
        obj.subs.insert(0, sub0);
        obj.subs.set_implied(template, n.value, &obj.name);
    }

    /// `[IIIIName]`, `[IIIIValue]`, `[IIIIDenotation]`.
    pub(super) fn companions(&mut self, obj: &mut Object, b: &ObjB) {
        for (sec, which) in [(b.name, 0u8), (b.value, 1), (b.denotation, 2)] {
            let Some(first) = sec else { continue };
            for e in self.entries(first) {
                if e.key.eq_ignore_ascii_case("NrOfEntries") {
                    continue;
                }
                // Companions name and set sub-objects of an ARRAY or RECORD: a VAR's sub-index 0
                // is the object itself, whose name is its own `ParameterName`.
                // `get_mut` makes only this one of a compact object's implied sub-objects.
                let sub = dec_u16(e.key.as_bytes())
                    .and_then(|n| u8::try_from(n).ok())
                    .filter(|_| obj.kind.has_subs())
                    .and_then(|n| obj.subs.get_mut(&n));
                let Some(s) = sub else {
                    self.warn(
                        codes::BAD_COMPACT_ENTRY,
                        format!(
                            "`{}` in [{}] is not a sub-index of object {:04X}",
                            e.key,
                            self.sec(first).name,
                            obj.index
                        ),
                        self.span(e.key_pos),
                        "ignored",
                    );
                    continue;
                };
                match which {
                    0 => s.name = Name::from(e.value),
                    1 => s.parameter_value = self.value(e, s.data_type),
                    _ => s.rare_mut().denotation = Some(self.text(e)),
                }
            }
        }
    }

    pub(super) fn module(
        &mut self,
        number: u16,
        b: &ModB,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Module {
        let file = self.file;
        let mut m = Module { number, ..Default::default() };
        if let Some(i) = b.info {
            m.has_info = true;
            m.span = self.span(self.sec(i).header_pos);
            for e in self.entries(i) {
                let is = |n: &str| e.key.eq_ignore_ascii_case(n);
                if is("ProductName") {
                    m.product_name = Some(self.text(e));
                } else if is("OrderCode") {
                    m.order_code = Some(self.text(e));
                } else if is("ProductVersion") || is("ProductRevision") {
                    match self.uint(e, 0xFFFF) {
                        Ok(v) => {
                            let v = v.map(|v| Spanned::new(v.value as u16, v.span));
                            if is("ProductVersion") {
                                m.product_version = v;
                            } else {
                                m.product_revision = v;
                            }
                        }
                        Err(()) => m.extra.push(raw_entry(e, file)),
                    }
                } else {
                    m.extra.push(raw_entry(e, file));
                }
            }
        }
        if let Some(i) = b.fixed_list {
            // The list is implied by the [MxFixedIIII] sections; read it for diagnostics only.
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, ob) in &b.fixed {
            match self.object(index, ob, extra) {
                Some(o) => {
                    std::sync::Arc::make_mut(&mut m.fixed_objects).insert(index, o);
                }
                None => {
                    for i in ob.subs.values() {
                        let s = self.sec(i);
                        self.warn(
                            codes::ORPHAN_SECTION,
                            format!("[{}] has no object section", s.name),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                        extra.push((i, self.raw_section(i)));
                    }
                }
            }
        }
        if let Some(i) = b.sub_ext_list {
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, &i) in &b.sub_ext {
            let header = self.span(self.sec(i).header_pos);
            let mut keys = self.keys(i);
            let count = keys.take(K::Count).map(|e| self.text(e));
            let obj_extend = keys.take(K::ObjExtend).and_then(|e| match self.uint(e, 0xFFFF) {
                Ok(v) => v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => None,
            });
            let template = self.sub_from_keys(
                &mut keys,
                0,
                header,
                None,
                &format_args!("module {number} sub-extension {index:04X}"),
            );
            m.sub_extends.insert(index, SubExtend { template, count, obj_extend });
        }
        if let Some(i) = b.comments {
            m.comments = self.comments(i, extra);
        }
        m
    }
}

/// A sub-object with nothing read yet, for [`Lower::fill_sub`].
fn blank_sub(sub_index: u8) -> SubObject {
    SubObject::new(sub_index, String::new(), DataType::Domain, Access::Ro)
}
