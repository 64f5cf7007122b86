"""aloft.plan is `aloft plan MISSION -o DIR --format json` with the files' texts: the same answer
as the binary's, the same files; each file is flown by aloft.mission to its sortie's figures;
existing files are kept without force=True; a bad option is refused naming it."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Dict, List, Optional, Set

import pytest

import aloft

# The shared survey (a QGroundControl survey v5, 52 waypoints) in a wind the issue plans it in.
WIND_8 = {"reserve_percent": 70, "wind_speed": 8, "wind_from": 0}
WIND_8_FLAGS = ["--reserve-percent", "70", "--wind-speed", "8", "--wind-from", "0"]


def survey(data: Path) -> Path:
    return data / "missions" / "neilvaltec_test.plan"


def lines_segments() -> List[Dict[str, object]]:
    """Survey lines 1 km long, 40 m apart at 40 m height: more than one M100 pack."""
    segments: List[Dict[str, object]] = [
        {"kind": "take-off", "altitude_m": 40.0, "climb_rate_mps": 3.0}]
    for k in range(24):
        east, north = (1000.0 if k % 2 == 0 else 0.0), 40.0 * k
        segments.append({"kind": "leg", "east_m": east, "north_m": north})
        segments.append({"kind": "leg", "east_m": east, "north_m": north + 40.0})
    segments += [{"kind": "return"}, {"kind": "landing", "rate_mps": 1.0}]
    return segments


def lines_mission(folder: Path, fmt: str) -> Path:
    """The lines as an aloft TOML or JSON mission."""
    path = folder / f"lines.{fmt}"
    if fmt == "json":
        path.write_text(json.dumps(
            {"name": "lines", "default_speed_mps": 8.0, "segment": lines_segments()}))
        return path
    text = 'name = "lines"\ndefault_speed_mps = 8.0\n'
    for s in lines_segments():
        text += "[[segment]]\n" + "".join(
            f"{k} = {json.dumps(v)}\n" for k, v in s.items())
    path.write_text(text)
    return path


def mission_path(name: Optional[str], data: Path, folder: Path) -> Optional[Path]:
    if name is None:
        return None
    if name in ("lines.toml", "lines.json"):
        return lines_mission(folder, name.split(".")[1])
    return data / "missions" / name


# (mission: a shared file, the lines written here, or None for the demo; Python options; flags;
# whether the route needs several packs: 24 km of lines, or the survey at 70 % reserve, are
# beyond one M100 pack, so the comparison covers sorties cut inside legs and resumed)
CASES = [
    ("neilvaltec_test.plan", WIND_8, WIND_8_FLAGS, True),
    ("neilvaltec_test.plan", dict(WIND_8, keep_angle=True, camera_interval_s=3.5),
     WIND_8_FLAGS + ["--keep-angle", "--camera-interval-s", "3.5"], True),
    ("lines.toml",
     {"wind_speed": 6, "wind_from": 90, "overlap_m": 25, "max_speed": 12},
     ["--wind-speed", "6", "--wind-from", "90", "--overlap-m", "25", "--max-speed", "12"], True),
    ("lines.json", {"speeds": "energy", "reserve_percent": 30, "corners": "stop"},
     ["--speeds", "energy", "--reserve-percent", "30", "--corners", "stop"], True),
    ("ardupilot_DO_CHANGE_SPEED_mission.txt", {"reserve_percent": 80, "speeds": "keep"},
     ["--reserve-percent", "80", "--speeds", "keep"], False),
    (None, {"payload_kg": 0.3, "speed": 7.5}, ["--payload-kg", "0.3", "--speed", "7.5"], False),
]


CASE_IDS = ["survey", "survey-angle-kept", "lines.toml", "lines.json", "waypoints", "demo"]


@pytest.mark.parametrize("name, options, flags, several", CASES, ids=CASE_IDS)
def test_plan_equals_cli(cli, data, tmp_path, name, options, flags, several):
    """The answer is the binary's JSON key for key, bit for bit; `texts` are the files the
    binary wrote, byte for byte (the Python call writes the same files over them)."""
    path = mission_path(name, data, tmp_path)
    out = tmp_path / "out"
    rc, stdout, err = cli.run("plan", *([str(path)] if path else []), "-o", str(out), *flags,
                              "--format", "json")
    assert rc == 0, err
    expected = json.loads(stdout)
    written = [Path(f).read_text() for f in expected["files"]]
    got = aloft.plan(path, output=out, force=True, **options)
    texts = got.pop("texts")
    assert got == expected
    assert texts == written
    assert [Path(f).read_text() for f in got["files"]] == written
    assert len(texts) == got["batteries"] == len(got["sorties"]) >= 1
    if several:
        assert got["batteries"] >= 2 and got["changes"]["cut_inside_legs"] is True


def test_no_plan_is_an_answer_and_writes_nothing(cli, data, tmp_path):
    """A reserve no pack keeps on the survey's farthest leg: the binary exits 1 with
    `feasible: false` and its reason; Python answers the same (with no texts), no error."""
    out_cli, out_py = tmp_path / "cli", tmp_path / "py"
    expected = cli.json("plan", str(survey(data)), "-o", str(out_cli), "--reserve-percent", "95",
                        code=1)
    got = aloft.plan(survey(data), output=out_py, reserve_percent=95)
    assert got.pop("texts") == []
    assert got == expected
    assert got["feasible"] is False and "full pack" in got["reason"]
    assert not out_cli.exists() and not out_py.exists()


@pytest.mark.parametrize("keep_angle", [True, False])
def test_shared_survey_files_fly_their_sorties(data, tmp_path, keep_angle):
    """The shared survey at 70 % reserve in 8 m/s from the north, cut for the forecast alone
    (confidence 0.5): with its grid angle kept it takes 3 batteries (issue 33), turned to the
    wind fewer. Each file written, read back by aloft.mission in the same conditions, is
    feasible on one pack and flies to its sortie's energy and time; the plan needs no more
    batteries than aloft.mission gives the mission as it is."""
    out = tmp_path / "sorties"
    got = aloft.plan(survey(data), output=out, keep_angle=keep_angle, confidence=0.5, **WIND_8)
    if keep_angle:
        assert got["batteries"] == 3
        assert got["changes"]["angles"] == []
    else:
        assert 2 <= got["batteries"] <= 3
        assert len(got["changes"]["angles"]) == 1
    assert sorted(p.name for p in out.iterdir()) == sorted(Path(f).name for f in got["files"])
    assert len(got["files"]) == len(got["sorties"]) == len(got["texts"]) == got["batteries"]
    total_wh = 0.0
    for file, sortie, text in zip(got["files"], got["sorties"], got["texts"]):
        assert Path(file).read_text() == text
        assert sortie["file"] == file
        flown = aloft.mission(file, **WIND_8)
        assert flown["feasible"] is True, file
        assert flown["batteries_required"] == 1, file
        # The same planner in the same conditions; 1e-6 leaves room for the file's numbers
        # (coordinates written in degrees and read back) and nothing more.
        assert flown["energy_wh"] == pytest.approx(sortie["energy_wh"], rel=1e-6)
        assert flown["duration_s"] == pytest.approx(sortie["duration_s"], rel=1e-6)
        assert flown["end_soc"] >= flown["required_reserve_soc"] - 1e-12
        total_wh += flown["energy_wh"]
    assert total_wh == pytest.approx(got["energy_wh"], rel=1e-6)
    as_is = aloft.mission(survey(data), **WIND_8)
    assert got["batteries"] <= min(as_is["batteries_required"], got["as_given"]["batteries"])


def test_sorties_cut_at_95_percent_hold_in_a_fresh_draw(data, tmp_path):
    """Cut at the default confidence (0.95 of 400 scenarios, seed 1), every sortie of the shared
    survey at 70 % reserve in 8 m/s from the north lands with the reserve in at least 95 % of
    1000 other scenarios drawn by aloft.mission from its file (seed 7, the plan's spreads: wind
    2 m/s and 25 deg, capacity 3 %, power 3 %), within three standard errors of the share
    (3 sqrt(0.95 x 0.05 / 1000) = 0.021); cut for the forecast alone, the first sortie holds in
    about half."""
    sure = aloft.plan(survey(data), output=tmp_path / "sure", **WIND_8)
    nominal = aloft.plan(survey(data), output=tmp_path / "nominal", confidence=0.5, **WIND_8)
    assert sure["confidence"] == 0.95 and nominal["confidence"] == 0.5
    spreads = sure["scenarios"]["spreads"]
    assert spreads["wind_speed_sd_mps"] == 2.0 and spreads["wind_from_sd_deg"] == 25.0
    draw = dict(samples=1000, seed=7, wind_speed_sd=2.0, wind_from_sd=25.0,
                capacity_sd_percent=3.0, power_sd_percent=3.0, **WIND_8)
    for sortie in sure["sorties"]:
        assert sortie["p_reserve"] >= 0.95
        band = sortie["landing_soc"]
        assert band["p5"] <= band["p50"] <= band["p95"]
        flown = aloft.mission(sortie["file"], **draw)["uncertainty"]
        assert flown["p_feasible"] >= 0.95 - 0.021, sortie["file"]
    first = aloft.mission(nominal["sorties"][0]["file"], **draw)["uncertainty"]
    assert first["p_feasible"] < 0.7
    assert sure["batteries"] >= nominal["batteries"]


def test_overwrite_refused_without_force(cli, data, tmp_path):
    """Files that exist are kept: the refusal comes before any file is written, with the
    binary's message in Python's words (force=True for --force); force=True writes them all."""
    out = tmp_path / "out"
    first = aloft.plan(survey(data), output=out, **WIND_8)
    files = [Path(f) for f in first["files"]]
    files[1].write_text("the operator's edit")
    files[0].unlink()
    message = cli.error("plan", str(survey(data)), "-o", str(out), *WIND_8_FLAGS)
    assert "--force" in message
    with pytest.raises(aloft.AloftError) as e:
        aloft.plan(survey(data), output=out, **WIND_8)
    assert str(e.value) == message.replace("--force", "force=True")
    assert str(files[1]) in str(e.value)
    assert files[1].read_text() == "the operator's edit"
    assert not files[0].exists()
    again = aloft.plan(survey(data), output=out, force=True, **WIND_8)
    assert again == first
    assert [f.read_text() for f in files] == first["texts"]


def test_without_output_nothing_is_written(data, tmp_path, monkeypatch):
    """Without `output` the plan is answered, with its files' names and texts, and no file is
    written (the command line always writes: -o is required there)."""
    monkeypatch.chdir(tmp_path)
    got = aloft.plan(survey(data), **WIND_8)
    assert list(tmp_path.iterdir()) == []
    written = aloft.plan(survey(data), output=tmp_path / "out", **WIND_8)
    assert got["files"] == [Path(f).name for f in written["files"]]
    assert got["texts"] == written["texts"]
    assert got["sorties"] == [dict(s, file=Path(s["file"]).name) for s in written["sorties"]]


@pytest.mark.parametrize("options, flags", [
    ({"overlap_m": -5}, ["--overlap-m=-5"]),
    ({"overlap_m": 2000.0}, ["--overlap-m", "2000"]),
    ({"vehicle": "no-such-drone"}, ["--vehicle", "no-such-drone"]),
    ({"reserve_percent": 150}, ["--reserve-percent", "150"]),
    ({"max_speed": 0}, ["--max-speed", "0"]),
    ({"max_speed": 250.0}, ["--max-speed", "250"]),
    ({"camera_interval_s": 0}, ["--camera-interval-s", "0"]),
    ({"confidence": 0.3}, ["--confidence", "0.3"]),
    ({"confidence": 1.0}, ["--confidence", "1"]),
])
def test_bad_values_refused_with_the_clis_message(cli, tmp_path, options, flags):
    """The engine's refusal, as the binary prints it; nothing written."""
    out = tmp_path / "out"
    expected = cli.error("plan", "-o", str(out), *flags)
    with pytest.raises(aloft.AloftError) as e:
        aloft.plan(output=out, **options)
    assert str(e.value) == expected
    assert not out.exists()


