"""Validate every FMU in a folder with fmpy, check its Enumerations as fmpy reads them, and
simulate it over its default experiment.

Usage: python check_fmus.py DIST_DIR OUT_DIR
Writes OUT_DIR/<model>.csv (time and every output) for the Rust cross-check
(tests/tests/fmpy_agreement.rs). Exits non-zero on any validation problem or failed simulation.
"""
import csv
import os
import sys

from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu


def check_enumerations(md):
    """Every Enumeration variable resolves, in fmpy, to its declared type with named items, and
    its start value is one of them (what a host shows the user). Prints what fmpy shows."""
    problems = []
    for v in md.modelVariables:
        if v.type != "Enumeration":
            continue
        t = v.declaredType
        if t is None or not t.items:
            problems.append(f"{v.name}: no declared type with items")
            continue
        items = {str(i.value): i.name for i in t.items}
        if v.start is not None and str(v.start) not in items:
            problems.append(f"{v.name}: start {v.start} is not an item of {t.name}")
            continue
        shown = ", ".join(f"{k} = {n}" for k, n in items.items())
        start = f"start {items[str(v.start)]}" if v.start is not None else "no start"
        print(f"  {v.name}: {t.name} ({shown}), {start}")
    return problems


def main(dist, out):
    os.makedirs(out, exist_ok=True)
    fmus = sorted(f for f in os.listdir(dist) if f.endswith(".fmu"))
    if not fmus:
        print(f"no FMU in {dist}", file=sys.stderr)
        return 1
    failed = 0
    for name in fmus:
        path = os.path.join(dist, name)
        problems = validate_fmu(path)
        if problems:
            failed += 1
            print(f"{name}: {len(problems)} validation problem(s)")
            for p in problems:
                print(f"  {p}")
            continue
        md = read_model_description(path)
        enum_problems = check_enumerations(md)
        if enum_problems:
            failed += 1
            print(f"{name}: {len(enum_problems)} enumeration problem(s)")
            for p in enum_problems:
                print(f"  {p}")
            continue
        de = md.defaultExperiment
        start, stop, step = float(de.startTime), float(de.stopTime), float(de.stepSize)
        outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        try:
            result = simulate_fmu(
                path,
                fmi_type="CoSimulation",
                start_time=start,
                stop_time=stop,
                step_size=step,
                output_interval=step,
                output=outputs,
            )
        except Exception as e:  # report and go on with the other FMUs
            failed += 1
            print(f"{name}: simulation failed: {e}")
            continue
        model = name[:-4]
        with open(os.path.join(out, model + ".csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["time"] + outputs)
            for row in result:
                w.writerow([repr(float(x)) for x in row])
        print(f"{name}: valid; simulated {start}..{stop} s, {len(result)} rows, {len(outputs)} outputs")
    print(f"{len(fmus) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
