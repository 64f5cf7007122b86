"""The keyword arguments are the CLI's flags in snake_case: walk each command's flags (from its
`--help`) and compare them with the options the Python function knows (listed by the error an
unknown keyword raises). Both come from the engine's one description of the options; this test
fails when a flag is added to one front end only."""

from __future__ import annotations

import inspect
import re
from typing import Callable, Set

import numpy as np
import pytest

import aloft
from aloft import _native

FLAG = re.compile(r"^\s+(?:-\w, )?--([a-z0-9-]+)", re.MULTILINE)


def cli_flags(cli, *command: str) -> Set[str]:
    rc, out, err = cli.run(*command, "--help")
    assert rc == 0, err
    return {f.replace("-", "_") for f in FLAG.findall(out)} - {"help"}


def python_options(call: Callable[..., object]) -> Set[str]:
    with pytest.raises(aloft.AloftError, match="unknown option 'no_such_option'") as e:
        call(no_such_option=1)
    known = str(e.value).split("known options: ", 1)[1]
    return set(known.split(", "))


LOG = "fixtures/logs/kaist_small.csv"
ZERO = np.zeros(1)

# (command, the Python function with its positional arguments, flags only the CLI has (output
# formats and files and --force to replace them, the replay of a log, the flight state of `power`), flags Python takes as
# positional arguments)
CASES = [
    (("mission",), lambda **o: aloft.mission(None, **o),
     {"format", "timeseries", "plot", "mcap", "replay", "profile", "lag", "acceleration",
      "acceleration_window", "force"}, set()),
    (("endurance",), lambda **o: aloft.endurance(**o), {"format", "plot", "force"}, set()),
    (("log", "info"), lambda **o: aloft.log_info(LOG, **o), {"format"}, set()),
    (("fit",), lambda **o: aloft.fit(LOG, "dji-m100", **o), {"format"},
     {"log", "vehicle_template"}),
    (("validate",), lambda **o: aloft.validate(LOG, "dji-m100", **o), {"format", "plot", "force"},
     {"log", "vehicle"}),
    # aloft.power names its keywords in its signature (checked below); the engine's parser is
    # reached through the native function.
    (("power",), lambda **o: _native.power(ZERO, ZERO, ZERO, ZERO, None, o),
     {"format", "airspeed", "roll", "pitch", "climb_rate", "air_direction_deg", "gradient",
      "input", "output", "force"}, set()),
]


@pytest.mark.parametrize("command, call, cli_only, positional", CASES,
                         ids=[" ".join(c[0]) for c in CASES])
def test_keywords_are_the_cli_flags(cli, repo, monkeypatch, command, call, cli_only, positional):
    monkeypatch.chdir(repo)
    flags = cli_flags(cli, *command)
    # The CLI-only flags named here exist (a renamed flag must not pass silently).
    assert cli_only <= flags, cli_only - flags
    assert python_options(call) == flags - cli_only - positional


def test_the_mission_series_takes_the_mission_flags(cli):
    scenario = {"samples", "seed", "wind_speed_sd", "wind_from_sd", "payload_sd_kg",
                "capacity_sd_percent", "power_sd_percent", "threads"}
    mission_only = {"format", "timeseries", "plot", "mcap", "replay", "profile", "lag",
                    "acceleration", "acceleration_window", "force"}
    expected = cli_flags(cli, "mission") - mission_only - scenario
    assert python_options(lambda **o: aloft.timeseries(None, **o)) == expected


def test_a_keyword_parses_as_its_flag():
    # Values reach the engine's parser as the CLI's words: a range, a choice and a pair.
    with pytest.raises(aloft.AloftError, match="'threads' of aloft.mission"):
        aloft.mission(samples=2, threads=5000)
    with pytest.raises(aloft.AloftError, match="expected one of 'geometric', 'paper'"):
        aloft.endurance(aoa="exact")
    with pytest.raises(aloft.AloftError, match="'payload_sd_kg' of aloft.mission needs 'samples'"):
        aloft.mission(payload_sd_kg=0.1)
    with pytest.raises(aloft.AloftError, match="'log' for aloft.fit"):
        aloft.fit(LOG, "dji-m100", log=LOG)


def test_the_power_signature_names_the_model_flags():
    states = {"airspeed", "roll", "pitch", "climb_rate", "air_direction_deg"}
    named = set(inspect.signature(aloft.power).parameters) - states
    assert named == python_options(lambda **o: _native.power(ZERO, ZERO, ZERO, ZERO, None, o))