@pytest.mark.parametrize("options, message", [
    ({"speeds": "fast"},
     "invalid value 'fast' for 'speeds' of aloft.plan: expected one of 'wind', 'energy', 'keep'"),
    ({"max_speed": "fast"}, "invalid value 'fast' for 'max_speed' of aloft.plan"),
    ({"max_speed": float("nan")}, "'max_speed' of aloft.plan: not a finite number"),
    ({"overlap_m": [1, 2]}, "'overlap_m' of aloft.plan: expected one value"),
    ({"reserve": 70}, "unknown option 'reserve' for aloft.plan"),
    ({"sweep_speed": 10}, "unknown option 'sweep_speed' for aloft.plan"),
    ({"wind_speed": 8}, "'wind_speed' of aloft.plan needs 'wind_from'"),
    ({"force": True}, "'force' of aloft.plan needs 'output'"),
    ({"wind_from_sd": 200},
     "invalid value '200' for 'wind_from_sd' of aloft.plan: a standard deviation from 0 to 180"),
])
def test_bad_option_raises_naming_it(tmp_path, monkeypatch, options, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(aloft.AloftError, match=re.escape(message)):
        aloft.plan(**options)
    assert list(tmp_path.iterdir()) == []


FLAG = re.compile(r"^\s+(?:-\w, )?--([a-z0-9-]+)", re.MULTILINE)


def test_keywords_are_the_plan_flags(cli):
    """The keywords are `aloft plan`'s flags (in snake case): those the
    engine parses are listed by an unknown keyword's refusal; `output` and `force` are
    arguments of the function, as `-o` and `--force` are the command's own."""
    rc, out, err = cli.run("plan", "--help")
    assert rc == 0, err
    flags: Set[str] = {f.replace("-", "_") for f in FLAG.findall(out)} - {"help"}
    assert {"output", "force", "format", "max_speed", "overlap_m", "speeds"} <= flags
    with pytest.raises(aloft.AloftError, match="unknown option 'no_such_option'") as e:
        aloft.plan(no_such_option=1)
    known = set(str(e.value).split("known options: ", 1)[1].split(", "))
    assert known == flags - {"output", "force", "format"}
