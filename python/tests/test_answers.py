"""The Python answers equal the CLI's JSON for the same request, key for key, bit for bit."""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pandas as pd
import pytest

import aloft

MISSION_CASES = [
    # (path relative to the repo or None, Python options, CLI flags)
    (None, {}, []),
    (None, {"payload_kg": 0.5, "wind_speed": 6.0, "wind_from": 270.0},
     ["--payload-kg", "0.5", "--wind-speed", "6", "--wind-from", "270"]),
    ("fixtures/missions/demo-survey.toml",
     {"reserve_percent": 30, "corners": "stop", "speed": 6.5, "time_step": 0.2, "rtl_altitude_m": 40},
     ["--reserve-percent", "30", "--corners", "stop", "--speed", "6.5", "--time-step", "0.2",
      "--rtl-altitude-m", "40"]),
    ("fixtures/missions/example.toml",
     {"battery": None, "aoa": "paper", "no_ground_effect": True, "start_percent": 90,
      "wind_speed": 4, "wind_from": 45, "wind_profile": "power-law", "gust_std": 0.5, "gust_seed": 7},
     ["--aoa", "paper", "--no-ground-effect", "--start-percent", "90",
      "--wind-speed", "4", "--wind-from", "45", "--wind-profile", "power-law", "--gust-std", "0.5",
      "--gust-seed", "7"]),
    # The day's air: 2000 m, 30 C, 40 % humidity, QNH 1005 hPa.
    (None, {"elevation_m": 2000, "temperature_c": 30, "humidity_percent": 40, "qnh_hpa": 1005},
     ["--elevation-m", "2000", "--temperature-c", "30", "--humidity-percent", "40",
      "--qnh-hpa", "1005"]),
]


@pytest.mark.parametrize("path, options, flags", MISSION_CASES)
def test_mission_equals_cli(cli, repo, path, options, flags):
    args = ["mission"] + ([repo / path] if path else []) + flags
    rc, out, err = cli.run(*map(str, args), "--format", "json")
    assert rc in (0, 1), err
    got = aloft.mission(None if path is None else repo / path, **options)
    assert got == json.loads(out)


def test_planner_file_and_infeasible_mission_equal_cli(cli, data):
    plan = data / "missions" / "neilvaltec_test.plan"
    # A reserve the flight cannot keep: the CLI exits 1, Python answers feasible=False.
    expected = cli.json("mission", str(plan), "--reserve-percent", "95", code=1)
    got = aloft.mission(plan, reserve_percent=95)
    assert got == expected
    assert got["feasible"] is False


def test_mission_map_describes_the_mission_the_cli_answers(cli, data):
    """The map (aloft serve's /api/map) has a path per segment of the CLI's answer, in its order,
    starting at home; its state of charge runs from the start to the answer's end; with samples,
    the band is ordered."""
    plan = data / "missions" / "kasperg3_mission.plan"
    expected = cli.json("mission", str(plan), "--reserve-percent", "30")
    got = aloft.mission_map(plan, reserve_percent=30, samples=20)
    assert [s["index"] for s in got["segments"]] == [s["index"] for s in expected["segments"]]
    assert got["segments"][0]["points_m"][0] == [0.0, 0.0, 0.0]
    home = json.loads(plan.read_text())["mission"]["plannedHomePosition"]
    assert got["home"] == {"latitude_deg": home[0], "longitude_deg": home[1]}
    assert got["battery"]["soc"][0] == expected["start_soc"]
    assert got["battery"]["soc"][-1] == expected["end_soc"]
    band = got["band"]
    assert all(a <= b <= c for a, b, c in zip(band["p5"], band["p50"], band["p95"]))
    demo = aloft.mission_map()
    assert "home" not in demo and "band" not in demo


def test_windy_missions_fly_at_the_envelope_and_equal_cli(cli):
    # 12 m/s: the upwind lines are flown slower at the tilt limit (an answer with the time lost).
    slowed = aloft.mission(wind_speed=12, wind_from=250)
    assert slowed == cli.json("mission", "--wind-speed", "12", "--wind-from", "250")
    assert slowed["feasible"] is True and slowed["time_lost_s"] > 10
    assert {s.get("limit") for s in slowed["segments"]} >= {"tilt"}
    # 20 m/s: beyond the M100; infeasible (the CLI exits 1), with the reason, not an error.
    stuck = aloft.mission(wind_speed=20, wind_from=250)
    assert stuck == cli.json("mission", "--wind-speed", "20", "--wind-from", "250", code=1)
    assert stuck["feasible"] is False and "cannot hold its position" in stuck["reason"]


