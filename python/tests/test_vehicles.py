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


def test_calibrate_vehicle_keeps_an_existing_file_without_force(cli, tmp_path):
    """aloft's one way of writing a file, from Python: an existing file is kept (the CLI's
    message in Python's words), force=True replaces it, and a planted link is never written
    through (force=True replaces the link itself)."""
    out = tmp_path / "m600.toml"
    out.write_text("the operator's own file")
    message = cli.error("vehicles", "calibrate", SPEC, "-o", str(out))
    assert "--force" in message
    with pytest.raises(aloft.AloftError) as e:
        aloft.calibrate_vehicle(SPEC, out)
    assert str(e.value) == message.replace("--force", "force=True")
    assert out.read_text() == "the operator's own file"
    aloft.calibrate_vehicle(SPEC, out, force=True)
    assert "[power]" in out.read_text()
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    link = tmp_path / "link.toml"
    link.symlink_to(victim)
    with pytest.raises(aloft.AloftError, match="exists"):
        aloft.calibrate_vehicle(SPEC, link)
    aloft.calibrate_vehicle(SPEC, link, force=True)
    assert not link.is_symlink() and "[power]" in link.read_text()
    assert victim.read_text() == "precious"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".aloft-")] == []
