use odc::{Access, Entry, ObjValue};

const TARGET_POSITION: Entry<i32> = Entry::new(0x607A, 0, "Target position", Access::Rww, true);

/// The shape of an SDO client's typed write.
fn write<T: ObjValue>(_entry: Entry<T>, _value: T) {}

fn main() {
    write(TARGET_POSITION, 1000i32);
    write(TARGET_POSITION, 1000u16);
    write(TARGET_POSITION, true);
}
