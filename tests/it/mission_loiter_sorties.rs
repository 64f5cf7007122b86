//! A loiter until the reserve and a route split into sorties, through the engine: each answer is
//! checked against flights the test makes itself and against an energy budget.

use aloft::engine::{plan_mission, Mission, MissionOptions, Plan, Vehicle};

use crate::common;
use aloft_planner::mission_toml::{landing, take_off};
use common::assert_warned;

fn plan(text: &str) -> Plan {
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let mission = Mission::from_text(text, "test").unwrap();
    plan_mission(&m100, &mission, &MissionOptions::default()).unwrap()
}

/// Out 1 km at the default 8 m/s (item 2), then a loiter until the reserve (item 3).
fn loiter() -> String {
    let out = "[[segment]]\nkind = \"leg\"\neast_m = 1000.0\nnorth_m = 0.0\nitem = 2\n";
    let until_reserve = "[[segment]]\nkind = \"loiter-until-reserve\"\nitem = 3\n";
    format!(
        "name = \"loiter\"\ndefault_speed_mps = 8.0\n{}{out}{until_reserve}",
        take_off(30.0, 2.0)
    )
}

/// The same route with a hover of `hover_s` and the way home written out by hand.
fn loiter_by_hand(hover_s: f64) -> String {
    let route = loiter().replace("kind = \"loiter-until-reserve\"\nitem = 3\n", "");
    format!(
        "{route}kind = \"hover\"\nduration_s = {hover_s}\n[[segment]]\nkind = \"return\"\n[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n"
    )
}

#[test]
fn the_loiter_is_the_last_second_that_lands_with_the_reserve() {
    let p = plan(&loiter());
    let s = p.summary();
    let l = s.loiter.as_ref().expect("a loiter answer");
    assert_eq!(l.item, Some(3));
    assert_eq!(l.segment, 3);
    assert!(s.feasible);
    // 99.9 Wh, 80 % usable above the reserve, about 270 W hover: 12 to 16 minutes.
    assert!(l.duration_s > 600.0 && l.duration_s < 1200.0, "{l:?}");
    assert_eq!(l.duration_s, l.duration_s.floor());
    // The same flight written by hand: one more second no longer lands with the reserve.
    let ok = plan(&loiter_by_hand(l.duration_s));
    let late = plan(&loiter_by_hand(l.duration_s + 1.0));
    assert!(ok.summary().feasible);
    assert!(!late.summary().feasible, "{:?}", late.summary().reason);
    assert_eq!(ok.summary().energy_wh, s.energy_wh);
    // The loiter begins where the route ends: take-off and leg.
    let route_s: f64 = s.segments[..2].iter().map(|x| x.duration_s).sum();
    assert!((l.start_s - route_s).abs() < 1e-9);
    // It lands within one second of hovering (about 0.1 % of the capacity) above the floor.
    let margin = s.reserve_soc - s.required_reserve_soc;
    assert!((0.0..2e-3).contains(&margin), "margin {margin}");
}

/// A lawn-mower survey too long for one pack: 24 lines of 1500 m, 30 m apart, at 10 m/s.
fn long_survey() -> String {
    let mut t = String::from(
        "name = \"long\"\ndefault_speed_mps = 10.0\n[[segment]]\nkind = \"take-off\"\naltitude_m = 40.0\nclimb_rate_mps = 2.5\nitem = 1\n",
    );
    let mut item = 2;
    for line in 0..24 {
        let north = 100.0 + 30.0 * f64::from(line);
        let (a, b) = if line % 2 == 0 {
            (0.0, 1500.0)
        } else {
            (1500.0, 0.0)
        };
        for east in [a, b] {
            t += &format!(
                "[[segment]]\nkind = \"leg\"\neast_m = {east}\nnorth_m = {north}\nitem = {item}\n"
            );
            item += 1;
        }
    }
    t += &format!("[[segment]]\nkind = \"return\"\nitem = {item}\n[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\nitem = {}\n", item + 1);
    t
}