@pytest.mark.parametrize("options, flags", [
    ({}, []),
    ({"payload_kg": 0.4, "wind_speed": 7, "wind_from": 90, "course": 45, "reserve_percent": 20},
     ["--payload-kg", "0.4", "--wind-speed", "7", "--wind-from", "90", "--course", "45",
      "--reserve-percent", "20"]),
    ({"orbit_radius": 50, "orbit_speed": 8, "aoa": "paper"},
     ["--orbit-radius", "50", "--orbit-speed", "8", "--aoa", "paper"]),
    ({"sweep_speed": 2.0, "vehicle": "fixtures/vehicles/dji-m100.toml"},
     ["--sweep-speed", "2", "--vehicle", "fixtures/vehicles/dji-m100.toml"]),
])
def test_endurance_equals_cli(cli, repo, monkeypatch, options, flags):
    monkeypatch.chdir(repo)
    assert aloft.endurance(**options) == cli.json("endurance", *flags)


STATES = [
    (0.0, 0.0, 0.0, 0.0),
    (5.0, 0.0, -5.0, 0.0),
    (12.5, 3.0, -14.0, 1.5),
    (7.25, -2.5, -9.75, -1.0),
    (15.0, 10.0, -20.0, 2.0),
]


def test_power_equals_cli_per_state(cli):
    a, r, p, c = (np.array(x) for x in zip(*STATES))
    got = aloft.power(a, r, p, c, vehicle="dji-m100")
    for i, (va, vr, vp, vc) in enumerate(STATES):
        expected = cli.json("power", "--airspeed", repr(va), "--roll", repr(vr), "--pitch", repr(vp),
                            "--climb-rate", repr(vc))
        # The CLI's JSON also names the take-off mass and the air the arrays were computed at.
        assert set(expected) == set(aloft.POWER_KEYS) | {
            "takeoff_mass_kg", "battery", "payload_kg",
            "air_density_kg_m3", "density_source", "density_altitude_m"}
        assert expected["air_density_kg_m3"] == 1.225 and expected["density_source"] == "isa"
        assert expected["takeoff_mass_kg"] == 1.755 + 0.600  # airframe + TB47D, no payload
        for k in aloft.POWER_KEYS:
            assert got[k][i] == expected[k], (k, i)  # bit for bit, no tolerance


def test_power_options_equal_cli(cli):
    got = aloft.power([9.0], [1.0], [-11.0], [0.5], vehicle="dji-m100",
                      without=["profile", "climb"], air_direction_deg=[20.0])
    expected = cli.json("power", "--vehicle", "dji-m100", "--airspeed", "9", "--roll", "1",
                        "--pitch", "-11", "--climb-rate", "0.5", "--without", "profile,climb",
                        "--air-direction-deg", "20")
    assert {k: float(got[k][0]) for k in aloft.POWER_KEYS} == {k: expected[k] for k in aloft.POWER_KEYS}
    got = aloft.power(14.0, 0.0, -16.0, profile_cutoff=10.0)
    expected = cli.json("power", "--airspeed", "14", "--pitch", "-16", "--profile-cutoff", "10")
    assert {k: float(got[k]) for k in aloft.POWER_KEYS} == {k: expected[k] for k in aloft.POWER_KEYS}


def test_power_in_the_days_air_equals_cli(cli):
    got = aloft.power(0.0, 0.0, 0.0, elevation_m=3000, temperature_c=-4.5)
    expected = cli.json("power", "--airspeed", "0", "--elevation-m", "3000", "--temperature-c", "-4.5")
    assert {k: float(got[k]) for k in aloft.POWER_KEYS} == {k: expected[k] for k in aloft.POWER_KEYS}
    sea = aloft.power(0.0, 0.0, 0.0)
    # Hover at a fixed mass: every term of eq (14) scales by sqrt(rho0 / rho), 1.161 at 3000 m ISA.
    assert abs(float(got["electrical_w"] / sea["electrical_w"]) - (1.225 / expected["air_density_kg_m3"]) ** 0.5) < 1e-9
    assert abs(expected["air_density_kg_m3"] - 0.9091) < 0.001


def test_power_takeoff_mass_options_equal_cli(cli):
    """`battery=` and `payload_kg=` are `--battery` and `--payload-kg`: the same take-off mass."""
    got = aloft.power([0.0, 8.0], 0.0, [0.0, -9.0], vehicle="dji-m100", battery="TB48D",
                      payload_kg=0.4)
    for i, (va, vp) in enumerate([(0.0, 0.0), (8.0, -9.0)]):
        expected = cli.json("power", "--airspeed", repr(va), "--pitch", repr(vp),
                            "--battery", "TB48D", "--payload-kg", "0.4")
        assert expected["takeoff_mass_kg"] == 1.755 + 0.676 + 0.4
        for k in aloft.POWER_KEYS:
            assert got[k][i] == expected[k], (k, i)
    # The power seed's validation case flies its own 3.29 kg.
    paper = aloft.power(0.0, 0.0, 0.0, vehicle="dji-m100-paper")
    assert abs(paper["thrust_n"] - 3.29 * 9.8066) < 1e-9


