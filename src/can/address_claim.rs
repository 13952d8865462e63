//! ISO 11783-5 address claiming: a pure state machine (frames and times in, frames out; no
//! clock, no I/O), shaped like AgIsoStack++'s `InternalControlFunction::update_address_claiming`.
//!
//! On start (and on [`AddressClaimer::restart`], after bus-off or when the link comes back):
//! a pseudo-random delay of 0–153 ms (0.6 ms × a byte of the NAME, as ISO 11783-5 asks of
//! devices answering at once), then a Request for Address Claimed to the global address from
//! the null address, then 250 ms of listening (ISO 11783-5's contention time) while the
//! claims of the other devices fill the address table. Then the preferred address is claimed
//! when it is free or held by a device with a higher NAME (the lower NAME wins); else, when
//! the NAME is self-configurable, the first free address of the configured range; else Cannot
//! Claim is sent (Address Claimed from the null address) and the device stays silent.
//!
//! Once claimed: a Request for Address Claimed (global, or to our address) is answered with our
//! claim; a claim of our address by another device is contended — a higher NAME is answered
//! with our claim again, a lower one takes the address and we move (self-configurable) or send
//! Cannot Claim. Application frames may go out only from [`AddressClaimer::address`], i.e.
//! 250 ms after our claim stood unchallenged (ISO 11783-5: no other transmission before the
//! contention time has passed). In Cannot Claim a Request is answered with Cannot Claim after
//! the pseudo-random delay.

use super::isobus::{
    address_claimed, read, request, Name, NetworkFrame, GLOBAL_ADDRESS, NULL_ADDRESS,
    PGN_ADDRESS_CLAIMED,
};
use super::Frame;
use serde::Serialize;

/// ISO 11783-5's contention time: a claim stands once unchallenged this long, s.
pub const CONTENTION_TIME: f64 = 0.25;

/// What the claimer is configured with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClaimParams {
    pub name: Name,
    /// The address wanted (0..=253).
    pub preferred: u8,
    /// Addresses a self-configurable NAME may move to, inclusive (ISO 11783-5 reserves
    /// 128..=247 for self-configurable devices; the agricultural industry group uses
    /// 128..=235, as AgIsoStack++ does).
    pub range: (u8, u8),
}

/// Where the claim stands, for the status.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "claim", content = "address")]
pub enum ClaimStatus {
    /// Waiting, requesting or within the contention time: no application frames.
    Claiming,
    /// Holding this address.
    Claimed(u8),
    /// No address could be claimed (Cannot Claim sent): silent.
    CannotClaim,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    /// Nothing sent yet: the delay starts at the first tick.
    Start,
    /// The pseudo-random delay before the Request for Address Claimed.
    Delay {
        until: f64,
    },
    /// Request sent; listening to the others' claims until `until`.
    Listening {
        until: f64,
    },
    /// Our claim of `address` went out at `since` (infinite until it is sent).
    Claimed {
        address: u8,
        since: f64,
    },
    CannotClaim,
}

/// The address-claim state machine.
#[derive(Debug, Clone)]
pub struct AddressClaimer {
    params: ClaimParams,
    state: State,
    /// The NAME claiming each address, from the Address Claimed frames seen.
    table: Box<[Option<Name>; 254]>,
    /// Our claim (or Cannot Claim) is to be sent at the next tick at or after this time.
    send_at: Option<f64>,
    /// Times the address was lost to another device.
    losses: u64,
}

impl AddressClaimer {
    pub fn new(params: ClaimParams) -> Self {
        AddressClaimer {
            params,
            state: State::Start,
            table: Box::new([None; 254]),
            send_at: None,
            losses: 0,
        }
    }

    pub fn params(&self) -> &ClaimParams {
        &self.params
    }

    /// The pseudo-random delay of this NAME, s: 0.6 ms × a byte folded from the NAME
    /// (0..=153 ms), so that devices answering one Request do not all answer at once.
    pub fn random_delay(&self) -> f64 {
        let n = self.params.name.0;
        let b = n
            .to_le_bytes()
            .iter()
            .fold(0u8, |a, x| a.rotate_left(3) ^ x);
        b as f64 * 0.6e-3
    }

    /// Start over (bus-off recovery, link up): delay, request, listen, claim.
    pub fn restart(&mut self) {
        self.state = State::Start;
        self.send_at = None;
    }

    /// The claim's standing.
    pub fn status(&self) -> ClaimStatus {
        match self.state {
            State::Claimed { address, .. } => ClaimStatus::Claimed(address),
            State::CannotClaim => ClaimStatus::CannotClaim,
            _ => ClaimStatus::Claiming,
        }
    }