#[test]
fn a_route_one_pack_cannot_fly_is_split_into_sorties_that_each_land_with_the_reserve() {
    let p = plan(&long_survey());
    let s = p.summary();
    assert!(!s.feasible);
    let n = s.batteries_required.expect("a split");
    assert_eq!(n as usize, s.sorties.len());
    assert!(n >= 2);
    // Contiguous, covering the whole mission, in order.
    assert_eq!(s.sorties[0].first_segment, 1);
    assert_eq!(s.sorties[0].first_item, Some(1));
    for w in s.sorties.windows(2) {
        assert_eq!(w[1].first_segment, w[0].last_segment + 1);
    }
    let segments = 2 + 48 + 1;
    assert_eq!(s.sorties[n as usize - 1].last_segment, segments);
    assert_eq!(s.sorties[n as usize - 1].last_item, Some(51));
    // Each sortie lands with the reserve: 20 % of the usable charge.
    let empty = p.report().empty_soc;
    for x in &s.sorties {
        assert!(x.end_soc - empty >= s.required_reserve_soc, "{x:?}");
    }
    // Energy budget: the survey's lines alone (48 legs) cost at least what the single-pack
    // flight paid per metre; every pack gives at most its usable 80 % above the 20 % reserve.
    let lines_m = 24.0 * 1500.0 + 23.0 * 30.0;
    let wh_per_m = s.segments[2].energy_wh / s.segments[2].distance_m;
    let usable_wh = 99.9 * (1.0 - s.required_reserve_soc);
    let lower = (lines_m * wh_per_m / usable_wh).ceil() as u32;
    assert!(n >= lower, "{n} sorties, at least {lower} by energy");
    assert!(
        n <= lower + 2,
        "{n} sorties, {lower} by energy: the greedy split wastes packs"
    );
    // Together they fly more than the single pack could (its flight ran out mid-route).
    let total: f64 = s.sorties.iter().map(|x| x.energy_wh).sum();
    assert!(total > s.energy_wh);
}

#[test]
fn a_survey_that_ends_in_the_air_is_priced_with_its_way_home_and_split_like_any_other() {
    // The long survey as a QGroundControl survey often is: no return, no landing (the vehicle
    // comes home by its mission-end action). aloft adds that way home (a return at the planning
    // speed and RTL altitude, a landing at 1 m/s): the same flight as the survey that writes it
    // out, so the same sorties, pack for pack.
    let closed = long_survey();
    let end = closed.find("[[segment]]\nkind = \"return\"").unwrap();
    let open = format!("allow_end_in_air = true\n{}", &closed[..end]);
    let (a, b) = (plan(&open), plan(&closed));
    let (a, b) = (a.summary(), b.summary());
    assert_warned(&a.warnings, "ends in the air after item 49");
    assert_eq!(a.segments.len(), b.segments.len());
    assert!(a.batteries_required.is_some() && a.batteries_required == b.batteries_required);
    for (x, y) in a.sorties.iter().zip(&b.sorties) {
        assert_eq!(x.energy_wh, y.energy_wh);
        assert_eq!(x.end_soc, y.end_soc);
    }
    // On one pack both run out at the same place.
    assert_eq!(a.energy_wh, b.energy_wh);
    assert_eq!(a.reason, b.reason);
}

#[test]
fn a_mission_one_pack_flies_needs_one_battery_and_lists_no_sorties() {
    let s = plan(aloft::engine::DEMO_MISSION);
    assert!(s.summary().feasible);
    assert_eq!(s.summary().batteries_required, Some(1));
    assert!(s.summary().sorties.is_empty());
    let json = s.to_json().unwrap();
    assert!(json.contains("\"batteries_required\": 1"));
    assert!(!json.contains("sorties"));
}

#[test]
fn a_leg_too_long_for_one_pack_cannot_be_split_and_says_so() {
    let far = "[[segment]]\nkind = \"leg\"\neast_m = 40000.0\nnorth_m = 0.0\nitem = 2\n";
    let text = format!(
        "default_speed_mps = 10.0\n{}{far}[[segment]]\nkind = \"return\"\n{}",
        take_off(30.0, 2.0),
        landing(1.0)
    );
    let s = plan(&text);
    let s = s.summary();
    assert!(!s.feasible);
    assert_eq!(s.batteries_required, None);
    assert_warned(
        &s.warnings,
        "item 2 (leg) cannot be flown from home and back",
    );
}