def test_timeseries_equals_cli_csv(cli, tmp_path):
    csv = tmp_path / "ts.csv"
    rc, _, err = cli.run("mission", "--payload-kg", "0.3", "--timeseries", str(csv))
    assert rc == 0, err
    expected = pd.read_csv(csv, float_precision="round_trip")
    got = aloft.timeseries(payload_kg=0.3)
    assert isinstance(got, pd.DataFrame)
    assert list(got.columns) == list(expected.columns)
    assert len(got) == len(expected) > 100
    for col in expected.columns:
        e, g = expected[col].to_numpy(), got[col].to_numpy()
        assert np.array_equal(g, e, equal_nan=g.dtype.kind == "f"), col
    assert got["segment"].dtype == np.int64


def test_log_info_equals_cli(cli, repo, data):
    log = repo / "fixtures" / "logs" / "kaist_small.csv"
    assert aloft.log_info(log) == cli.json("log", "info", str(log))
    log = sorted((data / "kaist_energy_drone").glob("2018-08-03*.csv"))[0]
    assert aloft.log_info(str(log), profile="kaist", max_lag=5.0) == cli.json(
        "log", "info", str(log), "--profile", "kaist", "--max-lag", "5")


def test_fit_and_validate_equal_cli(cli, repo, data, tmp_path):
    kaist = data / "kaist_energy_drone"
    train = sorted(kaist.glob("2018-08-03*.csv"))[0]
    test = sorted(kaist.glob("2018-08-06*.csv"))[0]
    template = repo / "fixtures" / "vehicles" / "kaist-template.toml"
    cli_toml, py_toml = tmp_path / "cli.toml", tmp_path / "py.toml"
    expected = cli.json("fit", "--log", str(train), "--profile", "kaist", "--vehicle-template",
                        str(template), "-o", str(cli_toml))
    got = aloft.fit(train, str(template), profile="kaist", output=py_toml)
    assert (got.pop("output"), expected.pop("output")) == (str(py_toml), str(cli_toml))
    assert got == expected
    assert py_toml.read_text() == cli_toml.read_text()
    expected = cli.json("validate", "--log", str(test), "--profile", "kaist", "--vehicle",
                        str(cli_toml), "--calibrate-first", "120")
    got = aloft.validate([test], str(py_toml), profile="kaist", calibrate_first=120)
    assert got == expected
    assert math.isfinite(got["flights"][0]["energy_error_percent"])
    # The fitted vehicle is a power model alone: its [power] mass + the payload.
    expected = cli.json("validate", "--log", str(test), "--profile", "kaist", "--vehicle",
                        str(cli_toml), "--payload-kg", "0.5")
    got = aloft.validate([test], str(py_toml), profile="kaist", payload_kg=0.5)
    assert got == expected
    assert got["takeoff_mass_kg"] == 8.0 + 0.5  # kaist-template's guessed 8 kg


def test_monte_carlo_mission_equals_cli(cli):
    """`samples` and the spreads, as `aloft mission --samples N ...`: the same uncertainty."""
    flags = ["--samples", "64", "--seed", "3", "--payload-sd-kg", "0.2", "--wind-speed-sd", "1",
             "--threads", "1"]
    rc, out, err = cli.run("mission", *flags, "--format", "json")
    assert rc in (0, 1), err
    got = aloft.mission(samples=64, seed=3, payload_sd_kg=0.2, wind_speed_sd=1.0, threads=1)
    assert got == json.loads(out)
    assert got["uncertainty"]["samples"] == 64


def test_live_replay_equals_cli(cli, data):
    """``aloft.live`` is ``aloft live --replay LOG --format json``: the same updates and check
    (the validation replay) or summary (the route ahead from the log's events)."""
    log = data / "flight_logs" / "sitl_ac47_00000002.BIN"
    for route, end in (("log", "check"), ("mission", "summary")):
        rc, out, err = cli.run("live", "--replay", str(log), "--route", route, "--vehicle",
                               "dji-m100", "--every", "5", "--format", "json")
        assert rc == 0, err
        lines = [json.loads(line) for line in out.splitlines()]
        got = aloft.live(log, "dji-m100", route=route, every=5)
        assert got["updates"] == lines[:-1]
        assert got[end] == lines[-1][end]
        assert len(got["updates"]) >= 2


