"""Shared fixtures of the Python package's tests: the repository, the command line binary
(for the byte-for-byte comparisons) and small scenes."""

import os
import shutil
from pathlib import Path

import pytest

import monolayer as ml

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def cli() -> str:
    """The `monolayer` binary: $MONOLAYER_BIN, or the workspace's release build."""
    b = os.environ.get("MONOLAYER_BIN") or str(ROOT / "target" / "release" / "monolayer")
    if not Path(b).is_file():
        pytest.fail(f"no monolayer binary at {b}: run `cargo build --release` first, or set MONOLAYER_BIN")
    return b


def single(**sets) -> "ml.Scene":
    """One paper cell (R = 8) at rest on 64² with margin 16 (as the Rust test of
    self-propulsion), with overrides."""
    s = ml.Scene.from_dict(
        {
            "domain": {"lx": 64, "ly": 64},
            "cells": {"count": 1, "radius": 8.0, "init": "positions", "positions": [[32.0, 32.0]]},
            "model": {"zeta": 0.0},
            "integrator": {"dt": 0.5, "margin": 16},
            "run": {"relax_time": 0.0, "time": 100.0, "output_every": 100.0, "series_every": 10.0},
        }
    )
    return s.update({k.replace("__", "."): v for k, v in sets.items()})


def small_paper(root: Path) -> "ml.Scene":
    """The paper's scene at 15 cells on 50², 10 TU of relaxation and 20 of activity."""
    return ml.Scene.from_toml(root / "scenes" / "paper.toml").update(SMALL)


SMALL = {
    "domain.lx": 50,
    "domain.ly": 50,
    "cells.count": 15,
    "run.relax_time": 10.0,
    "run.time": 20.0,
    "run.output_every": 10.0,
    "run.series_every": 2.0,
}
