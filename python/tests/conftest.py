"""Fixtures of the Python tests: the repository, and the `rtid` binary whose results
the module must reproduce (RTID_BIN, else the tests' build, else the release one)."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def rtid_bin() -> str:
    given = os.environ.get("RTID_BIN")
    candidates = [given] if given else [ROOT / "target/test-release/rtid", ROOT / "target/release/rtid"]
    for c in candidates:
        if c and Path(c).is_file():
            return str(c)
    pytest.fail(f"no rtid binary to compare with (tried {', '.join(map(str, candidates))}): "
                "build it (cargo build --profile test-release) or set RTID_BIN")


@pytest.fixture(scope="session")
def cli(rtid_bin):
    """Runs `rtid ARGS… --quiet` in the repository; returns stdout (JSON parsed with json=True)."""

    def run(*args, json_out=False):
        out = subprocess.run([rtid_bin, *map(str, args), "--quiet"], cwd=ROOT, check=True,
                             capture_output=True, text=True).stdout
        return json.loads(out) if json_out else out

    return run
