//! Asking the vehicle for its mission on a live link, when none passed on the link: the mission
//! download of the MAVLink mission protocol, as a ground station runs it.
//!
//! [`START_AFTER`] after the vehicle's first message, if no whole mission has been seen, aloft
//! sends MISSION_REQUEST_LIST; to the vehicle's MISSION_COUNT addressed to aloft it answers with
//! MISSION_REQUEST_INT for items 0, 1, ... in turn, and MISSION_ACK (accepted) after the last one.
//! The [`crate::Decoder`] assembles the mission from the vehicle's count and items like any other
//! download. A request unanswered for [`RETRY_AFTER`] is sent again, [`MAX_RETRIES`] times at most,
//! then aloft gives up (it does not ask again). A mission seen on the link before aloft's own
//! download started (another ground station's) ends the request.

use std::time::{Duration, Instant};

use mavlink::dialects::ardupilotmega::{
    MavMessage, MavMissionResult, MavMissionType, MISSION_ACK_DATA, MISSION_REQUEST_INT_DATA,
    MISSION_REQUEST_LIST_DATA,
};
use mavlink::MavHeader;

/// Wait after the vehicle's first message before asking for its mission.
pub const START_AFTER: Duration = Duration::from_secs(3);
/// Wait for an answer before asking again.
pub const RETRY_AFTER: Duration = Duration::from_millis(1_500);
/// Requests sent again without an answer before giving up.
pub const MAX_RETRIES: u32 = 5;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Not asked yet.
    Waiting,
    /// MISSION_REQUEST_LIST sent.
    List,
    /// MISSION_REQUEST_INT for `next` of `count` sent.
    Items { count: u16, next: u16 },
    /// Done, given up, or not needed.
    Done,
}

/// The download state (see the module docs).
#[derive(Debug)]
pub(crate) struct MissionRequest {
    ours: (u8, u8),
    state: State,
    vehicle_seen: Option<Instant>,
    last_sent: Option<Instant>,
    retries: u32,
}

impl MissionRequest {
    /// A download on behalf of the ground-station ids `ours`; `enabled` false never asks.
    pub(crate) fn new(ours: (u8, u8), enabled: bool) -> Self {
        Self {
            ours,
            state: if enabled { State::Waiting } else { State::Done },
            vehicle_seen: None,
            last_sent: None,
            retries: 0,
        }
    }

    /// Whether the download is over (done, given up or not needed).
    pub(crate) fn is_done(&self) -> bool {
        self.state == State::Done
    }

    /// Time passes: the first request, or a request sent again. `vehicle` is the vehicle's ids
    /// once known; `mission_known` whether a whole mission has been seen.
    pub(crate) fn tick(
        &mut self,
        now: Instant,
        vehicle: Option<(u32, u8)>,
        mission_known: bool,
    ) -> Option<MavMessage> {
        let (system, component) = vehicle?;
        let target = (u8::try_from(system).ok()?, component);
        let seen = *self.vehicle_seen.get_or_insert(now);
        match self.state {
            State::Done => None,
            State::Waiting | State::List if mission_known => {
                self.state = State::Done;
                None
            }
            State::Waiting if now.duration_since(seen) >= START_AFTER => {
                self.state = State::List;
                self.sent(now, request_list(target))
            }
            State::Waiting => None,
            State::List | State::Items { .. } => {
                let due = self
                    .last_sent
                    .is_none_or(|t| now.duration_since(t) >= RETRY_AFTER);
                if !due {
                    return None;
                }
                self.retries += 1;
                if self.retries > MAX_RETRIES {
                    self.state = State::Done;
                    return None;
                }
                self.last_sent = Some(now);
                Some(match self.state {
                    State::Items { next, .. } => request_item(target, next),
                    _ => request_list(target),
                })
            }
        }
    }

    /// A message of the vehicle: its count and items addressed to aloft move the download on.
    #[allow(deprecated)] // MISSION_ITEM: deprecated by MAVLink, still answered by older autopilots
    pub(crate) fn on_vehicle_message(
        &mut self,
        now: Instant,
        header: &MavHeader,
        msg: &MavMessage,
    ) -> Option<MavMessage> {
        let target = (u8::try_from(header.system_id).ok()?, header.component_id);
        let (to_us, count, seq) = match msg {
            MavMessage::MISSION_COUNT(c) if c.mission_type == MISSION => (
                self.to_us(c.target_system, c.target_component),
                Some(c.count),
                None,
            ),
            MavMessage::MISSION_ITEM_INT(i) if i.mission_type == MISSION => (
                self.to_us(i.target_system, i.target_component),
                None,
                Some(i.seq),
            ),
            MavMessage::MISSION_ITEM(i) if i.mission_type == MISSION => (
                self.to_us(i.target_system, i.target_component),
                None,
                Some(i.seq),
            ),
            _ => return None,
        };
        if !to_us {
            return None;
        }
        match (self.state, count, seq) {
            (State::List, Some(0), _) => {
                self.state = State::Done;
                Some(ack(target))
            }
            (State::List, Some(count), _) => {
                self.state = State::Items { count, next: 0 };
                self.retries = 0;
                self.sent(now, request_item(target, 0))
            }
            (State::Items { count, next }, _, Some(seq)) if seq == next => {
                let next = next + 1;
                self.retries = 0;
                if next >= count {
                    self.state = State::Done;
                    return Some(ack(target));
                }
                self.state = State::Items { count, next };
                self.sent(now, request_item(target, next))
            }
            _ => None,
        }
    }

