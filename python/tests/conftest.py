"""Shared fixtures: the repository, the `aloft` binary the answers are compared with, the data."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import List, Tuple

import pytest

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("ALOFT_DATA_DIR", REPO.parent / "shared" / "data"))


def _binary() -> Path:
    """`$ALOFT_BIN`, else the workspace's debug build (built here when missing).

    The binary must be built from the same tree as the package: a CLI from another checkout
    can differ (e.g. in which drag terms `aloft fit` keeps).
    """
    if os.environ.get("ALOFT_BIN"):
        return Path(os.environ["ALOFT_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    binary = target / "debug" / "aloft"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--locked", "--bin", "aloft"], cwd=REPO, check=True)
    return binary


class Cli:
    """Runs the `aloft` binary."""

    def __init__(self, binary: Path) -> None:
        self.binary = binary

    def run(self, *args: str) -> Tuple[int, str, str]:
        p = subprocess.run([str(self.binary), *args], capture_output=True, text=True, cwd=REPO)
        return p.returncode, p.stdout, p.stderr

    def json(self, *args: str, code: int = 0) -> dict:
        rc, out, err = self.run(*args, "--format", "json")
        assert rc == code, (rc, err)
        return json.loads(out)

    def error(self, *args: str) -> str:
        """The one-line message of a refused request (exit 2), without `aloft: error: `."""
        rc, out, err = self.run(*args)
        assert rc == 2, (rc, out, err)
        lines: List[str] = err.strip().splitlines()
        assert len(lines) == 1, err
        prefix = "aloft: error: "
        assert lines[0].startswith(prefix), lines[0]
        return lines[0][len(prefix):]


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli(_binary())


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def data() -> Path:
    if not DATA.is_dir():
        pytest.fail(f"ALOFT_DATA_DIR={DATA} does not exist (the shared data is needed)")
    return DATA