def test_live_failsafes_and_the_pack_state_equal_cli(cli, data):
    """Issue 44: the failsafe thresholds reach ``aloft.live`` as on the command line: the
    updates carry ``failsafes`` (the flag's, as the source) and ``soc_band`` where the pack is
    the vehicle's own (this log's 4S-size simulator pack is not the M100's 6S: its reports)."""
    log = data / "flight_logs" / "sitl_ac47_00000002.BIN"
    rc, out, err = cli.run("live", "--replay", str(log), "--vehicle", "dji-m100", "--every", "5",
                           "--low-voltage-v", "10.5", "--format", "json")
    assert rc == 0, err
    lines = [json.loads(line) for line in out.splitlines()]
    got = aloft.live(log, "dji-m100", every=5, low_voltage_v=10.5)
    assert got["updates"] == lines[:-1]
    sources = {f["source"] for u in got["updates"] for f in u.get("failsafes", [])}
    assert sources <= {"--low-voltage-v", "BATT_LOW_VOLT", "BATT_CRT_VOLT", "BATT_LOW_MAH",
                       "BATT_CRT_MAH"}, sources


def test_mission_from_a_rested_voltage_equals_cli(cli):
    """``start_voltage_v``: the M100's 6S pack rested at 3.58 V a cell starts at 4.56 % on the
    generic LiPo curve (5 % x (3.58 - 3.27) / (3.61 - 3.27)), with the failsafe's band."""
    flags = ["--start-voltage-v", "21.48", "--critical-voltage-v", "19.8", "--samples", "20"]
    rc, out, err = cli.run("mission", *flags, "--format", "json")
    assert rc in (0, 1), err
    got = aloft.mission(start_voltage_v=21.48, critical_voltage_v=19.8, samples=20)
    assert got == json.loads(out)
    assert abs(got["start_soc"] - 0.05 * (3.58 - 3.27) / (3.61 - 3.27)) < 1e-9
    assert got["uncertainty"]["failsafes"][0]["kind"] == "critical"
    with pytest.raises(aloft.AloftError, match="start_voltage_v"):
        aloft.mission(start_voltage_v=5.0)


def test_live_refuses_bad_options_and_links(data):
    log = data / "flight_logs" / "sitl_ac47_00000002.BIN"
    with pytest.raises(aloft.AloftError, match="every"):
        aloft.live(log, "dji-m100", every=0)
    with pytest.raises(aloft.AloftError, match="live"):
        aloft.live(log, "dji-m100", speed="fast")
    with pytest.raises(aloft.AloftError, match="low-voltage-v"):
        aloft.live(log, "dji-m100", low_voltage_v=-1)


def test_fit_of_an_own_vehicle_equals_cli(cli, data, tmp_path):
    """Without a template: the owner's flags, a per-log payload; the missing flag is named."""
    logs = sorted((data / "px4_flugdrohne" / "ulg").glob("*.ulg"))
    with_payload = [str(logs[0])] + [f"{p}:payload_kg=0.3" for p in logs[1:]]
    owner = {"mass_kg": 1.2, "rotor_diameter_m": 0.254, "battery_capacity_mah": 5000}
    cli_toml, py_toml = tmp_path / "quad.toml", tmp_path / "py" / "quad.toml"
    py_toml.parent.mkdir()
    args = ["fit"]
    for p in with_payload:
        args += ["--log", p]
    expected = cli.json(*args, "--mass-kg", "1.2", "--rotor-diameter-m", "0.254",
                        "--battery-capacity-mah", "5000", "-o", str(cli_toml))
    got = aloft.fit(with_payload, output=py_toml, **owner)
    assert (got.pop("output"), expected.pop("output")) == (str(py_toml), str(cli_toml))
    assert got == expected
    assert [s["file"] for s in got["skipped_logs"]] == [str(logs[3])]  # log_65
    assert py_toml.read_text() == cli_toml.read_text()
    # The file read back by Python's own TOML reader: the envelope is the logs' PX4 parameters
    # (MPC_TILTMAX_AIR 45, the smaller MPC_XY_VEL_MAX 12), the pack 3S at the stated capacity.
    written = tomllib.loads(py_toml.read_text())
    assert written["airframe"]["max_tilt_deg"] == 45.0
    assert written["airframe"]["max_speed_mps"] == 12.0
    assert written["battery"][0]["cells_series"] == 3
    assert written["battery"][0]["capacity_mah"] == 5000.0
    assert written["airframe"]["mass_kg"] + written["battery"][0]["mass_kg"] == pytest.approx(1.2)
    with pytest.raises(aloft.AloftError, match="--mass-kg"):
        aloft.fit(logs, rotor_diameter_m=0.254)
