"""Fixtures of the railfmu tests: the packaged FMUs in dist/, the `master` command, and short
versions of the project's passive-damper system (the bogie with two hydraulic yaw dampers)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
DIST = ROOT / "dist"


@pytest.fixture(scope="session")
def dist() -> Path:
    missing = [f for f in ("Bogie2Dof.fmu", "PassiveYawDamper.fmu") if not (DIST / f).is_file()]
    assert not missing, f"dist/ lacks {missing}: run scripts/test.sh (it packages the FMUs first)"
    return DIST


@pytest.fixture(scope="session")
def master_cmd() -> Path:
    exe = Path(os.environ.get("RAILFMU_MASTER", ROOT / "target" / "release" / "master"))
    assert exe.is_file(), f"{exe} missing: cargo build --release -p rail-study --bin master"
    return exe


def passive(dist: Path, stop_time: float, **parameters) -> dict:
    """systems/passive.json with absolute FMU paths, a shorter stop time, changed start values."""
    d = json.loads((ROOT / "systems" / "passive.json").read_text())
    for inst in d["instances"]:
        inst["fmu"] = str(dist / Path(inst["fmu"]).name)
    d["stop_time"] = stop_time
    d["instances"][0]["parameters"].update(parameters)
    return d


@pytest.fixture
def passive_file(dist: Path, tmp_path: Path) -> Path:
    p = tmp_path / "passive.json"
    p.write_text(json.dumps(passive(dist, 1.0), indent=2))
    return p


def run_master(master_cmd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(master_cmd), "--quiet", *map(str, args)], capture_output=True, text=True, check=False)


def bits(a: np.ndarray) -> np.ndarray:
    """The bit patterns of a float64 array (so -0.0 != 0.0 and NaN == NaN where identical)."""
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def speed_set(dist: Path, speeds_mps, seeds=(1,), stop_time: float = 1.0) -> dict:
    """A run set over speeds and track seeds of the passive system (inline base)."""
    return {
        "system": passive(dist, stop_time),
        "product": {"bogie.vehicle.speed": list(speeds_mps), "bogie.track.seed": list(seeds)},
    }
