//! The sections that are not objects: `[FileInfo]`, `[DeviceInfo]`, `[DummyUsage]`,
//! `[Comments]`, the object lists and DCF `[DeviceComissioning]`.

use super::*;

impl<'r, 'a> Lower<'r, 'a> {
    pub(super) fn file_info(&mut self, first: u32, dev: &mut Device) {
        self.soft = true;
        self.file_info_inner(first, dev);
        self.soft = false;
    }

    pub(super) fn file_info_inner(&mut self, first: u32, dev: &mut Device) {
        let fi = &mut dev.file_info;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            if is("FileName") {
                fi.file_name = Some(self.text(e));
            } else if is("FileVersion") || is("FileRevision") {
                match self.uint(e, 0xFF) {
                    Ok(v) => {
                        let v = v.map(|v| Spanned::new(v.value as u8, v.span));
                        if is("FileVersion") {
                            fi.file_version = v;
                        } else {
                            fi.file_revision = v;
                        }
                    }
                    Err(()) => fi.extra.push(raw_entry(e, self.file)),
                }
            } else if is("EDSVersion") {
                fi.eds_version = Some(self.text(e));
            } else if is("Description") {
                fi.description = Some(self.text(e));
            } else if is("CreationTime") {
                fi.creation_time = Some(self.text(e));
            } else if is("CreationDate") {
                fi.creation_date = Some(self.text(e));
            } else if is("CreatedBy") {
                fi.created_by = Some(self.text(e));
            } else if is("ModificationTime") {
                fi.modification_time = Some(self.text(e));
            } else if is("ModificationDate") {
                fi.modification_date = Some(self.text(e));
            } else if is("ModifiedBy") {
                fi.modified_by = Some(self.text(e));
            } else {
                fi.extra.push(raw_entry(e, self.file));
            }
        }
    }

    pub(super) fn device_info(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            let di = &mut dev.device_info;
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => {
                            dev.device_info.$field = v.map(|v| Spanned::new(v.value as $t, v.span))
                        }
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            macro_rules! bool_field {
                ($field:ident) => {
                    match self.boolean(e) {
                        Ok(v) => dev.device_info.$field = v,
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("VendorName") {
                di.vendor_name = Some(self.text(e));
            } else if is("ProductName") {
                di.product_name = Some(self.text(e));
            } else if is("OrderCode") {
                di.order_code = Some(self.text(e));
            } else if is("VendorNumber") {
                num_field!(vendor_number, u32);
            } else if is("ProductNumber") {
                num_field!(product_number, u32);
            } else if is("RevisionNumber") {
                num_field!(revision_number, u32);
            } else if is("Granularity") {
                num_field!(granularity, u8);
            } else if is("DynamicChannelsSupported") {
                num_field!(dynamic_channels_supported, u8);
            } else if is("NrOfRXPDO") {
                num_field!(nr_of_rx_pdo, u16);
            } else if is("NrOfTXPDO") {
                num_field!(nr_of_tx_pdo, u16);
            } else if is("CompactPDO") {
                num_field!(compact_pdo, u8);
            } else if is("SimpleBootUpMaster") {
                bool_field!(simple_boot_up_master);
            } else if is("SimpleBootUpSlave") {
                bool_field!(simple_boot_up_slave);
            } else if is("GroupMessaging") {
                bool_field!(group_messaging);
            } else if is("LSS_Supported") {
                bool_field!(lss_supported);
            } else if let Some(rate) = strip_prefix_ci(k.as_bytes(), "BaudRate_").and_then(dec_u16)
            {
                match self.boolean(e) {
                    Ok(Some(b)) => {
                        if b.value {
                            dev.device_info.baud_rates.push(u32::from(rate));
                        }
                    }
                    Ok(None) => {}
                    Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                }
            } else {
                di.extra.push(raw_entry(e, file));
            }
        }
    }

    pub(super) fn unexpected(&mut self, e: &Entry<'_>, section: &str) {
        self.warn(
            codes::UNEXPECTED_KEY,
            format!("key `{}` does not belong in [{}]", e.key, section),
            self.span(e.key_pos),
            "kept, not interpreted",
        );
    }

    /// Keeps entries a section without an `extra` slot cannot hold, as an unknown section of
    /// the same name.
    pub(super) fn keep_unexpected(
        &self,
        first: u32,
        kept: Vec<&Entry<'_>>,
        extra: &mut Vec<(u32, RawSection)>,
    ) {
        if kept.is_empty() {
            return;
        }
        let s = self.sec(first);
        extra.push((
            first,
            RawSection {
                name: s.name.to_owned(),
                entries: kept.into_iter().map(|e| raw_entry(e, self.file)).collect(),
                span: self.span(s.header_pos),
            },
        ));
    }

    pub(super) fn dummy_usage(
        &mut self,
        first: u32,
        dev: &mut Device,
        extra: &mut Vec<(u32, RawSection)>,
    ) {
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            let idx = strip_prefix_ci(e.key.as_bytes(), "Dummy").and_then(hex4);
            match idx {
                Some(idx) => match self.boolean(e) {
                    Ok(Some(b)) => {
                        dev.dummy_usage.insert(idx, b);
                    }
                    Ok(None) => {}
                    Err(()) => kept.push(e),
                },
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
    }

    pub(super) fn comments(
        &mut self,
        first: u32,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Vec<String> {
        let mut lines: BTreeMap<u16, String> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case("Lines") {
                continue; // implied by the LineN keys
            }
            match strip_prefix_ci(e.key.as_bytes(), "Line").and_then(dec_u16) {
                Some(n) => {
                    lines.insert(n, e.value.to_owned());
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        lines.into_values().collect()
    }

    /// A list section: the count key (ignored, implied) and `n=value` entries in order of n.
    pub(super) fn list_section(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Vec<(&'r Entry<'a>, u16)> {
        let mut items: BTreeMap<u16, &'r Entry<'a>> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case(count_key) {
                continue;
            }
            match dec_u16(e.key.as_bytes()) {
                Some(n) => {
                    items.insert(n, e);
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        items.into_iter().map(|(n, e)| (e, n)).collect()
    }

    pub(super) fn object_list(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> ObjectList {
        let mut list =
            ObjectList { span: self.span(self.sec(first).header_pos), ..Default::default() };
        if let Some(e) =
            self.entries(first).filter(|e| e.key.eq_ignore_ascii_case(count_key)).last()
        {
            match self.uint(e, 0xFFFF) {
                Ok(v) => list.supported_objects = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        for (e, _) in self.list_section(first, count_key, extra) {
            match self.uint(e, 0xFFFF) {
                Ok(Some(v)) => list.entries.push(Spanned::new(v.value as u16, v.span)),
                Ok(None) => {}
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        list
    }

    pub(super) fn commissioning(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        let mut c =
            Commissioning { span: self.span(self.sec(first).header_pos), ..Default::default() };
        for e in self.entries(first) {
            let is = |n: &str| e.key.eq_ignore_ascii_case(n);
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => c.$field = v.map(|v| Spanned::new(v.value as $t, v.span)),
                        Err(()) => c.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("NodeID") {
                num_field!(node_id, u8);
            } else if is("NodeName") {
                c.node_name = Some(self.text(e));
            } else if is("Baudrate") {
                num_field!(baudrate, u32);
            } else if is("NetNumber") {
                num_field!(net_number, u32);
            } else if is("NetworkName") {
                c.network_name = Some(self.text(e));
            } else if is("CANopenManager") {
                match self.boolean(e) {
                    Ok(v) => c.canopen_manager = v,
                    Err(()) => c.extra.push(raw_entry(e, file)),
                }
            } else if is("LSS_SerialNumber") {
                num_field!(lss_serial_number, u32);
            } else if is("NodeRefd") {
                c.node_refd = Some(self.text(e));
            } else if is("NetRefd") {
                c.net_refd = Some(self.text(e));
            } else {
                c.extra.push(raw_entry(e, file));
            }
        }
        if dev.commissioning.is_none() {
            dev.commissioning = Some(c);
        } else if let Some(old) = dev.commissioning.as_mut() {
            // Both spellings present: merge, later keys win.
            macro_rules! merge {
                ($($f:ident),*) => { $( if c.$f.is_some() { old.$f = c.$f; } )* };
            }
            merge!(
                node_id,
                node_name,
                baudrate,
                net_number,
                network_name,
                canopen_manager,
                lss_serial_number,
                node_refd,
                net_refd
            );
            old.extra.extend(c.extra);
        }
    }

    // ----- objects ---------------------------------------------------------------------------
}
