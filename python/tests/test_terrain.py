"""Issue 45 from Python: `aloft.mission(..., terrain=DIR)` is `aloft mission --terrain DIR`: the
same answer, each segment's least clearance over the shared SRTM3 tile and the reason naming the
ridge; `min_clearance_m=` is `--min-clearance-m`; a directory without tiles is an AloftError
naming it."""

from __future__ import annotations

from pathlib import Path

import pytest

import aloft


def test_the_ridge_is_judged_as_the_cli_judges_it(cli, repo: Path, data: Path) -> None:
    ridge = str(repo / "fixtures" / "missions" / "ridge-44n.toml")
    tiles = str(data / "terrain")
    got = aloft.mission(ridge, terrain=tiles)
    want = cli.json("mission", ridge, "--terrain", tiles, code=1)
    assert got == want
    assert got["feasible"] is False
    assert got["reason"].startswith("segment 2 (leg) passes 2.6 m above the ground")
    assert abs(got["segments"][1]["min_clearance_m"] - 2.6) < 0.05
    lower = aloft.mission(ridge, terrain=tiles, min_clearance_m=2)
    assert lower["feasible"] is True
    assert lower["min_clearance_m"] == got["min_clearance_m"]


def test_a_directory_without_tiles_is_an_error_naming_it(repo: Path, tmp_path: Path) -> None:
    ridge = str(repo / "fixtures" / "missions" / "ridge-44n.toml")
    with pytest.raises(aloft.AloftError) as e:
        aloft.mission(ridge, terrain=str(tmp_path))
    assert str(tmp_path) in str(e.value)
