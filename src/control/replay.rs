//! Replay: the controller node run offline on a recorded bus log, as fast as it computes.
//!
//! The frames of the log are fed to the node in order with their time stamps. Control periods
//! come from one of two sources:
//! - [`Ticks::Logged`]: a log written by `agsteerd --bus-log` holds agsteer's own frames (its
//!   source address, messages agsteer transmits). Each run of them with one time stamp is one
//!   control period the daemon ran at that time; the replay runs the node at the same time
//!   and compares the frames it sends with the logged ones, so a replay of the same build and
//!   configuration reproduces every decision, and a change of behaviour shows as the first
//!   period that differs.
//! - [`Ticks::Timer`]: any other log (a candump of a tractor's bus): a period every `dt` from
//!   the first frame, and one at each GNSS fix taken, as the daemon schedules them.
//!
//! Agsteer's own frames are never fed to the node as inputs (the daemon does not receive
//! them either).

use super::node::{ControllerNode, NodeStatus};
use crate::can::{codec, Frame, TimedFrame};
use crate::guidance::Event;
use crate::safety::SteeringCommand;

/// Where control periods come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ticks {
    /// At the time stamps of the logged commands.
    Logged,
    /// Every `dt` (s), and at each fix when `on_fix`.
    Timer { dt: f64, on_fix: bool },
}

/// One control period of the replay.
#[derive(Debug)]
pub struct ReplayTick<'a> {
    pub t: f64,
    pub command: SteeringCommand,
    pub status: NodeStatus,
    /// The frames the node sends.
    pub sent: &'a [Frame],
    /// The frames the daemon sent in this period ([`Ticks::Logged`]).
    pub logged: Option<&'a [Frame]>,
    /// The guidance events of this period (lines finished, turns; the daemon's save points).
    pub events: &'a [Event],
}

impl ReplayTick<'_> {
    /// The replayed frames equal the logged ones (`None` without a log to compare with).
    pub fn matches(&self) -> Option<bool> {
        self.logged.map(|l| l == self.sent)
    }
}

/// What a replay did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ReplaySummary {
    pub frames_in: u64,
    pub ticks: u64,
    /// Periods whose frames equal the logged ones, and those that differ ([`Ticks::Logged`]).
    pub matching: u64,
    pub differing: u64,
    /// Time of the first period that differs, s.
    pub first_difference_t: Option<f64>,
    /// Lines of the log that are not frames (skipped), counted by the caller.
    pub unreadable_lines: u64,
}

/// A frame agsteer itself sent: from `own` address, of a message agsteer transmits.
pub fn is_own(frame: &Frame, own: u8) -> bool {
    frame.source() == own && codec::find(frame.id).is_some_and(|(_, m)| m.transmitter == "AGSTEER")
}

/// The replay, fed frame by frame.
pub struct Replay<F: FnMut(&ReplayTick)> {
    node: ControllerNode,
    own: u8,
    ticks: Ticks,
    on_tick: F,
    summary: ReplaySummary,
    sent: Vec<Frame>,
    logged: Vec<Frame>,
    events: Vec<Event>,
    /// The logged period being collected: (its time, the node's command and status).
    open: Option<(f64, SteeringCommand, NodeStatus)>,
    next_tick: Option<f64>,
}

impl<F: FnMut(&ReplayTick)> Replay<F> {
    /// Replay into `node`, whose own source address is `own`; `on_tick` sees every period.
    pub fn new(node: ControllerNode, own: u8, ticks: Ticks, on_tick: F) -> Self {
        Replay {
            node,
            own,
            ticks,
            on_tick,
            summary: ReplaySummary::default(),
            sent: Vec::with_capacity(8),
            logged: Vec::with_capacity(8),
            events: Vec::new(),
            open: None,
            next_tick: None,
        }
    }

    /// One frame of the log, at `t` (s).
    pub fn push(&mut self, t: f64, frame: &Frame) {
        let own = is_own(frame, self.own);
        match self.ticks {
            Ticks::Logged => {
                if own {
                    if self.open.map(|(to, _, _)| to) != Some(t) {
                        self.close();
                        self.sent.clear();
                        let cmd = self.tick(t);
                        self.open = Some((t, cmd, self.node.status()));
                    }
                    self.logged.push(*frame);
                    return;
                }
                self.close();
                self.input(t, frame);
            }
            Ticks::Timer { dt, on_fix } => {
                if own {
                    return;
                }
                let mut next = self.next_tick.unwrap_or(t);
                while next <= t {
                    self.timer_tick(next);
                    next += dt;
                }
                if self.input(t, frame) && on_fix {
                    self.timer_tick(t);
                    next = t + dt;
                }
                self.next_tick = Some(next);
            }
        }
    }

    fn input(&mut self, t: f64, frame: &Frame) -> bool {
        self.summary.frames_in += 1;
        self.node.on_frame(&TimedFrame { t, frame: *frame })
    }

    /// One control period, its events drained as the daemon drains them.
    fn tick(&mut self, t: f64) -> SteeringCommand {
        let cmd = self.node.tick(t, &mut self.sent);
        self.events.clear();
        self.events
            .extend(self.node.controller_mut().guidance_mut().drain_events());
        cmd
    }

    fn timer_tick(&mut self, t: f64) {
        self.sent.clear();
        let command = self.tick(t);
        self.summary.ticks += 1;
        (self.on_tick)(&ReplayTick {
            t,
            command,
            status: self.node.status(),
            sent: &self.sent,
            logged: None,
            events: &self.events,
        });
    }

    /// Close the logged period being collected: compare and report it.
    fn close(&mut self) {
        let Some((t, command, status)) = self.open.take() else {
            return;
        };
        let tick = ReplayTick {
            t,
            command,
            status,
            sent: &self.sent,
            logged: Some(&self.logged),
            events: &self.events,
        };
        self.summary.ticks += 1;
        if tick.matches() == Some(true) {
            self.summary.matching += 1;
        } else {
            self.summary.differing += 1;
            self.summary.first_difference_t.get_or_insert(t);
        }
        (self.on_tick)(&tick);
        self.logged.clear();
    }

    /// The end of the log.
    pub fn finish(mut self) -> (ControllerNode, ReplaySummary) {
        self.close();
        (self.node, self.summary)
    }

    pub fn node(&self) -> &ControllerNode {
        &self.node
    }
}

/// [`Ticks::Logged`] when the frames hold agsteer's own commands from `own`, else a timer.
pub fn ticks_for<'a>(
    frames: impl IntoIterator<Item = &'a Frame>,
    own: u8,
    dt: f64,
    on_fix: bool,
) -> Ticks {
    if frames.into_iter().any(|f| is_own(f, own)) {
        Ticks::Logged
    } else {
        Ticks::Timer { dt, on_fix }
    }
}
