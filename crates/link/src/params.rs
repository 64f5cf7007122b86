//! Asking the vehicle for the parameters its battery failsafes act on, on a live link.
//!
//! Once the vehicle's HEARTBEAT has been seen (its autopilot known), aloft sends a
//! PARAM_REQUEST_READ by name (`param_index` -1) for each parameter of that autopilot's set
//! ([`ARDUPILOT_PARAMETERS`], [`PX4_PARAMETERS`]; another autopilot is asked nothing). The
//! vehicle answers each with PARAM_VALUE, which the [`crate::Decoder`] turns into
//! [`aloft_logs::telemetry::Event::Parameter`] like any other PARAM_VALUE (asked for or not). A
//! name not answered within [`RETRY_AFTER`] is asked again, [`MAX_RETRIES`] times at most (an
//! autopilot without that parameter does not answer). After the vehicle restarts the whole set
//! is asked again: its parameters may have changed.

use std::time::{Duration, Instant};

use mavlink::dialects::ardupilotmega::{MavAutopilot, MavMessage, PARAM_REQUEST_READ_DATA};

/// ArduPilot's battery failsafe parameters (first battery): the low and critical voltages and
/// charges, the low-voltage timer, which voltage they watch, their actions, the capacity.
pub const ARDUPILOT_PARAMETERS: [&str; 9] = [
    "BATT_LOW_VOLT",
    "BATT_CRT_VOLT",
    "BATT_LOW_MAH",
    "BATT_CRT_MAH",
    "BATT_LOW_TIMER",
    "BATT_FS_VOLTSRC",
    "BATT_FS_LOW_ACT",
    "BATT_FS_CRT_ACT",
    "BATT_CAPACITY",
];

/// PX4's: the low, critical and emergency thresholds (of its own state of charge), what its
/// estimate is made from (empty and charged cell voltages, internal resistance, capacity, cells,
/// load drop), and the low-battery action.
pub const PX4_PARAMETERS: [&str; 10] = [
    "BAT_LOW_THR",
    "BAT_CRIT_THR",
    "BAT_EMERGEN_THR",
    "BAT1_V_EMPTY",
    "BAT1_V_CHARGED",
    "BAT1_R_INTERNAL",
    "BAT1_CAPACITY",
    "BAT1_N_CELLS",
    "BAT1_V_LOAD_DROP",
    "COM_LOW_BAT_ACT",
];

/// Wait for an answer before asking again.
pub const RETRY_AFTER: Duration = Duration::from_millis(2_000);
/// Requests sent again for a name without an answer before giving it up.
pub const MAX_RETRIES: u32 = 3;

/// The parameters aloft asks an autopilot for (none for an autopilot it does not know).
pub fn failsafe_parameters(autopilot: MavAutopilot) -> &'static [&'static str] {
    match autopilot {
        MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA => &ARDUPILOT_PARAMETERS,
        MavAutopilot::MAV_AUTOPILOT_PX4 => &PX4_PARAMETERS,
        _ => &[],
    }
}

/// The requests' state (see the module docs).
#[derive(Debug)]
pub(crate) struct ParamRequest {
    enabled: bool,
    /// The names still to be answered, each with its requests sent so far.
    waiting: Vec<(&'static str, u32)>,
    /// The restart count the set was last asked for at (`None`: not asked yet).
    asked_for: Option<u32>,
    last_sent: Option<Instant>,
}

impl ParamRequest {
    /// Requests not sent yet; `enabled` false never asks. Answers are recognised by name,
    /// whoever they are addressed to.
    pub(crate) fn new(enabled: bool) -> Self {
        Self {
            enabled,
            waiting: Vec::new(),
            asked_for: None,
            last_sent: None,
        }
    }

