"""`aloft.endurance(payload_sweep=...)`: the CLI's `aloft endurance --payload-sweep` answer."""

from __future__ import annotations

import pytest

import aloft


@pytest.mark.parametrize("options, flags", [
    ({"payload_sweep": "0:1.5:0.25"}, ["--payload-sweep", "0:1.5:0.25"]),
    ({"payload_sweep": (0, 1.5, 0.25)}, ["--payload-sweep", "0:1.5:0.25"]),
    ({"payload_sweep": [0.1, 0.9, 0.2], "battery": "TB48D", "wind_speed": 5, "wind_from": 30,
      "course": 90, "reserve_percent": 20},
     ["--payload-sweep", "0.1:0.9:0.2", "--battery", "TB48D", "--wind-speed", "5",
      "--wind-from", "30", "--course", "90", "--reserve-percent", "20"]),
])
def test_payload_sweep_equals_cli(cli, options, flags):
    got = aloft.endurance(**options)
    assert got == cli.json("endurance", *flags)  # bit for bit: floats round-trip through JSON
    assert got["rows"], got
    for key in ("vehicle", "wind", "batteries", "rows", "notes"):
        assert key in got


def test_payload_sweep_rows_equal_single_endurance_answers():
    curve = aloft.endurance(payload_sweep="0:1:0.5")
    packs = [b["name"] for b in curve["batteries"]]
    assert "TB47D" in packs and "TB48D" in packs
    for row in curve["rows"]:
        single = aloft.endurance(payload_kg=row["payload_kg"], battery=row["battery"])
        for key in ("takeoff_mass_kg", "hover_power_w", "hover_endurance_s",
                    "max_endurance_speed_mps", "max_endurance_s", "max_range_speed_mps",
                    "max_range_m"):
            assert row[key] == single[key], (row["battery"], row["payload_kg"], key)


def test_payload_sweep_stops_at_the_maximum_takeoff_mass():
    curve = aloft.endurance(payload_sweep="0:2:0.25")
    for pack in curve["batteries"]:
        rows = [r for r in curve["rows"] if r["battery"] == pack["name"]]
        assert rows[-1]["payload_kg"] <= pack["max_payload_kg"] < rows[-1]["payload_kg"] + 0.25
        assert any(n.startswith(pack["name"] + ":") for n in curve["notes"])


@pytest.mark.parametrize("value, flag_value, why", [
    ("1:0:0.1", "1:0:0.1", "below START"),
    ("0:1:0", "0:1:0", "not positive"),
    ("a:b:c", "a:b:c", "not a number"),
    ((0, 1, float("nan")), "0:1:nan", "not a finite number"),
    ("0:1e9:1e-9", "0:1e9:1e-9", "more than the 1000"),
])
def test_bad_sweeps_refused_as_the_cli_refuses_them(cli, value, flag_value, why):
    cli_message = cli.error("endurance", "--payload-sweep", flag_value)
    with pytest.raises(aloft.AloftError, match="'payload_sweep' of aloft.endurance") as e:
        aloft.endurance(payload_sweep=value)
    # The same reason as the CLI's, after the option's name.
    reason = str(e.value).split(": ", 1)[1]
    assert why in reason
    assert cli_message.endswith(reason), (cli_message, reason)


def test_payload_sweep_excludes_a_payload_and_the_speed_sweep():
    with pytest.raises(aloft.AloftError, match="'payload_sweep' .* cannot be used with 'payload_kg'"):
        aloft.endurance(payload_sweep="0:1:0.5", payload_kg=0.5)
    with pytest.raises(aloft.AloftError, match="cannot be used with 'sweep_speed'"):
        aloft.endurance(payload_sweep="0:1:0.5", sweep_speed=1.0)
    with pytest.raises(aloft.AloftError, match="START:STOP:STEP"):
        aloft.endurance(payload_sweep=(0, 1))


def test_a_sweep_entirely_above_the_limit_is_refused(cli):
    cli_message = cli.error("endurance", "--payload-sweep", "50:60:1")
    with pytest.raises(aloft.AloftError, match="3.600 kg maximum take-off mass") as e:
        aloft.endurance(payload_sweep="50:60:1")
    assert cli_message.endswith(str(e.value)), (cli_message, str(e.value))
