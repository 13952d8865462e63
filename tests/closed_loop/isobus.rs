//! The controller node as an ISO 11783 node, in process: its address claim (ISO 11783-5) seen
//! from the bus — claim before anything else, Request for Address Claimed answered, a second
//! claimant with a lower NAME, Cannot Claim — and the steer-ready loop over the ISO 11783-7
//! messages only. The same behaviours run on SocketCAN in the VM suite (vcan_tests).

use agsteer::can::isobus::{
    address_claimed, read, request, Name, NameFields, NetworkFrame, GLOBAL_ADDRESS, NULL_ADDRESS,
    PGN_ADDRESS_CLAIMED,
};
use agsteer::can::{Frame, TimedFrame};
use agsteer::config::Config;
use agsteer::control::node::ControllerNode;
use agsteer::safety::FaultCode;

fn config(overrides: &[&str]) -> Config {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo.toml");
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Config::load(std::path::Path::new(path), &o).unwrap()
}

/// The node ticked every control period from `t0` to `t1`, with `inject` (time, frame) frames
/// delivered before the tick they fall in; returns every frame sent with its time.
fn run(
    node: &mut ControllerNode,
    dt: f64,
    t0: f64,
    t1: f64,
    inject: &[(f64, Frame)],
) -> Vec<(f64, Frame)> {
    let mut sent = Vec::new();
    let mut out = Vec::new();
    let mut k = 0u64;
    loop {
        let t = t0 + k as f64 * dt;
        if t > t1 + 1e-9 {
            break;
        }
        for (ti, f) in inject {
            if *ti > t - dt && *ti <= t {
                node.on_frame(&TimedFrame { t: *ti, frame: *f });
            }
        }
        out.clear();
        node.tick(t, &mut out);
        sent.extend(out.iter().map(|f| (t, *f)));
        k += 1;
    }
    sent
}

fn name(self_configurable: bool, identity: u32) -> Name {
    Name::new(&NameFields {
        self_configurable,
        identity_number: identity,
        ..NameFields::GUIDANCE_CONTROLLER
    })
}

#[test]
fn claims_before_any_other_frame_and_answers_a_request() {
    let cfg = config(&[]);
    let dt = cfg.dt();
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    let sent = run(&mut node, dt, 0.0, 2.0, &[]);
    // The first frame is the Request for Address Claimed, the second our claim of the
    // preferred address; every other frame comes 250 ms after it, from that address.
    let first = read(&sent[0].1);
    assert!(
        matches!(
            first,
            Some(NetworkFrame::Request {
                pgn: PGN_ADDRESS_CLAIMED,
                dest: GLOBAL_ADDRESS,
                source: NULL_ADDRESS
            })
        ),
        "{first:?}"
    );
    let (t_claim, claim) = sent[1];
    assert_eq!(
        read(&claim),
        Some(NetworkFrame::AddressClaimed {
            name: cfg.isobus.name(),
            source: cfg.bus.source_address
        })
    );
    let (t_app, app) = sent[2];
    assert!(t_app >= t_claim + 0.25 - 1e-9, "{t_app} vs claim {t_claim}");
    assert_eq!(app.source(), cfg.bus.source_address);
    assert!(sent[2..].iter().all(|(_, f)| read(f).is_none()));
    // Claimed: the fault is no longer the address (no GNSS in this test).
    assert_eq!(node.status().fault, FaultCode::GnssTimeout);

    // A Request for Address Claimed, to everyone: answered with the claim, once.
    let req = request(PGN_ADDRESS_CLAIMED, 0x80, GLOBAL_ADDRESS);
    let sent = run(&mut node, dt, 2.02, 2.5, &[(2.03, req)]);
    let claims: Vec<_> = sent
        .iter()
        .filter(|(_, f)| matches!(read(f), Some(NetworkFrame::AddressClaimed { .. })))
        .collect();
    assert_eq!(claims.len(), 1, "{claims:?}");
    assert!(claims[0].0 <= 2.04 + 1e-9, "answered in the next period");
    // Steering and status frames carry on.
    assert!(sent.iter().any(|(t, f)| *t > 2.1 && read(f).is_none()));
}

