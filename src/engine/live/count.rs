//! The autopilot's count of the charge drawn (MAVLink BATTERY_STATUS `current_consumed`), and
//! whether it is believed.
//!
//! The count is physical evidence only where the pack could have drawn it. A count is not
//! believed where it is:
//! - **negative** (MAVLink's `-1`, "not sent", is left out when the message is read; any other
//!   negative count is a wrapped 32-bit counter or a damaged message);
//! - **beyond the pack**: more than [`BEYOND_PACK`] times the pack's capacity;
//! - **gone back**: below the last believed count by more than [`RESOLUTION_AH`] (the charge
//!   drawn never goes back: a wrap or a reset of the counter);
//! - **a jump**: above the last believed count by more than the measured current could draw
//!   since, `JUMP_MARGIN * sum(max(|I_k|, |I_k+1|) dt) + SLACK_OF_PACK * capacity`
//!   ([`JUMP_MARGIN`], [`SLACK_OF_PACK`]; the current held from its last sample to the count's
//!   time, over a silent link too), or, where no current was ever measured, more than
//!   [`UNMEASURED_C_RATE`] would draw.
//!
//! Each count is judged against the last believed one, so a count that comes back to its own
//! track (a single damaged message, a counter that recovers) is believed again, and one that
//! stays off (a jump to `INT32_MAX`, a wrap that counts on from a new base) is not believed for
//! the rest of the flight. While the count is not believed, the charge drawn is the energy used
//! over the pack's rated energy ([`super::charge`]). Each time the count stops being believed,
//! for a new reason, the next update's note says so once (not every update).

/// Largest count believed, in capacities of the pack flown: the charge a pack delivers exceeds
/// its rating by a few percent when new, and the count runs from the autopilot's boot (a pack
/// changed while it runs is counted on).
const BEYOND_PACK: f64 = 1.2;

/// The count's resolution, A h: MAVLink counts whole mA h.
const RESOLUTION_AH: f64 = 0.001;

/// How many times the charge the measured current draws a rise of the count may be: the
/// autopilot counts at its own rate (10 Hz and more) the current the link samples at 1-5 Hz,
/// so a peak between two samples is counted and not seen.
const JUMP_MARGIN: f64 = 1.5;

/// A rise of the count always believed, in capacities of the pack (1 %, 45 mA h on a 4.5 A h
/// pack: 13 s of a 12 A hover): the count and the current are sampled at different instants.
const SLACK_OF_PACK: f64 = 0.01;

/// The current a count may have been drawn at where none was ever measured, in C (capacities
/// per hour): beyond what a multirotor's LiPo delivers for long (25-30 C is a pack's burst
/// rating).
const UNMEASURED_C_RATE: f64 = 30.0;

/// Why a count is not believed.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Doubt {
    /// Below 0.
    Negative { count_ah: f64 },
    /// More than the pack holds.
    BeyondPack { count_ah: f64 },
    /// Below the last believed count.
    WentBack { from_ah: f64, to_ah: f64 },
    /// Above the last believed count by more than the current could draw.
    Jump {
        from_ah: f64,
        to_ah: f64,
        elapsed_s: f64,
        bound_ah: f64,
    },
}

impl Doubt {
    /// Whether `other` is the same reason (the note is said once per reason).
    fn same_kind(&self, other: &Doubt) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }
}

/// The autopilot's count of one flight (from the stream's start or the vehicle's last restart).
#[derive(Debug, Clone)]
pub(crate) struct ChargeCount {
    capacity_ah: f64,
    /// The last believed count: time, s, and count, A h.
    believed: Option<(f64, f64)>,
    /// Whether the last count is believed.
    last_believed: bool,
    /// The most the measured current drew since the last believed count, A h (to the last
    /// current sample).
    could_draw_ah: f64,
    /// The last current sample: time, s, and its magnitude, A.
    current: Option<(f64, f64)>,
    /// The reason last said in a note, while the count is not believed.
    said: Option<Doubt>,
    /// A note not yet given to an update.
    note: Option<String>,
}

impl ChargeCount {
    /// No count yet, for a pack of `capacity_ah` (A h).
    pub(crate) fn new(capacity_ah: f64) -> Self {
        Self {
            capacity_ah,
            believed: None,
            last_believed: false,
            could_draw_ah: 0.0,
            current: None,
            said: None,
            note: None,
        }
    }

    /// A current sample `current_a` (A, positive discharging) at `time_s`.
    pub(crate) fn current(&mut self, time_s: f64, current_a: f64) {
        if !current_a.is_finite() {
            return;
        }
        let now_a = current_a.abs();
        if let Some((t, a)) = self.current {
            self.could_draw_ah += a.max(now_a) * (time_s - t).max(0.0) / 3600.0;
        }
        self.current = Some((time_s, now_a));
    }

    /// A count `count_ah` (A h) at `time_s`: believed or not (module docs).
    pub(crate) fn count(&mut self, time_s: f64, count_ah: f64) {
        match self.doubt(time_s, count_ah) {
            None => {
                self.believed = Some((time_s, count_ah));
                self.last_believed = true;
                self.could_draw_ah = 0.0;
                self.said = None;
            }
            Some(doubt) => {
                self.last_believed = false;
                if !self.said.is_some_and(|s| s.same_kind(&doubt)) {
                    self.note = Some(note(doubt, self.capacity_ah));
                    self.said = Some(doubt);
                }
            }
        }
    }

