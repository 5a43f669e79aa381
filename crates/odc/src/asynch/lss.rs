//! LSS master (CiA 305) on the async master.
