//! One source per input: a real bus carries several GNSS receivers (and several heading
//! sources) at once, whose positions differ by metres. The selector locks each input kind —
//! position, course/speed, heading, fix quality — on one source and drops the others' inputs.
//!
//! A kind's source is configured (by CAN address, by ISO 11783-5 NAME, or a stream input) or
//! chosen automatically: the first source whose fix quality reaches the required one (for the
//! position; heading and course/speed the first usable source), kept until it goes stale, then
//! the next. The fix quality follows the position's source unless configured. Every source seen
//! is listed for `agsteer status`. A change of source is reported (the node logs it and, unless
//! configured otherwise, disengages). It works on [`Input`]s, whatever carried them.
//!
//! Magnetic headings (most NMEA 2000 compasses and many 127250 senders) are refused unless the
//! policy allows applying the variation the same message carries (true = magnetic + variation,
//! positive East); a magnetic heading without variation is always refused.

use super::{FixQuality, HeadingReference, Input, SourceId};
use serde::Serialize;

/// The input kinds that are locked on one source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Position,
    CourseSpeed,
    Heading,
    Quality,
}

const KINDS: [Kind; 4] = [
    Kind::Position,
    Kind::CourseSpeed,
    Kind::Heading,
    Kind::Quality,
];

impl Kind {
    fn of(input: &Input) -> Option<Kind> {
        match input {
            Input::Position(_) => Some(Kind::Position),
            Input::CourseSpeed(_) => Some(Kind::CourseSpeed),
            Input::Heading(_) => Some(Kind::Heading),
            Input::Quality(_) => Some(Kind::Quality),
            _ => None,
        }
    }
    fn index(self) -> usize {
        self as usize
    }
}

/// How a kind's source is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Choice {
    /// The first suitable source, kept until stale.
    #[default]
    Auto,
    /// This source only.
    Source(SourceId),
    /// The CAN node with this ISO 11783-5 NAME, at whatever address it claimed.
    Name(u64),
}

/// What to do with a heading referred to magnetic North.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MagneticHeading {
    /// Drop it.
    #[default]
    Refuse,
    /// Use it with the variation the message carries (dropped when it carries none).
    ApplyVariation,
}

/// The selector's parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceParams {
    pub position: Choice,
    pub course_speed: Choice,
    pub heading: Choice,
    /// `Auto` follows the position's source.
    pub quality: Choice,
    /// A locked source that sent nothing of its kind for this long is dropped, s.
    pub stale_s: f64,
    /// The fix quality a source must report before automatic selection takes its positions.
    pub min_quality: FixQuality,
    pub magnetic: MagneticHeading,
    /// A change of source disengages the steering.
    pub disengage_on_change: bool,
}

impl Default for SourceParams {
    fn default() -> Self {
        SourceParams {
            position: Choice::Auto,
            course_speed: Choice::Auto,
            heading: Choice::Auto,
            quality: Choice::Auto,
            stale_s: 1.0,
            min_quality: FixQuality::Other,
            magnetic: MagneticHeading::Refuse,
            disengage_on_change: true,
        }
    }
}

/// A change of a kind's source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SourceChange {
    pub t: f64,
    pub kind: Kind,
    pub from: Option<SourceId>,
    pub to: SourceId,
}

/// One source seen on the inputs (for `agsteer status`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeenSource {
    pub source: SourceId,
    /// Its ISO 11783-5 NAME, once it claimed an address.
    pub name: Option<u64>,
    /// The kinds it sends (position, course_speed, heading, quality).
    pub kinds: [bool; 4],
    /// The kinds it is selected for.
    pub selected: [bool; 4],
    pub last_t: f64,
    /// Its last reported fix quality.
    pub quality: Option<FixQuality>,
    pub inputs: u64,
}

/// Sources listed at most (the rest are counted in [`SourceSelector::unlisted`]).
pub const MAX_LISTED: usize = 32;

