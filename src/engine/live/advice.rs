//! The advice of an update, from the scenarios of the route ahead, with hysteresis.
//!
//! In the air: `continue` while [`P_HOLDS`] of the rest's scenarios land with the reserve,
//! `return now` where they do not but that share of a direct return's do, `land now` where
//! neither holds (or the rest is a return already); on the ground, `continue` or `do not take
//! off`.
//!
//! Hysteresis, so that the advice does not flap between two answers on noise, and never
//! latches:
//! - a graver advice is given at once (the first update whose scenarios ask for it);
//! - a milder one only once it has held, with a margin, for [`RELAX_HOLD_S`] seconds of the
//!   stream: its share of the scenarios at least [`P_HOLDS`] + [`RELAX_MARGIN`] at every update
//!   since; a graver answer in between starts the wait again;
//! - nothing else holds the advice: when the evidence clears, it is back to `continue` after the
//!   hold time.
//!
//! Taking off or landing starts over: on the ground and in the air the advice answers different
//! questions.

/// Share of the scenarios that must land with the reserve for a route to be flown.
pub(crate) const P_HOLDS: f64 = 0.95;

/// The margin on [`P_HOLDS`] a milder advice must clear (97 %: all of 20 scenarios, 194 of
/// 200).
pub(crate) const RELAX_MARGIN: f64 = 0.02;

/// How long a milder advice must hold before it is given, s of the stream (five updates at the
/// default one a second; a report's jump settles in five reports, too).
pub(crate) const RELAX_HOLD_S: f64 = 5.0;

/// What to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Advice {
    /// Fly on (in the air), or take off (on the ground).
    Continue,
    /// The route does not hold its reserve, a direct return does.
    ReturnNow,
    /// Neither holds.
    LandNow,
    /// On the ground: the mission does not hold its reserve.
    DoNotTakeOff,
}

impl Advice {
    /// As the update and the link say it.
    pub(crate) fn as_str(self) -> &'static str {
        match self {
            Advice::Continue => "continue",
            Advice::ReturnNow => "return now",
            Advice::LandNow => "land now",
            Advice::DoNotTakeOff => "do not take off",
        }
    }

    /// How grave: the higher, the further from flying on.
    fn gravity(self) -> u8 {
        match self {
            Advice::Continue => 0,
            Advice::ReturnNow | Advice::DoNotTakeOff => 1,
            Advice::LandNow => 2,
        }
    }

    /// Whether it is the ground's advice (`None`: either).
    fn on_ground(self) -> Option<bool> {
        match self {
            Advice::Continue => None,
            Advice::DoNotTakeOff => Some(true),
            Advice::ReturnNow | Advice::LandNow => Some(false),
        }
    }
}

/// The shares of the scenarios that land with the reserve: what the advice is made from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Shares {
    /// The route ahead's.
    pub rest: f64,
    /// A direct return's, where it was flown (in the air, the rest not a return already, and
    /// the rest below [`P_HOLDS`] + [`RELAX_MARGIN`]).
    pub back: Option<f64>,
    /// In the air.
    pub in_air: bool,
    /// The route ahead is a return (or a landing) already.
    pub rest_is_return: bool,
}

impl Shares {
    /// Whether a direct return must be flown to advise (module docs).
    pub(crate) fn needs_back(rest: f64, in_air: bool, rest_is_return: bool) -> bool {
        in_air && !rest_is_return && rest < P_HOLDS + RELAX_MARGIN
    }

    /// The advice where `needed` of the scenarios must land with the reserve.
    fn advice(&self, needed: f64) -> Advice {
        if self.rest >= needed {
            Advice::Continue
        } else if !self.in_air {
            Advice::DoNotTakeOff
        } else if self.rest_is_return {
            Advice::LandNow
        } else if self.back.is_some_and(|b| b >= needed) {
            Advice::ReturnNow
        } else {
            Advice::LandNow
        }
    }
}

