"""`aloft.vehicles()` and `aloft.calibrate_vehicle()`: the CLI's `aloft vehicles` answers."""

from __future__ import annotations

import json
import os

import pytest

import aloft

SPEC = os.path.join(os.path.dirname(__file__), "..", "..", "fixtures", "vehicles", "specs",
                    "dji-m600.toml")


def test_vehicles_equals_cli(cli):
    got = aloft.vehicles()
    assert got == cli.json("vehicles")
    names = [v["name"] for v in got]
    assert names[:4] == ["dji-m100", "dji-m600", "dji-inspire1", "dji-inspire1-pro"]
    assert "2xTB48D" in got[0]["batteries"]
    assert "hover 35 min" in got[1]["source"]["calibrated_on"]


def test_calibrate_vehicle_equals_cli_and_writes_a_vehicle(cli, tmp_path):
    out = tmp_path / "m600.toml"
    got = aloft.calibrate_vehicle(SPEC, out)
    cli_out = tmp_path / "m600-cli.toml"
    assert got == cli.json("vehicles", "calibrate", SPEC, "-o", str(cli_out))
    assert out.read_text() == cli_out.read_text()
    assert abs(got["efficiency"] - 0.4995) < 1e-4
    hover = aloft.endurance(vehicle=str(out))
    assert abs(hover["hover_endurance_s"] / 60 - 35.0) < 0.01


def test_bad_spec_raises_with_the_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(open(SPEC).read().replace("rotors = 6", "rotors = 0"))
    with pytest.raises(aloft.AloftError, match="rotors"):
        aloft.calibrate_vehicle(bad, tmp_path / "out.toml")
    assert not (tmp_path / "out.toml").exists()
