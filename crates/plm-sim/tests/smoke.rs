use plm_core::st7580::{Command, ResetCause};
use plm_core::time::MS;
use plm_sim::{HostDriver, Outcome, Sim, SimConfig};

#[test]
fn powers_on_and_answers_ping_and_mib_read() {
    let mut d = HostDriver::new(Sim::new(SimConfig::default()));
    d.run_for(100 * MS);
    let frames = d.frames();
    assert!(
        matches!(&frames[..], [Command::BioResetIndication(r)] if r.reset_cause == ResetCause::PowerOn),
        "{frames:?}"
    );
    let out = d.request(
        &Command::PingRequest {
            data: vec![1, 2, 3],
        },
        500 * MS,
    );
    assert_eq!(
        out,
        Outcome::Answer(Command::PingConfirm {
            data: vec![1, 2, 3]
        })
    );
    let out = d.request(&Command::MibReadRequest { index: 0x0A }, 500 * MS);
    assert_eq!(
        out,
        Outcome::Answer(Command::MibReadConfirm {
            data: vec![0x00, 0x42, 0x00, 0x97]
        })
    );
}
