//! The floor of the XML parse benches: a bare quick-xml pass over pre-decoded text that builds
//! nothing, the ceiling for any XML parser built on quick-xml.

use quick_xml::Reader;
use quick_xml::events::Event;

/// Every event of `text`, counted.
pub fn tokenize(text: &str) -> usize {
    let mut reader = Reader::from_str(text);
    let mut events = 0usize;
    loop {
        match reader.read_event() {
            Ok(Event::Eof) | Err(_) => break,
            Ok(_) => events += 1,
        }
    }
    events
}