    /// Why `count_ah` at `time_s` is not believed, if it is not.
    fn doubt(&self, time_s: f64, count_ah: f64) -> Option<Doubt> {
        if !(count_ah.is_finite() && count_ah >= 0.0) {
            return Some(Doubt::Negative { count_ah });
        }
        if count_ah > BEYOND_PACK * self.capacity_ah {
            return Some(Doubt::BeyondPack { count_ah });
        }
        let (t0, from_ah) = self.believed?;
        if count_ah < from_ah - RESOLUTION_AH {
            return Some(Doubt::WentBack {
                from_ah,
                to_ah: count_ah,
            });
        }
        let elapsed_s = (time_s - t0).max(0.0);
        let bound_ah =
            JUMP_MARGIN * self.could_draw_by(time_s, elapsed_s) + SLACK_OF_PACK * self.capacity_ah;
        (count_ah - from_ah > bound_ah).then_some(Doubt::Jump {
            from_ah,
            to_ah: count_ah,
            elapsed_s,
            bound_ah,
        })
    }

    /// The most the measured current could draw from the last believed count to `time_s`
    /// (`elapsed_s` later), A h: the current held from its last sample on; without any, the
    /// pack at [`UNMEASURED_C_RATE`].
    fn could_draw_by(&self, time_s: f64, elapsed_s: f64) -> f64 {
        match self.current {
            Some((t, a)) => self.could_draw_ah + a * (time_s - t).max(0.0) / 3600.0,
            None => UNMEASURED_C_RATE * self.capacity_ah * elapsed_s / 3600.0,
        }
    }

    /// The count now, A h, where the last one is believed.
    pub(crate) fn believed_ah(&self) -> Option<f64> {
        match self.last_believed {
            true => self.believed.map(|(_, c)| c),
            false => None,
        }
    }

    /// The note not yet said, once.
    pub(crate) fn take_note(&mut self) -> Option<String> {
        self.note.take()
    }
}

/// What the update's note says of a count not believed.
fn note(doubt: Doubt, capacity_ah: f64) -> String {
    const COUNT: &str = "the autopilot's count of the charge drawn (current_consumed)";
    let what = match doubt {
        Doubt::Negative { count_ah } => format!("{COUNT}, {count_ah:.3} A h, is negative"),
        Doubt::BeyondPack { count_ah } => {
            format!("{COUNT}, {count_ah:.3} A h, is more than the {capacity_ah:.3} A h pack holds")
        }
        Doubt::WentBack { from_ah, to_ah } => {
            format!("{COUNT} went back from {from_ah:.3} to {to_ah:.3} A h")
        }
        Doubt::Jump {
            from_ah,
            to_ah,
            elapsed_s,
            bound_ah,
        } => format!(
            "{COUNT} rose from {from_ah:.3} to {to_ah:.3} A h in {elapsed_s:.1} s, more than the \
             measured current could draw ({bound_ah:.3} A h)"
        ),
    };
    format!(
        "{what}: not believed; the charge drawn is the energy used over the pack's rated energy \
         until the count agrees again"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4.5 A h pack counted from `from_ah` at 0 s, with 12 A measured every 0.2 s up to
    /// `to_s`.
    fn counting(from_ah: f64, to_s: f64) -> ChargeCount {
        let mut c = ChargeCount::new(4.5);
        c.current(0.0, 12.0);
        c.count(0.0, from_ah);
        for k in 1..=(to_s * 5.0).round() as u32 {
            c.current(0.2 * f64::from(k), 12.0);
        }
        c
    }

    /// 12 A for 10 s is 33.3 mA h; the bound is 1.5 times it plus 45 mA h, 95 mA h: a rise of
    /// 90 mA h is believed, one of 100 mA h is not (and said, once), the next count on the
    /// track is believed again.
    #[test]
    fn a_rise_is_believed_up_to_what_the_current_could_draw() {
        let mut c = counting(1.0, 10.0);
        c.count(10.0, 1.090);
        assert_eq!(c.believed_ah(), Some(1.090));
        let mut c = counting(1.0, 10.0);
        c.count(10.0, 1.100);
        assert_eq!(c.believed_ah(), None);
        let note = c.take_note().unwrap();
        assert!(
            note.contains("rose from 1.000 to 1.100 A h in 10.0 s"),
            "{note}"
        );
        assert!(note.contains("(0.095 A h)"), "{note}");
        c.count(10.2, 1.101);
        assert_eq!(c.take_note(), None);
        c.count(10.4, 1.035);
        assert_eq!(c.believed_ah(), Some(1.035));
    }

    /// Negative, beyond 1.2 capacities (5.4 A h), or back by more than a mA h: not believed.
    /// Without a current ever measured, the bound is 1.5 times 30 C (37.5 mA h a second on
    /// 4.5 A h) plus 45 mA h: 157.5 mA h over 2 s.
    #[test]
    fn negative_beyond_the_pack_or_back_is_not_believed() {
        let mut c = ChargeCount::new(4.5);
        c.count(0.0, -0.002);
        assert!(c.take_note().unwrap().contains("is negative"));
        c.count(1.0, 5.401);
        assert!(c
            .take_note()
            .unwrap()
            .contains("more than the 4.500 A h pack"));
        c.count(2.0, 5.399);
        assert_eq!(c.believed_ah(), Some(5.399));
        // 0.2 mA h back: within the count's resolution.
        c.count(3.0, 5.3988);
        assert_eq!(c.believed_ah(), Some(5.3988));
        assert_eq!(c.take_note(), None);
        c.count(4.0, 5.0);
        assert!(c
            .take_note()
            .unwrap()
            .contains("went back from 5.399 to 5.000"));
        let mut u = ChargeCount::new(4.5);
        u.count(0.0, 1.0);
        u.count(2.0, 1.157);
        assert_eq!(u.believed_ah(), Some(1.157));
        u.count(4.0, 1.316);
        assert_eq!(u.believed_ah(), None);
    }
}