/// The advice given, and since when a milder one has held.
#[derive(Debug, Clone, Default)]
pub(crate) struct AdviceHold {
    given: Option<Advice>,
    /// When the milder advice started to hold, s of the stream.
    milder_since_s: Option<f64>,
}

impl AdviceHold {
    /// The advice at `now_s` from `shares` (module docs).
    pub(crate) fn advise(&mut self, now_s: f64, shares: &Shares) -> Advice {
        let strict = shares.advice(P_HOLDS);
        let with_margin = shares.advice(P_HOLDS + RELAX_MARGIN);
        let given = match self.given {
            // Taken off or landed since: another question.
            Some(g) if g.on_ground().is_none_or(|ground| ground != shares.in_air) => g,
            _ => return self.give(strict),
        };
        if strict.gravity() > given.gravity() {
            return self.give(strict);
        }
        if with_margin.gravity() >= given.gravity() {
            self.milder_since_s = None;
            return given;
        }
        let since = *self.milder_since_s.get_or_insert(now_s);
        // 1e-9 s: the stream's times are sums of steps; an update on the hold's end relaxes.
        if now_s - since >= RELAX_HOLD_S - 1e-9 {
            return self.give(with_margin);
        }
        given
    }

    fn give(&mut self, advice: Advice) -> Advice {
        self.given = Some(advice);
        self.milder_since_s = None;
        advice
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn air(rest: f64, back: Option<f64>) -> Shares {
        Shares {
            rest,
            back,
            in_air: true,
            rest_is_return: false,
        }
    }

    /// Graver at once; milder after 5 s at the margin, the wait started again by a graver
    /// answer; `land now` back to `return now`, then to `continue`.
    #[test]
    fn graver_at_once_milder_after_the_hold() {
        let mut h = AdviceHold::default();
        assert_eq!(h.advise(0.0, &air(1.0, None)), Advice::Continue);
        assert_eq!(h.advise(1.0, &air(0.9, Some(1.0))), Advice::ReturnNow);
        // Alternating: never back.
        for t in 2..12 {
            let s = match t % 2 {
                0 => air(1.0, None),
                _ => air(0.9, Some(1.0)),
            };
            assert_eq!(h.advise(f64::from(t), &s), Advice::ReturnNow, "{t}");
        }
        // At 0.96: holds, not with the margin: stays.
        for t in 12..20 {
            assert_eq!(
                h.advise(f64::from(t), &air(0.96, Some(1.0))),
                Advice::ReturnNow
            );
        }
        for t in 20..25 {
            assert_eq!(h.advise(f64::from(t), &air(0.98, None)), Advice::ReturnNow);
        }
        assert_eq!(h.advise(25.0, &air(0.98, None)), Advice::Continue);
        // Land now at once, then back by steps.
        assert_eq!(h.advise(26.0, &air(0.0, Some(0.0))), Advice::LandNow);
        assert_eq!(h.advise(27.0, &air(0.0, Some(1.0))), Advice::LandNow);
        assert_eq!(h.advise(32.0, &air(0.0, Some(1.0))), Advice::ReturnNow);
        assert_eq!(h.advise(33.0, &air(1.0, None)), Advice::ReturnNow);
        assert_eq!(h.advise(38.0, &air(1.0, None)), Advice::Continue);
    }

    /// On the ground `do not take off`, and in the air after it the air's answer at once.
    #[test]
    fn taking_off_starts_over() {
        let mut h = AdviceHold::default();
        let ground = Shares {
            rest: 0.5,
            back: None,
            in_air: false,
            rest_is_return: false,
        };
        assert_eq!(h.advise(0.0, &ground), Advice::DoNotTakeOff);
        assert_eq!(h.advise(1.0, &air(1.0, None)), Advice::Continue);
        let back = Shares {
            rest_is_return: true,
            ..air(0.5, None)
        };
        assert_eq!(h.advise(2.0, &back), Advice::LandNow);
        assert!(Shares::needs_back(0.96, true, false));
        assert!(!Shares::needs_back(0.98, true, false));
        assert!(!Shares::needs_back(0.5, true, true));
    }
}
