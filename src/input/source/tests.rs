use super::*;
use crate::input::{HeadingInput, PositionInput, QualityInput};

const A: SourceId = SourceId::Can(0x1C);
const B: SourceId = SourceId::Can(0x80);

fn position(t: f64, source: SourceId, lat_deg: f64) -> Input {
    Input::Position(PositionInput {
        t,
        source,
        lat_deg,
        lon_deg: 5.0,
        altitude_m: None,
        latency_s: None,
        quality: None,
    })
}

fn quality(t: f64, source: SourceId, quality: FixQuality) -> Input {
    Input::Quality(QualityInput {
        t,
        source,
        quality,
        satellites: None,
        hdop: None,
        correction_age_s: None,
        horizontal_sigma_m: None,
    })
}

fn heading(t: f64, source: SourceId, reference: HeadingReference, variation: Option<f64>) -> Input {
    Input::Heading(HeadingInput {
        t,
        source,
        heading: 1.0,
        reference,
        variation,
    })
}

fn lat(i: Option<Input>) -> Option<f64> {
    match i {
        Some(Input::Position(p)) => Some(p.lat_deg),
        _ => None,
    }
}

#[test]
fn two_receivers_the_first_with_a_fix_is_kept_the_other_ignored_and_listed() {
    let mut s = SourceSelector::new(SourceParams::default());
    // B's positions come first but B has no fix quality yet: not taken.
    assert_eq!(lat(s.select(&position(0.0, B, 52.1)).0), None);
    let (q, change) = s.select(&quality(0.05, A, FixQuality::RtkFixed));
    assert!(q.is_some());
    assert_eq!(
        change.map(|c| (c.kind, c.from, c.to)),
        Some((Kind::Quality, None, A))
    );
    let (p, change) = s.select(&position(0.1, A, 52.0));
    assert_eq!(lat(p), Some(52.0));
    assert_eq!(change.map(|c| c.kind), Some(Kind::Position));
    for k in 1..50 {
        let t = 0.1 + k as f64 * 0.1;
        assert!(s.select(&quality(t, B, FixQuality::RtkFixed)).0.is_none());
        assert_eq!(lat(s.select(&position(t, B, 52.1)).0), None, "B ignored");
        let (p, change) = s.select(&position(t, A, 52.0));
        assert_eq!((lat(p), change), (Some(52.0), None), "A kept");
    }
    let seen = s.seen();
    assert_eq!(seen.len(), 2);
    let a = seen.iter().find(|x| x.source == A).unwrap();
    let b = seen.iter().find(|x| x.source == B).unwrap();
    assert!(a.selected[Kind::Position as usize] && !b.selected[Kind::Position as usize]);
    assert!(b.kinds[Kind::Position as usize] && b.kinds[Kind::Quality as usize]);
    assert_eq!(b.quality, Some(FixQuality::RtkFixed));
}

#[test]
fn a_stale_source_is_replaced_and_the_change_reported() {
    let mut s = SourceSelector::new(SourceParams::default());
    s.select(&quality(0.0, A, FixQuality::RtkFixed));
    s.select(&position(0.0, A, 52.0));
    s.select(&quality(0.0, B, FixQuality::RtkFloat));
    // A stops; B within the stale time is still ignored.
    assert_eq!(lat(s.select(&position(0.9, B, 52.1)).0), None);
    let (p, change) = s.select(&position(1.2, B, 52.1));
    assert_eq!(lat(p), Some(52.1));
    let c = change.unwrap();
    assert_eq!((c.kind, c.from, c.to), (Kind::Position, Some(A), B));
    // A comes back: B is kept (sticky).
    s.select(&quality(1.3, A, FixQuality::RtkFixed));
    assert_eq!(lat(s.select(&position(1.3, A, 52.0)).0), None);
    assert_eq!(s.selected(Kind::Position), Some(B));
}

#[test]
fn a_configured_address_or_name_is_the_only_source() {
    let mut s = SourceSelector::new(SourceParams {
        position: Choice::Source(B),
        quality: Choice::Source(B),
        ..SourceParams::default()
    });
    s.select(&quality(0.0, A, FixQuality::RtkFixed));
    assert_eq!(lat(s.select(&position(0.0, A, 52.0)).0), None);
    assert_eq!(lat(s.select(&position(0.1, B, 52.1)).0), Some(52.1));
    // By NAME: the receiver claimed 0x80, later re-claims at 0x81.
    let name = 0xA00C_8100_0020_0001;
    let mut s = SourceSelector::new(SourceParams {
        position: Choice::Name(name),
        quality: Choice::Name(name),
        ..SourceParams::default()
    });
    assert_eq!(
        lat(s.select(&position(0.0, B, 52.1)).0),
        None,
        "NAME not known yet"
    );
    s.on_address_claim(0x80, name);
    assert_eq!(lat(s.select(&position(0.1, B, 52.1)).0), Some(52.1));
    assert_eq!(s.seen()[0].name, Some(name));
    s.on_address_claim(0x81, name);
    assert_eq!(
        lat(s.select(&position(0.2, B, 52.1)).0),
        None,
        "0x80 is no longer it"
    );
    let (p, change) = s.select(&position(0.3, SourceId::Can(0x81), 52.1));
    assert_eq!(lat(p), Some(52.1));
    assert_eq!(change.unwrap().from, Some(B));
}

#[test]
fn magnetic_headings_are_refused_or_corrected_by_the_variation() {
    let mut s = SourceSelector::new(SourceParams::default());
    assert!(s
        .select(&heading(0.0, A, HeadingReference::Magnetic, Some(0.1)))
        .0
        .is_none());
    assert!(s
        .select(&heading(0.0, A, HeadingReference::Unknown, None))
        .0
        .is_none());
    assert!(s
        .select(&heading(0.0, A, HeadingReference::True, None))
        .0
        .is_some());
    let mut s = SourceSelector::new(SourceParams {
        magnetic: MagneticHeading::ApplyVariation,
        ..SourceParams::default()
    });
    assert!(s
        .select(&heading(0.0, A, HeadingReference::Magnetic, None))
        .0
        .is_none());
    let Some(Input::Heading(h)) = s
        .select(&heading(0.0, A, HeadingReference::Magnetic, Some(0.1)))
        .0
    else {
        panic!()
    };
    // 0.1 rad East of magnetic North: the true heading is 0.1 rad further clockwise.
    assert!((h.heading - 0.9).abs() < 1e-12);
    assert_eq!(h.reference, HeadingReference::True);
}

#[test]
fn a_serial_receiver_whose_positions_carry_their_quality_is_selected() {
    let mut s = SourceSelector::new(SourceParams::default());
    let mut p = position(0.0, SourceId::Stream(0), 52.0);
    if let Input::Position(ref mut x) = p {
        x.quality = Some(FixQuality::RtkFloat);
    }
    assert_eq!(lat(s.select(&p).0), Some(52.0));
    // Below the minimum quality: a source is not chosen.
    let mut s = SourceSelector::new(SourceParams {
        min_quality: FixQuality::RtkFixed,
        ..SourceParams::default()
    });
    assert_eq!(lat(s.select(&p).0), None);
}
