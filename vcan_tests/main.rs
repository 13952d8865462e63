//! Tests that need a real CAN interface. They run inside the qemu VM (`tools/vcan-vm`) with
//! `AGSTEER_VCAN=vcan0`; elsewhere each test prints "skipped" and passes.

mod support;

use agsteer::can::bus::{CanBus, Filter, SocketCanBus};
use agsteer::can::Frame;
use std::time::{Duration, Instant};
use support::*;

#[test]
fn frames_round_trip_and_filters_drop_others() {
    let Some(iface) = vcan() else { return };
    let mut tx = SocketCanBus::open(&iface, &[]).unwrap();
    let mut rx = SocketCanBus::open(
        &iface,
        &[Filter {
            id: 0x0CFF1000,
            mask: 0x03FFFF00,
        }],
    )
    .unwrap();
    tx.send(&Frame::new(0x0CFF2A2A, &[9, 9])).unwrap();
    tx.send(&Frame::new(0x0CFF1013, &[1, 2, 3, 4, 5, 6, 7, 8]))
        .unwrap();
    let f = recv_within(&mut rx, Duration::from_secs(1)).expect("filtered frame arrives");
    assert_eq!(f.frame.id, 0x0CFF1013);
    assert_eq!(f.frame.payload(), &[1, 2, 3, 4, 5, 6, 7, 8]);
    assert!(
        recv_within(&mut rx, Duration::from_millis(100)).is_none(),
        "0CFF2A2A is filtered out"
    );
}

#[test]
fn cansend_and_candump_interoperate() {
    let Some(iface) = vcan() else { return };
    let mut rx = SocketCanBus::open(&iface, &[]).unwrap();
    run_ok("cansend", &[&iface, "0CFF202A#0102030405060708"]);
    let f = recv_within(&mut rx, Duration::from_secs(1)).expect("cansend frame");
    assert_eq!(f.frame.id, 0x0CFF202A);
    let dump = Candump::start(&iface);
    std::thread::sleep(Duration::from_millis(200));
    let mut tx = SocketCanBus::open(&iface, &[]).unwrap();
    tx.send(&Frame::new(0x18FF212A, &[0xAA, 0xBB])).unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let lines = dump.stop();
    assert!(
        lines.iter().any(|l| l.contains("18FF212A#AABB")),
        "{lines:?}"
    );
}

#[test]
fn echo_round_trip_baseline() {
    let Some(iface) = vcan() else { return };
    let (median, p99) = echo_latency(&iface, 2000);
    println!(
        "ECHO-LATENCY median_us={:.1} p99_us={:.1}",
        median * 1e6,
        p99 * 1e6
    );
    assert!(median < 0.05);
}

/// Wait for a frame.
fn recv_within(bus: &mut SocketCanBus, d: Duration) -> Option<agsteer::can::TimedFrame> {
    let end = Instant::now() + d;
    while Instant::now() < end {
        if let Ok(Some(f)) = bus.try_recv() {
            return Some(f);
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    None
}
