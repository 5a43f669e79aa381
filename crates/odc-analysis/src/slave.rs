//! The typed entries of a device: what the generated `od` describes and the `slave` dictionary
//! (generated, or built at run time by the simulator) serves.

use odc_model::{Device, Object, SubObject};

use crate::{RustTy, cia402};

/// The sub-objects of an object that have a Rust type, in sub-index order: a VAR's sub-index 0,
/// every typed sub-object of a record or array. `cia402` is [`cia402::is_cia402`] of the device
/// (its controlword and statusword are typed as the runtime's words).
pub fn typed_subs(object: &Object, cia402: bool) -> impl Iterator<Item = (&SubObject, RustTy)> {
    let var = !object.kind.has_subs();
    object
        .subs
        .values()
        .filter(move |s| !var || s.sub_index == 0)
        .filter_map(move |s| RustTy::of_entry(s, object.index, var, cia402).map(|t| (s, t)))
}

/// One entry of the `slave` dictionary of a device: its address, its sub-object in the model
/// and the value type it is stored as.
#[derive(Clone, Copy, Debug)]
pub struct SlaveEntry<'a> {
    /// The object's index.
    pub index: u16,
    /// The sub-object (its sub-index, access, limits, default).
    pub sub: &'a SubObject,
    /// The value type; limits and defaults that are no value of it are not used.
    pub ty: RustTy,
}

/// The entries of the `slave` dictionary of `device`, in address order: every typed sub-object
/// ([`typed_subs`]) of every object. The generated dictionary and the one the simulator builds
/// from the model serve exactly these.
pub fn slave_entries(device: &Device) -> Vec<SlaveEntry<'_>> {
    let cia402 = cia402::is_cia402(device);
    device
        .objects
        .iter()
        .flat_map(|(&index, object)| {
            typed_subs(object, cia402).map(move |(sub, ty)| SlaveEntry { index, sub, ty })
        })
        .collect()
}