/// The selector. Allocation happens only when a new source is first seen.
#[derive(Debug, Clone)]
pub struct SourceSelector {
    params: SourceParams,
    locked: [Option<(SourceId, f64)>; 4],
    /// The source each kind was last locked on (for the change report).
    previous: [Option<SourceId>; 4],
    seen: Vec<SeenSource>,
    unlisted: u64,
    /// NAME of each CAN address, from the address claims seen.
    names: Box<[Option<u64>; 256]>,
}

fn rank(q: FixQuality) -> u8 {
    match q {
        FixQuality::None => 0,
        FixQuality::Other => 1,
        FixQuality::RtkFloat => 2,
        FixQuality::RtkFixed => 3,
    }
}

impl SourceSelector {
    pub fn new(params: SourceParams) -> Self {
        SourceSelector {
            params,
            locked: [None; 4],
            previous: [None; 4],
            seen: Vec::new(),
            unlisted: 0,
            names: Box::new([None; 256]),
        }
    }

    /// New parameters; a kind whose choice changed is unlocked.
    pub fn set_params(&mut self, params: SourceParams) {
        for k in KINDS {
            if self.choice(k) != choice_of(&params, k) {
                self.locked[k.index()] = None;
            }
        }
        self.params = params;
    }

    pub fn params(&self) -> &SourceParams {
        &self.params
    }

    fn choice(&self, k: Kind) -> Choice {
        choice_of(&self.params, k)
    }

    /// A CAN node claimed `address` with `name` (ISO 11783-5 address claim).
    pub fn on_address_claim(&mut self, address: u8, name: u64) {
        // Another node at this NAME's old address is no longer it.
        for n in self.names.iter_mut() {
            if *n == Some(name) {
                *n = None;
            }
        }
        self.names[address as usize] = Some(name);
        for s in self.seen.iter_mut() {
            if s.source == SourceId::Can(address) {
                s.name = Some(name);
            }
        }
    }

    /// The NAME of a source, if known.
    pub fn name_of(&self, source: SourceId) -> Option<u64> {
        match source {
            SourceId::Can(a) => self.names[a as usize],
            _ => None,
        }
    }

    /// Every source seen, in order of first appearance.
    pub fn seen(&self) -> &[SeenSource] {
        &self.seen
    }

    /// Sources seen beyond [`MAX_LISTED`].
    pub fn unlisted(&self) -> u64 {
        self.unlisted
    }

    /// The source a kind is locked on.
    pub fn selected(&self, kind: Kind) -> Option<SourceId> {
        self.locked[kind.index()].map(|(s, _)| s)
    }

    fn note(&mut self, input: &Input, kind: Kind) {
        let source = input.source();
        let name = self.name_of(source);
        let idx = match self.seen.iter().position(|s| s.source == source) {
            Some(i) => i,
            None if self.seen.len() < MAX_LISTED => {
                self.seen.push(SeenSource {
                    source,
                    name,
                    kinds: [false; 4],
                    selected: [false; 4],
                    last_t: input.t(),
                    quality: None,
                    inputs: 0,
                });
                self.seen.len() - 1
            }
            None => {
                self.unlisted += 1;
                return;
            }
        };
        let s = &mut self.seen[idx];
        s.kinds[kind.index()] = true;
        s.last_t = input.t();
        s.inputs += 1;
        match input {
            Input::Quality(q) => s.quality = Some(q.quality),
            Input::Position(p) => {
                if let Some(q) = p.quality {
                    s.quality = Some(q);
                }
            }
            _ => {}
        }
    }

    fn quality_of(&self, source: SourceId) -> Option<FixQuality> {
        self.seen
            .iter()
            .find(|s| s.source == source)
            .and_then(|s| s.quality)
    }

