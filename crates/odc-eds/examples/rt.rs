//! Debug helper: parse, write, parse again and show where the models differ.

fn main() {
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path).unwrap_or_default();
        let mut sources = odc_model::Sources::new();
        let p = odc_eds::parse(&mut sources, &path, &bytes);
        let format = p.device.format.unwrap_or(odc_model::Format::Eds);
        let text = odc_eds::write(&p.device, format);
        let p2 = odc_eds::parse(&mut sources, &path, text.as_bytes());
        let (a, b) = (&p.device, &p2.device);
        println!("{path}: equal={}", a == b);
        for (i, o) in &a.objects {
            match b.objects.get(i) {
                Some(o2) if o2 == o => {}
                Some(o2) => println!("object {i:04X} differs:\n{o:#?}\n{o2:#?}"),
                None => println!("object {i:04X} missing"),
            }
        }
        if a.objects.len() != b.objects.len() {
            println!("object count differs");
        }
        if a.file_info != b.file_info {
            println!("file_info {:?} {:?}", a.file_info, b.file_info);
        }
        if a.device_info != b.device_info {
            println!("device_info {:?}\n{:?}", a.device_info, b.device_info);
        }
        if a.commissioning != b.commissioning {
            println!("comm");
        }
        if a.object_lists != b.object_lists {
            println!("lists");
        }
        if a.extra_sections != b.extra_sections {
            println!("extra {:?}\n{:?}", a.extra_sections, b.extra_sections);
        }
        if a.modules != b.modules {
            println!("modules");
        }
        if a.pdos != b.pdos {
            println!("pdos");
        }
        if a.format != b.format {
            println!("format");
        }
        if std::env::var_os("SHOW").is_some() {
            println!("{text}");
        }
    }
}
