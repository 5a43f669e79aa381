//! A Beckhoff EM2042 (16 digital outputs, fixed PDOs, no mailbox) on EtherCAT, with ethercrab:
//! `cargo run -p odc-examples --features ethercrab --example ethercat_em2042 -- eth0`.
//!
//! Its ESI is the corpus's `esi/beckhoff__Beckhoff_EM2xxx.xml`: the generated `pdi::Outputs`
//! is the terminal's 2-byte image (sync managers 0 and 1, 8 one-bit PDOs each), so the program
//! writes named channels instead of bit masks. The terminal's PDOs are fixed and it has no
//! CoE, so its start-up only checks the identity. A running light, one channel per 100 ms.

use std::error::Error;

#[cfg(not(odc_no_corpus))]
fn main() -> Result<(), Box<dyn Error>> {
    let interface = std::env::args().nth(1).ok_or("usage: ethercat_em2042 <interface>")?;
    smol::block_on(app::run(&interface))
}

#[cfg(odc_no_corpus)]
fn main() -> Result<(), Box<dyn Error>> {
    Err("built without the corpus (its ESI): set ODC_CORPUS and rebuild".into())
}

#[cfg(not(odc_no_corpus))]
mod app {
    use std::error::Error;
    use std::sync::Arc;
    use std::time::Duration;

    use ethercrab::std::{ethercat_now, tx_rx_task};
    use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
    use odc::ethercat::ethercrab::{ConfigureError, wire::EtherCrabWireWrite};

    /// The master side of the EM2042's ESI.
    mod em2042 {
        odc::include_od!("em2042");
    }
    use em2042::{pdi, startup};

    const MAX_SUBDEVICES: usize = 16;
    const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
    const MAX_FRAMES: usize = 16;
    const PDI_LEN: usize = 64;
    static PDU_STORAGE: PduStorage<MAX_FRAMES, MAX_PDU_DATA> = PduStorage::new();

    /// Channel `n` (0..16) on, the others off.
    fn light(n: usize) -> pdi::Outputs {
        let mut o = pdi::Outputs::default();
        let channels = [
            &mut o.channel_1_output,
            &mut o.channel_2_output,
            &mut o.channel_3_output,
            &mut o.channel_4_output,
            &mut o.channel_5_output,
            &mut o.channel_6_output,
            &mut o.channel_7_output,
            &mut o.channel_8_output,
            &mut o.channel_9_output,
            &mut o.channel_10_output,
            &mut o.channel_11_output,
            &mut o.channel_12_output,
            &mut o.channel_13_output,
            &mut o.channel_14_output,
            &mut o.channel_15_output,
            &mut o.channel_16_output,
        ];
        for (i, c) in channels.into_iter().enumerate() {
            *c = i == n;
        }
        o
    }

    pub async fn run(interface: &str) -> Result<(), Box<dyn Error>> {
        let (tx, rx, pdu_loop) = PDU_STORAGE.try_split().map_err(|()| "PDU storage split twice")?;
        let maindevice =
            Arc::new(MainDevice::new(pdu_loop, Timeouts::default(), MainDeviceConfig::default()));
        smol::spawn(tx_rx_task(interface, tx, rx)?).detach();

        let group = maindevice.init_single_group::<MAX_SUBDEVICES, PDI_LEN>(ethercat_now).await?;
        let mut terminal = None;
        for (i, sd) in group.iter(&maindevice).enumerate() {
            match startup::configure(&sd).await {
                Ok(()) => terminal = Some(i),
                Err(ConfigureError::WrongDevice { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
        let terminal = terminal.ok_or("no EM2042 on the bus")?;
        let group = group.into_op(&maindevice).await?;
        {
            let sd = group.subdevice(&maindevice, terminal)?;
            // ethercrab sized the image from the SII: the ESI's layout must agree.
            if sd.outputs_raw().len() != pdi::OUTPUT_LEN {
                return Err("the terminal's output image is not the ESI's".into());
            }
        }
        let mut tick = smol::Timer::interval(Duration::from_millis(100));
        for step in 0..160 {
            group.tx_rx(&maindevice).await?;
            let sd = group.subdevice(&maindevice, terminal)?;
            light(step % 16).pack_to_slice(&mut sd.outputs_raw_mut())?;
            smol::stream::StreamExt::next(&mut tick).await;
        }
        let group = group.into_safe_op(&maindevice).await?;
        let group = group.into_pre_op(&maindevice).await?;
        group.into_init(&maindevice).await?;
        Ok(())
    }
}