    /// The address application frames may be sent from at `t`: claimed, and unchallenged for
    /// the contention time.
    pub fn address(&self, t: f64) -> Option<u8> {
        match self.state {
            State::Claimed { address, since } if t - since >= CONTENTION_TIME => Some(address),
            _ => None,
        }
    }

    /// Times our address was taken by a device with a lower NAME.
    pub fn losses(&self) -> u64 {
        self.losses
    }

    /// The address of the device whose NAME has `function`, the lowest such address if several.
    pub fn find_function(&self, function: u8) -> Option<u8> {
        self.table
            .iter()
            .position(|n| n.is_some_and(|n| n.function() == function && n != self.params.name))
            .map(|a| a as u8)
    }

    /// The NAME claiming `address`, as last seen.
    pub fn name_at(&self, address: u8) -> Option<Name> {
        self.table.get(address as usize).copied().flatten()
    }

    fn free(&self, address: u8) -> bool {
        self.name_at(address).is_none_or(|n| n == self.params.name)
    }

    /// Whether we would win `address` against its holder (free, or a higher NAME holds it).
    fn wins(&self, address: u8) -> bool {
        self.name_at(address).is_none_or(|n| n >= self.params.name)
    }

    /// The address to claim: the preferred one if we win it; else the first free one of the
    /// range when self-configurable (other than `lost`, just taken from us).
    fn choose(&self, lost: Option<u8>) -> Option<u8> {
        let p = &self.params;
        if lost != Some(p.preferred) && p.preferred < NULL_ADDRESS && self.wins(p.preferred) {
            return Some(p.preferred);
        }
        if !p.name.self_configurable() {
            return None;
        }
        let (lo, hi) = p.range;
        (lo..=hi.min(253)).find(|&a| Some(a) != lost && self.free(a))
    }

    /// One received frame at `t` (any frame; only Requests and Address Claimed matter).
    pub fn on_frame(&mut self, t: f64, f: &Frame) {
        match read(f) {
            Some(NetworkFrame::Request { pgn, dest, .. }) if pgn == PGN_ADDRESS_CLAIMED => {
                let ours = match self.state {
                    State::Claimed { address, .. } => dest == address,
                    _ => false,
                };
                if dest != GLOBAL_ADDRESS && !ours {
                    return;
                }
                match self.state {
                    // Answered at once with our claim.
                    State::Claimed { .. } => self.send_at = Some(t),
                    // Cannot Claim after the pseudo-random delay (ISO 11783-5).
                    State::CannotClaim => self.send_at = Some(t + self.random_delay()),
                    _ => {}
                }
            }
            Some(NetworkFrame::AddressClaimed { name, source }) => {
                if name == self.params.name || source >= NULL_ADDRESS {
                    return;
                }
                // A device that moved no longer holds its old address.
                for slot in self.table.iter_mut() {
                    if *slot == Some(name) {
                        *slot = None;
                    }
                }
                if let Some(slot) = self.table.get_mut(source as usize) {
                    *slot = Some(name);
                }
                if let State::Claimed { address, .. } = self.state {
                    if address != source {
                        return;
                    }
                    if name > self.params.name {
                        // We win: claim again; the other device must move.
                        self.send_at = Some(t);
                    } else {
                        self.losses += 1;
                        tracing::warn!(
                            address,
                            winner = format_args!("{:016X}", name.0),
                            "ISO 11783-5 address lost to a device with a lower NAME"
                        );
                        self.claim(t, Some(address));
                    }
                }
            }
            _ => {}
        }
    }

    /// Claim an address chosen now (sending at the next tick), or give up.
    fn claim(&mut self, t: f64, lost: Option<u8>) {
        match self.choose(lost) {
            Some(address) => {
                // The contention time runs from the claim's sending (next tick).
                self.state = State::Claimed {
                    address,
                    since: f64::INFINITY,
                };
                self.send_at = Some(t);
            }
            None => {
                tracing::error!(
                    preferred = self.params.preferred,
                    "ISO 11783-5: no address can be claimed; sending Cannot Claim and staying silent"
                );
                self.state = State::CannotClaim;
                self.send_at = Some(t);
            }
        }
    }

