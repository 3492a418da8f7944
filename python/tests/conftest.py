"""Shared fixtures: the repository's paths and the clayc binary to compare against."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
GRAMMARS = ROOT / "grammars"


def _target_dir() -> Path:
    return Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))


@pytest.fixture(scope="session")
def clayc() -> str:
    """The clayc binary: $CLAYC, else the newest one cargo built, else a fresh debug build."""
    given = os.environ.get("CLAYC")
    if given:
        return given
    built = [
        p for p in (_target_dir() / "release" / "clayc", _target_dir() / "debug" / "clayc") if p.is_file()
    ]
    if built:
        return str(max(built, key=lambda p: p.stat().st_mtime))
    if shutil.which("cargo") is None:
        pytest.fail("no clayc binary: set CLAYC or build it with `cargo build --bin clayc`")
    subprocess.run(
        ["cargo", "build", "-q", "--workspace", "--bin", "clayc"], cwd=ROOT, check=True
    )
    return str(_target_dir() / "debug" / "clayc")


@pytest.fixture()
def grammars() -> Path:
    return GRAMMARS


@pytest.fixture()
def root() -> Path:
    return ROOT
