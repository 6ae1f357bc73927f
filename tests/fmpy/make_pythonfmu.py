"""Builds PyOscillator.fmu from py_oscillator.py with pythonfmu (its binary, not written by this
project, embeds a Python interpreter) and simulates it with fmpy.

Usage: python make_pythonfmu.py OUT_DIR
Writes OUT_DIR/PyOscillator.fmu, PyOscillator.system.json, PyOscillator.fmpy.csv (see
foreign_common.py) and python_env.txt (what a non-Python host needs to load the FMU).
"""
import os
import sys
from pathlib import Path

from pythonfmu.builder import FmuBuilder

from foreign_common import python_env, write_experiment

HERE = Path(__file__).resolve().parent


def main(out):
    os.makedirs(out, exist_ok=True)
    fmu = Path(out) / "PyOscillator.fmu"
    if fmu.exists():
        fmu.unlink()
    built = FmuBuilder.build_FMU(HERE / "py_oscillator.py", dest=fmu)
    if Path(built) != fmu:
        os.replace(built, fmu)
    python_env(out)
    write_experiment(
        out,
        "PyOscillator",
        str(fmu),
        "osc",
        {"mass": 0.8, "stiffness": 60.0, "initial_position": 0.02, "force": 0.5},
        0.0,
        1.0,
        1e-3,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