    /// Advance to `t`, appending the network management frames to send.
    pub fn tick(&mut self, t: f64, out: &mut Vec<Frame>) {
        match self.state {
            State::Start => {
                self.state = State::Delay {
                    until: t + self.random_delay(),
                };
                self.tick(t, out);
                return;
            }
            State::Delay { until } if t >= until => {
                out.push(request(PGN_ADDRESS_CLAIMED, NULL_ADDRESS, GLOBAL_ADDRESS));
                self.state = State::Listening {
                    until: t + CONTENTION_TIME,
                };
            }
            State::Listening { until } if t >= until => self.claim(t, None),
            _ => {}
        }
        if self.send_at.is_some_and(|at| t >= at) {
            self.send_at = None;
            match &mut self.state {
                State::Claimed { address, since } => {
                    if since.is_infinite() {
                        *since = t;
                    }
                    out.push(address_claimed(self.params.name, *address))
                }
                State::CannotClaim => out.push(address_claimed(self.params.name, NULL_ADDRESS)),
                _ => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::isobus::{NameFields, PGN_REQUEST};

    fn name(self_configurable: bool, identity: u32) -> Name {
        Name::new(&NameFields {
            self_configurable,
            identity_number: identity,
            ..NameFields::GUIDANCE_CONTROLLER
        })
    }

    fn claimer(n: Name) -> AddressClaimer {
        AddressClaimer::new(ClaimParams {
            name: n,
            preferred: 0x2A,
            range: (128, 130),
        })
    }

    /// Run `c` from `t0` to `t1` in 10 ms ticks, collecting its frames with their times.
    fn run(c: &mut AddressClaimer, t0: f64, t1: f64) -> Vec<(f64, Frame)> {
        let mut all = Vec::new();
        let mut out = Vec::new();
        let mut t = t0;
        while t <= t1 + 1e-9 {
            out.clear();
            c.tick(t, &mut out);
            all.extend(out.iter().map(|f| (t, *f)));
            t += 0.01;
        }
        all
    }

    fn claims(frames: &[(f64, Frame)]) -> Vec<(f64, u8)> {
        frames
            .iter()
            .filter_map(|(t, f)| match read(f) {
                Some(NetworkFrame::AddressClaimed { source, .. }) => Some((*t, source)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn claims_the_preferred_address_after_request_and_contention_time() {
        let mut c = claimer(name(true, 1));
        let delay = c.random_delay();
        assert!((0.0..=0.153 + 1e-12).contains(&delay), "{delay}");
        let frames = run(&mut c, 0.0, 1.0);
        // First a Request for Address Claimed from the null address, after the delay.
        let (t_req, req) = frames[0];
        assert_eq!(req.id, 0x18EA_FFFE);
        assert_eq!(pgn_of_req(&req), PGN_ADDRESS_CLAIMED);
        assert!(t_req >= delay - 1e-9 && t_req < delay + 0.011);
        // Then our claim of 0x2A, 250 ms later, once.
        let cl = claims(&frames);
        assert_eq!(cl.len(), 1);
        assert!((cl[0].0 - t_req - CONTENTION_TIME).abs() < 0.011);
        assert_eq!(cl[0].1, 0x2A);
        // Application frames only 250 ms after the claim.
        assert_eq!(c.address(cl[0].0 + 0.2), None);
        assert_eq!(c.address(cl[0].0 + 0.2501), Some(0x2A));
        assert_eq!(c.status(), ClaimStatus::Claimed(0x2A));
    }

    fn pgn_of_req(f: &Frame) -> u32 {
        match read(f) {
            Some(NetworkFrame::Request { pgn, .. }) => pgn,
            _ => 0,
        }
    }

    #[test]
    fn answers_a_request_for_address_claimed_global_or_to_its_address_only() {
        let mut c = claimer(name(true, 1));
        run(&mut c, 0.0, 1.0);
        let mut out = Vec::new();
        // To another address: no answer.
        c.on_frame(1.0, &request(PGN_ADDRESS_CLAIMED, 0x80, 0x33));
        c.tick(1.0, &mut out);
        assert!(out.is_empty());
        // Another PGN requested: no answer.
        c.on_frame(1.0, &request(0xFEE5, 0x80, GLOBAL_ADDRESS));
        c.tick(1.0, &mut out);
        assert!(out.is_empty());
        for dest in [GLOBAL_ADDRESS, 0x2A] {
            c.on_frame(1.1, &request(PGN_ADDRESS_CLAIMED, 0x80, dest));
            out.clear();
            c.tick(1.1, &mut out);
            assert_eq!(out, vec![address_claimed(c.params.name, 0x2A)]);
        }
        // Answering does not stop application frames.
        assert_eq!(c.address(1.2), Some(0x2A));
        let _ = PGN_REQUEST;
    }

    #[test]
    fn a_lower_name_takes_the_address_and_a_self_configurable_device_moves() {
        let ours = name(true, 5);
        let mut c = claimer(ours);
        run(&mut c, 0.0, 1.0);
        assert_eq!(c.address(1.0), Some(0x2A));
        // A higher NAME claims 0x2A: we claim again and keep it.
        let higher = name(true, 9);
        c.on_frame(1.0, &address_claimed(higher, 0x2A));
        let mut out = Vec::new();
        c.tick(1.0, &mut out);
        assert_eq!(out, vec![address_claimed(ours, 0x2A)]);
        assert_eq!(c.losses(), 0);
        // A lower NAME claims 0x2A: we lose it, stop at once and claim 128 (the range's first).
        let lower = name(true, 2);
        c.on_frame(1.5, &address_claimed(lower, 0x2A));
        assert_eq!(c.address(1.5), None);
        out.clear();
        c.tick(1.5, &mut out);
        assert_eq!(out, vec![address_claimed(ours, 128)]);
        assert_eq!(c.losses(), 1);
        assert_eq!(c.address(1.6), None, "within the contention time");
        assert_eq!(c.address(1.75), Some(128));
        assert_eq!(c.name_at(0x2A), Some(lower));
    }

    #[test]
    fn contention_during_start_up_picks_a_free_address_of_the_range() {
        let mut c = claimer(name(true, 5));
        let mut out = Vec::new();
        c.tick(0.0, &mut out);
        // Others answer the request: 0x2A by a lower NAME, 128 by anyone.
        c.on_frame(0.2, &address_claimed(name(true, 1), 0x2A));
        c.on_frame(0.2, &address_claimed(name(false, 77), 128));
        let cl = claims(&run(&mut c, 0.0, 1.0));
        assert_eq!(cl.iter().map(|c| c.1).collect::<Vec<_>>(), vec![129]);
        // Preferred held by a higher NAME: we take it.
        let mut c = claimer(name(true, 5));
        c.on_frame(0.0, &address_claimed(name(true, 6), 0x2A));
        let cl = claims(&run(&mut c, 0.0, 1.0));
        assert_eq!(cl.iter().map(|c| c.1).collect::<Vec<_>>(), vec![0x2A]);
    }

    #[test]
    fn not_self_configurable_or_range_full_sends_cannot_claim_and_stays_silent() {
        let mut c = claimer(name(false, 5));
        run(&mut c, 0.0, 1.0);
        c.on_frame(1.0, &address_claimed(name(false, 1), 0x2A));
        let mut out = Vec::new();
        c.tick(1.0, &mut out);
        assert_eq!(out, vec![address_claimed(c.params.name, NULL_ADDRESS)]);
        assert_eq!(c.status(), ClaimStatus::CannotClaim);
        assert_eq!(c.address(5.0), None);
        // A Request is answered with Cannot Claim after the pseudo-random delay.
        c.on_frame(2.0, &request(PGN_ADDRESS_CLAIMED, 0x80, GLOBAL_ADDRESS));
        let frames = run(&mut c, 2.0, 2.5);
        assert_eq!(frames.len(), 1);
        assert_eq!(frames[0].1, address_claimed(c.params.name, NULL_ADDRESS));
        assert!(frames[0].0 >= 2.0 + c.random_delay() - 1e-9);
        // Self-configurable, but every address of the range is held by lower NAMEs.
        let mut c = claimer(name(true, 50));
        for a in [0x2A, 128, 129, 130] {
            c.on_frame(0.0, &address_claimed(name(true, a as u32), a));
        }
        let frames = run(&mut c, 0.0, 1.0);
        assert_eq!(claims(&frames), vec![(claims(&frames)[0].0, NULL_ADDRESS)]);
        assert_eq!(c.status(), ClaimStatus::CannotClaim);
    }

    #[test]
    fn restart_claims_again_and_a_moved_device_frees_its_old_address() {
        let mut c = claimer(name(true, 5));
        run(&mut c, 0.0, 1.0);
        c.restart();
        assert_eq!(c.address(1.0), None);
        let frames = run(&mut c, 1.0, 2.0);
        assert_eq!(frames[0].1.id, 0x18EA_FFFE, "request again");
        assert_eq!(claims(&frames).len(), 1);
        assert_eq!(c.address(2.0), Some(0x2A));
        // The steering ECU claims 0x1C, then moves to 0x80: found at its new address.
        let steer = NameFields {
            function: 16,
            ..name(true, 3).fields()
        };
        c.on_frame(2.0, &address_claimed(Name::new(&steer), 0x1C));
        assert_eq!(c.find_function(16), Some(0x1C));
        c.on_frame(2.1, &address_claimed(Name::new(&steer), 0x80));
        assert_eq!(c.find_function(16), Some(0x80));
        assert_eq!(c.name_at(0x1C), None);
        assert_eq!(
            c.find_function(23),
            None,
            "our own NAME is not another device"
        );
    }
}
