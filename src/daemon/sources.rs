//! The status reply's `sources` object: every GNSS source seen and the one each input is
//! locked on.

use serde::Serialize;

/// One source seen, for the status reply.
#[derive(Serialize)]
pub struct SourceReply {
    source: crate::input::SourceId,
    /// Its ISO 11783-5 NAME (hex), once it claimed an address.
    name: Option<String>,
    /// The inputs it sends, and those it is selected for.
    sends: Vec<crate::input::source::Kind>,
    selected_for: Vec<crate::input::source::Kind>,
    quality: Option<crate::input::FixQuality>,
    inputs: u64,
    last_s_ago: f64,
}

#[derive(Serialize)]
pub struct SourcesReply {
    /// The source each input is locked on (null: none yet).
    position: Option<crate::input::SourceId>,
    course_speed: Option<crate::input::SourceId>,
    heading: Option<crate::input::SourceId>,
    quality: Option<crate::input::SourceId>,
    seen: Vec<SourceReply>,
    /// Sources past the listed ones.
    unlisted: u64,
}

pub fn sources_reply(sel: &crate::input::source::SourceSelector, now: f64) -> SourcesReply {
    use crate::input::source::Kind;
    const KINDS: [Kind; 4] = [
        Kind::Position,
        Kind::CourseSpeed,
        Kind::Heading,
        Kind::Quality,
    ];
    let pick = |flags: &[bool; 4]| {
        KINDS
            .iter()
            .zip(flags)
            .filter(|(_, on)| **on)
            .map(|(k, _)| *k)
            .collect()
    };
    SourcesReply {
        position: sel.selected(Kind::Position),
        course_speed: sel.selected(Kind::CourseSpeed),
        heading: sel.selected(Kind::Heading),
        quality: sel.selected(Kind::Quality),
        seen: sel
            .seen()
            .iter()
            .map(|s| SourceReply {
                source: s.source,
                name: s.name.map(|n| format!("{n:016X}")),
                sends: pick(&s.kinds),
                selected_for: pick(&s.selected),
                quality: s.quality,
                inputs: s.inputs,
                last_s_ago: (now - s.last_t).max(0.0),
            })
            .collect(),
        unlisted: sel.unlisted(),
    }
}
