//! A purge of a served host's transmit side ([`Ports::purge_to_modem`]):
//! what the host wrote and the modem has not yet received is lost, a
//! T_REQ change waiting behind it comes at once, and the modem runs on.

use plm_core::time::MS;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::{Ports, Sim, SimConfig};

/// The bytes that reached node 0's host by now.
fn read(p: &mut dyn Ports) -> Vec<u8> {
    p.host_read_of(0).into_iter().map(|(_, b)| b).collect()
}

/// Noise fills node 0's UART for about 0.7 s at 57600 baud; T_REQ
/// asserted behind it is not seen while it drains, and is at once when
/// the host purges what it wrote.
fn t_req_waits_for_the_noise_until_purged(p: &mut dyn Ports) {
    p.advance_to(200 * MS);
    read(p); // the reset indication
             // No STX among them: nothing for the modem to take as a frame.
    p.write_to(0, &[0x55; 4096]);
    let backlog = p.backlog_to_modem(0);
    assert!(
        (700 * MS..720 * MS).contains(&backlog),
        "4096 bytes at 57600 baud: {backlog} µs"
    );
    p.set_treq_of(0, true);
    p.advance_to(300 * MS);
    assert!(read(p).is_empty(), "T_REQ seen before the bytes before it");
    p.purge_to_modem(0);
    assert_eq!(p.backlog_to_modem(0), 0);
    p.advance_to(320 * MS);
    let got = read(p);
    assert_eq!(got.first(), Some(&0x3F), "the status message: {got:02X?}");
    // The noise is gone for good: nothing more comes when it would have
    // drained.
    p.set_treq_of(0, false);
    p.advance_to(1_500 * MS);
    assert!(read(p).is_empty());
}

/// The status message on its way to the host is not heard after a purge
/// of the host's receive side.
fn what_is_on_the_way_to_the_host_is_purged(p: &mut dyn Ports) {
    p.advance_to(200 * MS);
    read(p);
    p.set_treq_of(0, true);
    p.advance_to(200 * MS + 100);
    p.purge_to_host(0);
    p.advance_to(300 * MS);
    assert!(read(p).is_empty(), "heard after the purge");
}

#[test]
fn a_hosts_receive_purge_drops_what_is_on_its_way() {
    what_is_on_the_way_to_the_host_is_purged(&mut Sim::new(SimConfig::default()));
    what_is_on_the_way_to_the_host_is_purged(&mut Network::new(NetConfig::served_line(1, 1, 1)));
}

#[test]
fn an_st7580_hosts_purge_drops_its_bytes_in_flight() {
    let mut sim = Sim::new(SimConfig::default());
    t_req_waits_for_the_noise_until_purged(&mut sim);
    // The modem ran on: no second reset indication, and it answers.
    sim.set_treq_of(0, true);
    sim.advance_to(1_520 * MS);
    assert_eq!(read(&mut sim).first(), Some(&0x3F));
}

#[test]
fn an_st7570_hosts_purge_drops_its_bytes_in_flight() {
    let mut net = Network::new(NetConfig::served_line(1, 1, 1));
    t_req_waits_for_the_noise_until_purged(&mut net);
}
