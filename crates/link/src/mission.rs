//! The vehicle's mission, assembled from the mission protocol as it passes on the link.
//!
//! - A transfer starts with MISSION_COUNT (of the mission, not a fence or rally list): sent by the
//!   vehicle (a ground station downloads it) or sent to the vehicle by another system (an upload).
//!   The items of that transfer come from the same sender; when items `0..count` have all been
//!   seen (retransmissions replace), the whole mission is emitted and kept as the vehicle's.
//! - Items the vehicle sends outside a transfer (a ground station re-reading item 0, which is home
//!   on ArduPilot) update the kept mission; it is emitted again when an item changed.
//! - While no mission is known, items the vehicle sends outside a transfer that run from 0 with
//!   consecutive sequence numbers are collected; when the run ends (an item out of sequence, a
//!   MISSION_ACK, a MISSION_COUNT, the end of the stream) a run of two items or more is emitted.
//!   A lone item 0 is not a mission (it is how ground stations read home).
//!
//! Memory: at most [`MAX_MISSION_ITEMS`] items are held (a larger MISSION_COUNT is ignored).
//!
//! # Deviation
//!
//! An upload is taken when its last item is seen, without waiting for the vehicle's MISSION_ACK:
//! acknowledgements are lost as often as items on a noisy link, and a vehicle that refused an
//! upload is rare. A later download or re-read corrects it.

use aloft_logs::telemetry::MissionItem;

/// Most items of a mission held (MAVLink allows 65,535; autopilots store far fewer).
pub const MAX_MISSION_ITEMS: usize = 10_000;

/// A system and component.
pub(crate) type Sender = (u32, u8);

/// One mission transfer in progress.
#[derive(Debug)]
struct Transfer {
    sender: Sender,
    items: Vec<Option<MissionItem>>,
    seen: usize,
}

/// Assembles the mission (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct MissionAssembler {
    transfer: Option<Transfer>,
    known: Option<Vec<MissionItem>>,
    run: Vec<MissionItem>,
}

impl MissionAssembler {
    /// MISSION_COUNT of a mission from `sender`: a transfer starts. A run in progress ends (and
    /// is returned when it is a mission).
    pub(crate) fn count(&mut self, sender: Sender, count: u16) -> Option<Vec<MissionItem>> {
        let ended = self.end_run();
        let count = usize::from(count);
        if count > MAX_MISSION_ITEMS {
            self.transfer = None;
            return ended;
        }
        if count == 0 {
            // An empty mission: nothing to transfer, the vehicle holds none.
            self.transfer = None;
            self.known = Some(Vec::new());
            return Some(Vec::new());
        }
        self.transfer = Some(Transfer {
            sender,
            items: vec![None; count],
            seen: 0,
        });
        ended
    }

    /// A mission item from `sender` (`from_vehicle` when the sender is the vehicle).
    pub(crate) fn item(
        &mut self,
        sender: Sender,
        from_vehicle: bool,
        item: MissionItem,
    ) -> Option<Vec<MissionItem>> {
        if let Some(t) = self.transfer.as_mut().filter(|t| t.sender == sender) {
            let slot = t.items.get_mut(item.seq as usize)?;
            if slot.is_none() {
                t.seen += 1;
            }
            *slot = Some(item);
            if t.seen < t.items.len() {
                return None;
            }
            let done: Vec<MissionItem> =
                self.transfer.take()?.items.into_iter().flatten().collect();
            self.run.clear();
            self.known = Some(done.clone());
            return Some(done);
        }
        if !from_vehicle {
            return None;
        }
        match self.known.as_mut() {
            Some(known) => update(known, item).then(|| known.clone()),
            None => self.extend_run(item),
        }
    }

    /// The mission as the vehicle holds it, once a whole one has been seen.
    pub(crate) fn known(&self) -> Option<&[MissionItem]> {
        self.known.as_deref()
    }

    /// MISSION_ACK between the vehicle and another system: a run in progress ends.
    pub(crate) fn ack(&mut self) -> Option<Vec<MissionItem>> {
        self.end_run()
    }

    /// The end of the stream: a run in progress ends.
    pub(crate) fn finish(&mut self) -> Option<Vec<MissionItem>> {
        self.end_run()
    }

