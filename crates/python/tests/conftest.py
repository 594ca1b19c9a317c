"""Shared fixtures: the repository root, the CLI binary built by `cargo build --release`."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture(scope="session")
def cli() -> str:
    """The `flexstar` binary: $FLEXSTAR_BIN, else target/release/flexstar, else on PATH."""
    for cand in (os.environ.get("FLEXSTAR_BIN"), str(ROOT / "target" / "release" / "flexstar"), shutil.which("flexstar")):
        if cand and os.access(cand, os.X_OK):
            return cand
    pytest.fail("no flexstar binary: run `cargo build --release -p flexstar-cli` or set FLEXSTAR_BIN")
