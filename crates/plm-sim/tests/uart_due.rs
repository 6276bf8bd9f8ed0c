//! When the bytes on a served node's UART have arrived
//! ([`Ports::uart_due_of`]): the one instant of a run of bytes that a host
//! answering the modem's frames must look at at once, where each byte is
//! an event of the world of its own.

use plm_core::time::MS;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::{Ports, Sim, SimConfig};

/// The host's bytes are due when the last reaches the modem; the modem's
/// status message when its last byte reaches the host; nothing when the
/// wires are idle.
fn the_ends_of_the_runs_both_ways(p: &mut dyn Ports) {
    p.advance_to(200 * MS);
    p.host_read_of(0);
    assert_eq!(p.uart_due_of(0), None, "idle wires");

    // No STX among them: nothing for the modem to take as a frame.
    p.write_to(0, &[0x55; 10]);
    let due = p.uart_due_of(0).expect("the host's bytes on their way");
    assert_eq!(due, 200 * MS + p.backlog_to_modem(0));
    assert!(
        p.next_deadline().is_some_and(|d| d < due),
        "each byte is an event of its own"
    );
    p.advance_to(due);
    assert_eq!(p.uart_due_of(0), None, "all in");

    p.set_treq_of(0, true);
    let due = loop {
        let next = p.next_deadline().expect("the modem answers T_REQ");
        p.advance_to(next);
        if let Some(due) = p.uart_due_of(0) {
            break due;
        }
    };
    p.advance_to(due);
    let status = p.host_read_of(0);
    assert!(status.len() >= 2, "the status message: {status:02X?}");
    assert_eq!(status.last().map(|b| b.0), Some(due), "{status:?}");
    assert_eq!(p.uart_due_of(0), None);
}

#[test]
fn an_st7580s_uart_is_due_at_the_end_of_each_run() {
    the_ends_of_the_runs_both_ways(&mut Sim::new(SimConfig::default()));
}

#[test]
fn an_st7570s_uart_is_due_at_the_end_of_each_run() {
    the_ends_of_the_runs_both_ways(&mut Network::new(NetConfig::served_line(1, 1, 1)));
}