    /// The vehicle restarted: transfers and runs in progress are abandoned; the mission it holds
    /// (kept in its storage) is returned to be announced again.
    pub(crate) fn reboot(&mut self) -> Option<Vec<MissionItem>> {
        self.transfer = None;
        self.run.clear();
        self.known.clone()
    }

    fn extend_run(&mut self, item: MissionItem) -> Option<Vec<MissionItem>> {
        let next = self.run.len();
        if item.seq as usize == next && next < MAX_MISSION_ITEMS {
            self.run.push(item);
            return None;
        }
        if next > 0 && item.seq as usize == next - 1 {
            // A retransmission replaces the last item.
            self.run[next - 1] = item;
            return None;
        }
        let ended = self.end_run();
        if item.seq == 0 {
            self.run.push(item);
        }
        ended
    }

    fn end_run(&mut self) -> Option<Vec<MissionItem>> {
        let run = std::mem::take(&mut self.run);
        if run.len() < 2 {
            return None;
        }
        self.known = Some(run.clone());
        Some(run)
    }
}

/// Replaces the item of the same sequence number; whether it changed (compared bit for bit, so
/// a NaN parameter, which MAVLink uses for "not set", is equal to itself).
fn update(known: &mut [MissionItem], item: MissionItem) -> bool {
    let Some(slot) = known.get_mut(item.seq as usize) else {
        return false;
    };
    let same = slot.frame == item.frame
        && slot.command == item.command
        && slot
            .params
            .iter()
            .zip(&item.params)
            .all(|(a, b)| a.to_bits() == b.to_bits());
    *slot = item;
    !same
}

#[cfg(test)]
mod tests {
    use super::*;

    const GCS: Sender = (255, 190);
    const VEHICLE: Sender = (1, 1);

    fn item(seq: u32, lat: f64) -> MissionItem {
        MissionItem {
            seq,
            frame: 3,
            command: 16,
            params: [0.0, 0.0, 0.0, f64::NAN, lat, 8.5, 20.0],
        }
    }

    #[test]
    fn an_upload_with_retransmissions_is_one_mission() {
        let mut m = MissionAssembler::default();
        assert!(m.count(GCS, 3).is_none());
        assert!(m.item(GCS, false, item(0, 47.0)).is_none());
        assert!(m.item(GCS, false, item(0, 47.0)).is_none());
        assert!(m.item(GCS, false, item(1, 47.1)).is_none());
        // Items of another sender are not part of the transfer.
        assert!(m.item((254, 1), false, item(2, 9.0)).is_none());
        let done = m.item(GCS, false, item(2, 47.2)).unwrap();
        assert_eq!(done.len(), 3);
        assert_eq!(done[2].params[4].to_bits(), 47.2f64.to_bits());
    }

    #[test]
    fn a_reread_item_updates_the_mission_only_when_it_changed() {
        let mut m = MissionAssembler::default();
        m.count(VEHICLE, 2);
        m.item(VEHICLE, true, item(0, 47.0));
        assert!(m.item(VEHICLE, true, item(1, 47.1)).is_some());
        assert!(m.item(VEHICLE, true, item(0, 47.0)).is_none());
        let again = m.item(VEHICLE, true, item(0, 46.9)).unwrap();
        assert_eq!(again[0].params[4].to_bits(), 46.9f64.to_bits());
        // Outside the mission: ignored.
        assert!(m.item(VEHICLE, true, item(5, 1.0)).is_none());
    }

    #[test]
    fn a_run_without_count_is_a_mission_when_it_ends_and_a_lone_item_0_is_not() {
        let mut m = MissionAssembler::default();
        assert!(m.item(VEHICLE, true, item(0, 47.0)).is_none());
        assert!(m.ack().is_none());
        for k in 0..4 {
            assert!(m.item(VEHICLE, true, item(k, 47.0)).is_none());
        }
        assert_eq!(m.finish().unwrap().len(), 4);
    }

    #[test]
    fn counts_beyond_the_limit_and_zero() {
        let mut m = MissionAssembler::default();
        assert!(m.count(GCS, 10_001).is_none());
        assert!(m.item(GCS, false, item(0, 1.0)).is_none());
        assert_eq!(m.count(VEHICLE, 0), Some(Vec::new()));
    }
}