    /// Time passes: the whole set once the vehicle is known (again after each restart), then
    /// the names not answered, every [`RETRY_AFTER`]. `reboots` is the restarts seen so far.
    pub(crate) fn tick(
        &mut self,
        now: Instant,
        vehicle: Option<(u32, u8)>,
        autopilot: Option<MavAutopilot>,
        reboots: u32,
    ) -> Vec<MavMessage> {
        let (Some((system, component)), Some(autopilot), true) = (vehicle, autopilot, self.enabled)
        else {
            return Vec::new();
        };
        let Ok(system) = u8::try_from(system) else {
            return Vec::new();
        };
        if self.asked_for != Some(reboots) {
            self.asked_for = Some(reboots);
            self.waiting = failsafe_parameters(autopilot)
                .iter()
                .map(|n| (*n, 0))
                .collect();
            self.last_sent = None;
        }
        let due = self
            .last_sent
            .is_none_or(|t| now.duration_since(t) >= RETRY_AFTER);
        if !due {
            return Vec::new();
        }
        self.waiting.retain(|(_, sent)| *sent <= MAX_RETRIES);
        if self.waiting.is_empty() {
            return Vec::new();
        }
        self.last_sent = Some(now);
        self.waiting
            .iter_mut()
            .map(|(name, sent)| {
                *sent += 1;
                read_request((system, component), name)
            })
            .collect()
    }

    /// A message of the vehicle: a PARAM_VALUE answers its name.
    pub(crate) fn on_vehicle_message(&mut self, msg: &MavMessage) {
        if let MavMessage::PARAM_VALUE(p) = msg {
            if let Ok(name) = p.param_id.to_str() {
                self.waiting.retain(|(n, _)| *n != name);
            }
        }
    }
}

/// PARAM_REQUEST_READ of `name` (by name: `param_index` -1).
fn read_request((target_system, target_component): (u8, u8), name: &str) -> MavMessage {
    MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
        param_index: -1,
        target_system,
        target_component,
        param_id: name.into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::ardupilotmega::{MavParamType, PARAM_VALUE_DATA};

    const VEHICLE: Option<(u32, u8)> = Some((1, 1));
    const ARDU: Option<MavAutopilot> = Some(MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA);
    const PX4: Option<MavAutopilot> = Some(MavAutopilot::MAV_AUTOPILOT_PX4);

    fn names(msgs: &[MavMessage]) -> Vec<String> {
        msgs.iter()
            .map(|m| match m {
                MavMessage::PARAM_REQUEST_READ(r) => {
                    assert_eq!(r.param_index, -1);
                    assert_eq!((r.target_system, r.target_component), (1, 1));
                    r.param_id.to_str().unwrap().to_string()
                }
                other => panic!("not a PARAM_REQUEST_READ: {other:?}"),
            })
            .collect()
    }

    fn value(name: &str) -> MavMessage {
        MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
            param_value: 1.0,
            param_count: 1,
            param_index: 0,
            param_id: name.into(),
            param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        })
    }

    /// The autopilot's own set, once; the unanswered names again after the wait, then given up;
    /// the whole set again after a restart.
    #[test]
    fn the_autopilots_set_is_asked_retried_and_asked_again_after_a_restart() {
        let t0 = Instant::now();
        let mut r = ParamRequest::new(true);
        assert!(r.tick(t0, None, None, 0).is_empty());
        let first = names(&r.tick(t0, VEHICLE, ARDU, 0));
        assert_eq!(first, ARDUPILOT_PARAMETERS);
        assert!(r.tick(t0 + RETRY_AFTER / 2, VEHICLE, ARDU, 0).is_empty());
        for n in &ARDUPILOT_PARAMETERS[1..] {
            r.on_vehicle_message(&value(n));
        }
        let mut t = t0;
        let mut again = Vec::new();
        for _ in 0..10 {
            t += RETRY_AFTER;
            again.extend(names(&r.tick(t, VEHICLE, ARDU, 0)));
        }
        assert_eq!(again, vec!["BATT_LOW_VOLT"; MAX_RETRIES as usize]);
        let after_restart = names(&r.tick(t, VEHICLE, ARDU, 1));
        assert_eq!(after_restart, ARDUPILOT_PARAMETERS);
    }

    #[test]
    fn px4_is_asked_its_own_names_and_other_autopilots_none() {
        let t0 = Instant::now();
        let mut px4 = ParamRequest::new(true);
        assert_eq!(names(&px4.tick(t0, VEHICLE, PX4, 0)), PX4_PARAMETERS);
        let mut other = ParamRequest::new(true);
        let generic = Some(MavAutopilot::MAV_AUTOPILOT_GENERIC);
        assert!(other.tick(t0, VEHICLE, generic, 0).is_empty());
        let mut off = ParamRequest::new(false);
        assert!(off.tick(t0, VEHICLE, ARDU, 0).is_empty());
    }
}