#[test]
fn a_second_claimant_with_a_lower_name_moves_us_and_a_fixed_name_goes_silent() {
    let cfg = config(&[]);
    let dt = cfg.dt();
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    run(&mut node, dt, 0.0, 1.0, &[]);
    let ours = cfg.isobus.name();
    // A higher NAME claims 0x2A: we keep it (our claim again).
    let higher = Name(ours.0 + 1);
    let sent = run(
        &mut node,
        dt,
        1.02,
        1.5,
        &[(1.03, address_claimed(higher, 0x2A))],
    );
    assert!(sent.iter().any(|(_, f)| *f == address_claimed(ours, 0x2A)));
    assert!(sent
        .iter()
        .all(|(_, f)| f.source() == 0x2A || f.source() == NULL_ADDRESS));
    // A lower NAME claims it: we claim the first address of the range and send nothing else
    // for 250 ms; the status says the address was lost meanwhile.
    let lower = Name(ours.0 - 1);
    let sent = run(
        &mut node,
        dt,
        1.52,
        3.0,
        &[(1.53, address_claimed(lower, 0x2A))],
    );
    let (t_move, _) = *sent
        .iter()
        .find(|(_, f)| *f == address_claimed(ours, 128))
        .expect("claims 128");
    assert!(
        sent.iter().all(|(t, f)| *t < 1.53 || f.source() != 0x2A),
        "nothing more from 0x2A"
    );
    let app: Vec<_> = sent
        .iter()
        .filter(|(t, f)| *t > 1.53 && read(f).is_none())
        .collect();
    assert!(!app.is_empty());
    assert!(app
        .iter()
        .all(|(t, f)| *t >= t_move + 0.25 - 1e-9 && f.source() == 128));
    assert_eq!(node.status().isobus.address_losses, 1);

    // Not self-configurable: Cannot Claim, then silence, and the fault says why.
    let cfg = config(&["isobus.self_configurable=false"]);
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    run(&mut node, dt, 0.0, 1.0, &[]);
    let lower = name(false, 0);
    assert!(lower < cfg.isobus.name());
    let sent = run(
        &mut node,
        dt,
        1.02,
        3.0,
        &[(1.03, address_claimed(lower, 0x2A))],
    );
    let sent: Vec<_> = sent.into_iter().filter(|(t, _)| *t > 1.03).collect();
    assert_eq!(sent.len(), 1, "{sent:?}");
    assert_eq!(sent[0].1, address_claimed(cfg.isobus.name(), NULL_ADDRESS));
    let st = node.status();
    assert!(matches!(
        st.state,
        agsteer::safety::SafetyState::Disengaged | agsteer::safety::SafetyState::Fault(_)
    ));
    assert_eq!(st.fault, FaultCode::AddressLost);
}

#[test]
fn without_address_claim_frames_go_out_at_once() {
    let cfg = config(&["isobus.address_claim=false"]);
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    let sent = run(&mut node, cfg.dt(), 0.0, 0.1, &[]);
    assert!(sent.iter().all(|(_, f)| read(f).is_none()));
    assert_eq!(sent[0].0, 0.0);
}

/// An AB job closed-loop over the ISO 11783-7 messages only (the simulator's steer-ready
/// tractor: Guidance System Command in, Guidance Machine Info out, no wheel-angle frame),
/// against the same job with the proprietary angle frames.
#[test]
fn steer_ready_loop_drives_the_job_within_twice_the_angle_mode_xte() {
    use agsteer::demo::{run, DemoOptions};
    let angle = config(&["job.line_num=3"]);
    let iso = config(&["job.line_num=3", "bus.output=\"curvature\""]);
    let go = |cfg: &Config| run(cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    let a = go(&angle);
    let b = go(&iso);
    println!(
        "STEER-READY xte_rms angle {:.4} m iso {:.4} m; p95 {:.4} / {:.4}; max {:.4} / {:.4}; disengagements {:?}",
        a.report.xte_rms_m,
        b.report.xte_rms_m,
        a.report.xte_p95_m,
        b.report.xte_p95_m,
        a.report.xte_max_m,
        b.report.xte_max_m,
        b.disengage_events
    );
    assert!(a.report.finished && b.report.finished, "{:?}", b.report);
    assert_eq!(b.report.lines_completed, a.report.lines_completed);
    // No disengagement but the job's end (no guidance once finished).
    assert!(
        b.disengage_events.iter().all(|(_, c)| c == "no_guidance"),
        "{:?}",
        b.disengage_events
    );
    assert!(
        b.report.xte_rms_m <= 2.0 * a.report.xte_rms_m,
        "iso {} vs angle {}",
        b.report.xte_rms_m,
        a.report.xte_rms_m
    );
    assert!(b.report.xte_p95_m <= 2.0 * a.report.xte_p95_m);
}

/// The steer-ready tractor's gate: a lockout stops steering (fault steering_lockout), an
/// operator override makes its ECU request a reset, which the node honours (not intended to
/// steer) before the operator engages again.
#[test]
fn steer_ready_lockout_and_request_reset_stop_steering_until_cleared() {
    use agsteer::demo::{run, DemoOptions};
    use agsteer::sim::can_node::{Fault, FaultKind, Scenario};
    let cfg = config(&["job.line_num=2", "bus.output=\"curvature\""]);
    for (kind, code) in [
        (FaultKind::SteeringLockout, "steering_lockout"),
        (FaultKind::OperatorOverride, "steering_reset_requested"),
    ] {
        let opts = DemoOptions {
            scenario: Scenario {
                fault: vec![Fault {
                    kind,
                    at_s: 20.0,
                    duration_s: 1.0,
                }],
            },
            ..Default::default()
        };
        let r = run(&cfg, &opts, &mut |_| {}, &mut |_, _| {}).unwrap();
        let after: Vec<_> = r
            .disengage_events
            .iter()
            .filter(|(t, _)| *t >= 20.0)
            .collect();
        println!("STEER-READY {kind:?}: {after:?}");
        let (t, c) = after.first().expect("disengaged");
        assert_eq!(c, code);
        // Within two Machine Info periods and a control period.
        assert!(*t - 20.0 <= 0.2 + cfg.dt() + 1e-9, "{t}");
        // Engaged again once cleared: the job finishes.
        assert!(r.report.finished, "{:?}", r.report);
    }
}
