"""Refusals raise AloftError (a ValueError) with the CLI's one-line message."""

from __future__ import annotations

import numpy as np
import pytest

import aloft


def test_aloft_error_is_value_error():
    assert issubclass(aloft.AloftError, ValueError)


@pytest.mark.parametrize("call, flags", [
    (lambda: aloft.mission(vehicle="no-such-drone"), ["mission", "--vehicle", "no-such-drone"]),
    (lambda: aloft.mission("no/such/mission.toml"), ["mission", "no/such/mission.toml"]),
    (lambda: aloft.mission(payload_kg=3.0), ["mission", "--payload-kg", "3"]),
    (lambda: aloft.mission("fixtures/missions/example.toml", speed=0.0, rtl_altitude_m=40),
     ["mission", "fixtures/missions/example.toml", "--speed", "0", "--rtl-altitude-m", "40"]),
    (lambda: aloft.mission(reserve_percent=150), ["mission", "--reserve-percent", "150"]),
    (lambda: aloft.mission(battery="no-such-pack"), ["mission", "--battery", "no-such-pack"]),
    (lambda: aloft.endurance(payload_kg=-1), ["endurance", "--payload-kg=-1"]),
    (lambda: aloft.log_info("fixtures/logs/kaist_missing_cur.csv"),
     ["log", "info", "fixtures/logs/kaist_missing_cur.csv"]),
    (lambda: aloft.fit("fixtures/logs/kaist_small.csv", "dji-m100", free="k,nonsense"),
     ["fit", "--log", "fixtures/logs/kaist_small.csv", "--vehicle-template", "dji-m100",
      "--free", "k,nonsense", "-o", "/dev/null"]),
    (lambda: aloft.power(5.0, 0.0, -5.0, aoa="geometric"),
     ["power", "--airspeed", "5", "--pitch", "-5", "--aoa", "geometric"]),
    (lambda: aloft.power(5.0, 0.0, -5.0, battery="TB55"),
     ["power", "--airspeed", "5", "--pitch", "-5", "--battery", "TB55"]),
    (lambda: aloft.power(0.0, 0.0, 0.0, payload_kg=2.0), ["power", "--payload-kg", "2"]),
    (lambda: aloft.power(0.0, 0.0, 0.0, vehicle="dji-m100-paper", battery="TB47D"),
     ["power", "--vehicle", "dji-m100-paper", "--battery", "TB47D"]),
    (lambda: aloft.endurance(vehicle="no/such/quad.toml"),
     ["endurance", "--vehicle", "no/such/quad.toml"]),
])
def test_message_is_the_clis(cli, repo, monkeypatch, call, flags):
    monkeypatch.chdir(repo)
    expected = cli.error(*flags)
    with pytest.raises(aloft.AloftError) as e:
        call()
    assert str(e.value) == expected
    assert "\n" not in str(e.value)


def test_power_names_the_refused_element(cli):
    expected = cli.error("power", "--airspeed", "5", "--roll", "95")
    with pytest.raises(aloft.AloftError) as e:
        aloft.power([5.0, 5.0, 5.0], [0.0, 95.0, 0.0], 0.0)
    assert str(e.value) == f"element 1: {expected}"


def test_non_finite_inputs_refused():
    with pytest.raises(aloft.AloftError, match="not a finite number"):
        aloft.power([1.0, np.nan], 0.0, 0.0)
    with pytest.raises(aloft.AloftError, match="'payload_kg'.*not a finite number"):
        aloft.mission(payload_kg=float("inf"))


def test_unknown_option_named():
    # An option no flag of `aloft mission` has.
    with pytest.raises(aloft.AloftError, match="unknown option 'sample' for aloft.mission"):
        aloft.mission(sample=100)
    # Scenario spreads without `samples`, as `--seed` without `--samples`.
    with pytest.raises(aloft.AloftError, match="need 'samples'"):
        aloft.mission(payload_sd_kg=0.2)
    with pytest.raises(aloft.AloftError, match="unknown option 'wind' for aloft.endurance"):
        aloft.endurance(wind=5)


def test_old_lag_of_log_info_says_its_new_name(cli, repo, monkeypatch):
    # `log info --lag` is now `--max-lag` (a search window; `lag` is the lag itself in fit and
    # validate): the old name is refused with the new one, never taken silently.
    monkeypatch.chdir(repo)
    log = "fixtures/logs/kaist_small.csv"
    with pytest.raises(aloft.AloftError, match="'lag' of aloft.log_info is now 'max_lag'"):
        aloft.log_info(log, lag=5.0)
    assert "--lag of log info is now --max-lag" in cli.error("log", "info", log, "--lag", "5")


def test_pairs_that_need_each_other():
    with pytest.raises(aloft.AloftError, match="'wind_speed' .* needs 'wind_from'"):
        aloft.mission(wind_speed=5)
    with pytest.raises(aloft.AloftError, match="'orbit_radius' .* needs 'orbit_speed'"):
        aloft.endurance(orbit_radius=50)
    with pytest.raises(aloft.AloftError, match="expected one of 'pass', 'stop'"):
        aloft.mission(corners="sideways")


def test_shapes_that_do_not_broadcast():
    with pytest.raises(aloft.AloftError, match="do not broadcast"):
        aloft.power(np.zeros(3), np.zeros(4), 0.0)
