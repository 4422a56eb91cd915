"""Shared fixtures: the repository root and the `moreau` command (for comparisons with the CLI).

The CLI is `$MOREAU_BIN` if that file exists, else the workspace's debug binary, built once per session with
`cargo build -q -p moreau` (a no-op after `cargo test --workspace`). Tests that need it are
skipped when neither cargo nor `$MOREAU_BIN` is available.
"""
import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Callable, List

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
WORKED = EXAMPLES / "worked-example.toml"


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


def _cli_exe() -> Path:
    exe = os.environ.get("MOREAU_BIN")
    if exe and Path(exe).is_file():
        return Path(exe)
    if shutil.which("cargo") is None:
        pytest.skip("comparison with the CLI needs cargo or $MOREAU_BIN")
    subprocess.run(["cargo", "build", "-q", "-p", "moreau"], cwd=ROOT, check=True)
    meta = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"], cwd=ROOT, check=True, capture_output=True, text=True
    )
    return Path(json.loads(meta.stdout)["target_directory"]) / "debug" / "moreau"


class Cli:
    def __init__(self, exe: Path) -> None:
        self.exe = exe

    def run(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run([str(self.exe), *map(str, args)], cwd=ROOT, capture_output=True, text=True, timeout=300)

    def json(self, *args: str):
        r = self.run(*args)
        assert r.returncode in (0, 1), r.stderr
        return json.loads(r.stdout)

    def error(self, *args: str) -> str:
        """The one-line message of a failing command, without `error: `."""
        r = self.run(*args)
        assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
        lines: List[str] = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
        return lines[0][len("error: "):]


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli(_cli_exe())
