"""Simulates FMUs with fmpy over their DefaultExperiment, sampled at its stepSize (fmpy's
round interval where it has none; fmpy would otherwise sample long runs more coarsely), and
writes one CSV per FMU: `NAME.fmpy.csv` in OUT_DIR, the header the recorded variable names,
every value written with repr (round-trip exact; booleans as 0/1).

    python reference_fmus.py OUT_DIR FMU...
"""

import os
import sys

import fmpy


def main():
    out_dir = sys.argv[1]
    for path in sys.argv[2:]:
        name = os.path.splitext(os.path.basename(path))[0]
        experiment = fmpy.read_model_description(path).defaultExperiment
        step = experiment.stepSize if experiment is not None else None
        result = fmpy.simulate_fmu(
            path, output_interval=float(step) if step is not None else None
        )
        names = result.dtype.names
        with open(os.path.join(out_dir, name + ".fmpy.csv"), "w") as f:
            f.write(",".join(names) + "\n")
            for row in result:
                f.write(",".join(repr(float(row[n])) for n in names) + "\n")


if __name__ == "__main__":
    main()