    /// Whether `source` may be chosen for `kind` now (a configured one always; an automatic
    /// one when suitable).
    fn suitable(&self, kind: Kind, input: &Input) -> bool {
        let source = input.source();
        match self.choice(kind) {
            Choice::Source(s) => s == source,
            Choice::Name(n) => self.name_of(source) == Some(n),
            // Position and quality go together: the first source whose fix quality reaches
            // the minimum, whichever of its two inputs comes first (129029 and 129025 are
            // separate messages; a GGA carries both).
            Choice::Auto => {
                let good = self
                    .quality_of(source)
                    .is_some_and(|q| rank(q) >= rank(self.params.min_quality).max(1));
                let partner = match kind {
                    Kind::Position => Some(Kind::Quality),
                    Kind::Quality => Some(Kind::Position),
                    Kind::Heading | Kind::CourseSpeed => None,
                };
                match partner {
                    None => true,
                    Some(p) if self.choice(p) == Choice::Auto => {
                        match self.locked[p.index()]
                            .filter(|(_, last)| input.t() - last <= self.params.stale_s)
                        {
                            Some((s, _)) => s == source,
                            None => good,
                        }
                    }
                    Some(_) => good,
                }
            }
        }
    }

    /// The input as the controller should take it (a magnetic heading corrected, or `None`
    /// when it is dropped), and a change of source if this input caused one.
    pub fn select(&mut self, input: &Input) -> (Option<Input>, Option<SourceChange>) {
        let Some(kind) = Kind::of(input) else {
            return (Some(*input), None);
        };
        self.note(input, kind);
        let t = input.t();
        let source = input.source();
        let input = match self.usable(input) {
            Some(i) => i,
            None => return (None, None),
        };
        let k = kind.index();
        // A configured choice that no longer matches (a NAME moved) unlocks.
        if let Some((s, last)) = self.locked[k] {
            let keep = match self.choice(kind) {
                Choice::Auto => t - last <= self.params.stale_s,
                Choice::Source(c) => c == s,
                Choice::Name(n) => self.name_of(s) == Some(n),
            };
            if !keep {
                self.locked[k] = None;
                self.mark(s, kind, false);
            }
        }
        match self.locked[k] {
            Some((s, _)) if s == source => {
                self.locked[k] = Some((s, t));
                (Some(input), None)
            }
            Some(_) => (None, None),
            None => {
                if !self.suitable(kind, &input) {
                    return (None, None);
                }
                let from = self.previous[k];
                self.previous[k] = Some(source);
                self.locked[k] = Some((source, t));
                self.mark(source, kind, true);
                let change = SourceChange {
                    t,
                    kind,
                    from,
                    to: source,
                };
                (Some(input), Some(change))
            }
        }
    }

    fn mark(&mut self, source: SourceId, kind: Kind, on: bool) {
        for s in self.seen.iter_mut() {
            if on {
                s.selected[kind.index()] = s.source == source;
            } else if s.source == source {
                s.selected[kind.index()] = false;
            }
        }
    }

    /// A heading is usable when true, or magnetic with its variation and the policy allows.
    fn usable(&self, input: &Input) -> Option<Input> {
        let Input::Heading(h) = input else {
            return Some(*input);
        };
        match (h.reference, self.params.magnetic, h.variation) {
            (HeadingReference::True, _, _) => Some(*input),
            (HeadingReference::Magnetic, MagneticHeading::ApplyVariation, Some(v)) => {
                let mut h = *h;
                // Yaw is counter-clockwise from East: a variation East (clockwise) lowers it.
                h.heading = crate::geo::wrap_angle(h.heading - v);
                h.reference = HeadingReference::True;
                h.variation = None;
                Some(Input::Heading(h))
            }
            _ => None,
        }
    }
}

fn choice_of(p: &SourceParams, k: Kind) -> Choice {
    match k {
        Kind::Position => p.position,
        Kind::CourseSpeed => p.course_speed,
        Kind::Heading => p.heading,
        Kind::Quality => p.quality,
    }
}

#[cfg(test)]
mod tests;