    fn to_us(&self, system: u8, component: u8) -> bool {
        system == self.ours.0 && (component == self.ours.1 || component == 0)
    }

    fn sent(&mut self, now: Instant, msg: MavMessage) -> Option<MavMessage> {
        self.last_sent = Some(now);
        Some(msg)
    }
}

const MISSION: MavMissionType = MavMissionType::MAV_MISSION_TYPE_MISSION;

fn request_list((target_system, target_component): (u8, u8)) -> MavMessage {
    MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
        target_system,
        target_component,
        mission_type: MISSION,
    })
}

fn request_item((target_system, target_component): (u8, u8), seq: u16) -> MavMessage {
    MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
        seq,
        target_system,
        target_component,
        mission_type: MISSION,
    })
}

fn ack((target_system, target_component): (u8, u8)) -> MavMessage {
    MavMessage::MISSION_ACK(MISSION_ACK_DATA {
        target_system,
        target_component,
        mavtype: MavMissionResult::MAV_MISSION_ACCEPTED,
        mission_type: MISSION,
        opaque_id: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::ardupilotmega::{MISSION_COUNT_DATA, MISSION_ITEM_INT_DATA};

    const VEHICLE: (u32, u8) = (1, 1);

    fn header() -> MavHeader {
        MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 0,
        }
    }

    fn count(n: u16) -> MavMessage {
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: n,
            target_system: 255,
            target_component: 190,
            ..MISSION_COUNT_DATA::default()
        })
    }

    fn item(seq: u16) -> MavMessage {
        MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
            seq,
            target_system: 255,
            target_component: 190,
            ..MISSION_ITEM_INT_DATA::default()
        })
    }

    #[test]
    fn the_download_runs_list_count_items_ack() {
        let t0 = Instant::now();
        let mut r = MissionRequest::new((255, 190), true);
        assert!(r.tick(t0, Some(VEHICLE), false).is_none());
        let list = r.tick(t0 + START_AFTER, Some(VEHICLE), false).unwrap();
        assert!(matches!(list, MavMessage::MISSION_REQUEST_LIST(_)));
        let first = r.on_vehicle_message(t0, &header(), &count(2)).unwrap();
        assert!(matches!(first, MavMessage::MISSION_REQUEST_INT(ref q) if q.seq == 0));
        // A repeated item 0 is not item 1.
        let second = r.on_vehicle_message(t0, &header(), &item(0)).unwrap();
        assert!(matches!(second, MavMessage::MISSION_REQUEST_INT(ref q) if q.seq == 1));
        assert!(r.on_vehicle_message(t0, &header(), &item(0)).is_none());
        let done = r.on_vehicle_message(t0, &header(), &item(1)).unwrap();
        assert!(matches!(done, MavMessage::MISSION_ACK(_)));
        assert!(r.is_done());
    }

    #[test]
    fn unanswered_requests_are_sent_again_then_given_up() {
        let t0 = Instant::now();
        let mut r = MissionRequest::new((255, 190), true);
        r.tick(t0, Some(VEHICLE), false);
        let mut t = t0 + START_AFTER;
        let mut sent = 0;
        for _ in 0..20 {
            sent += usize::from(r.tick(t, Some(VEHICLE), false).is_some());
            t += RETRY_AFTER;
        }
        assert_eq!(sent, 1 + MAX_RETRIES as usize);
        assert!(r.is_done());
    }

    #[test]
    fn a_mission_seen_first_or_a_disabled_request_asks_nothing() {
        let t0 = Instant::now();
        let mut r = MissionRequest::new((255, 190), true);
        assert!(r.tick(t0 + START_AFTER, Some(VEHICLE), true).is_none());
        assert!(r.is_done());
        let mut off = MissionRequest::new((255, 190), false);
        assert!(off.tick(t0 + START_AFTER, Some(VEHICLE), false).is_none());
    }
}
