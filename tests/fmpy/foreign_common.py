"""Shared helpers of the foreign-FMU scripts (make_container.py, make_pythonfmu.py).

Each foreign FMU NAME.fmu gets, beside it in the output folder:
  NAME.system.json  a one-instance system description for the master (`master run`), with the
                    parameters and timing of the experiment;
  NAME.fmpy.csv     fmpy's simulate_fmu result of the same experiment (time and every output,
                    Real, Integer and Boolean as numbers), header `time,<instance>.<variable>,...`.
tests/tests/foreign_fmus.rs runs the system in the master and compares with the CSV.
"""
import csv
import json
import os
import sys

from fmpy import read_model_description, simulate_fmu


def python_env(out_dir):
    """Writes python_env.txt (KEY=VALUE lines): what a non-Python host needs to run a pythonfmu FMU in-process.

    A pythonfmu binary leaves the Python C-API symbols undefined (it is not linked against
    libpython: inside a Python host they are already there), so another host must load
    libpython with its symbols global first (LD_PRELOAD), and the embedded interpreter must
    find its standard library (PYTHONHOME: it would otherwise look next to the host's
    executable) and numpy etc. (PYTHONPATH: the venv's site-packages)."""
    import sysconfig

    libdir = sysconfig.get_config_var("LIBDIR") or ""
    ldlib = sysconfig.get_config_var("LDLIBRARY") or ""
    env = {
        "LIBPYTHON": os.path.join(libdir, ldlib),
        "PYTHONHOME": sys.base_prefix,
        "PYTHONPATH": sysconfig.get_paths()["purelib"],
    }
    with open(os.path.join(out_dir, "python_env.txt"), "w") as f:
        for k, v in env.items():
            f.write(f"{k}={v}\n")
    return env


def write_experiment(out_dir, name, fmu_path, instance, parameters, start, stop, step):
    """Writes NAME.system.json and NAME.fmpy.csv (see the module doc)."""
    system = {
        "instances": [{"name": instance, "fmu": os.path.basename(fmu_path), "parameters": parameters}],
        "start_time": start,
        "stop_time": stop,
        "step": step,
    }
    with open(os.path.join(out_dir, name + ".system.json"), "w") as f:
        json.dump(system, f, indent=2)

    md = read_model_description(fmu_path)
    outputs = [
        v.name
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Integer", "Boolean")
    ]
    result = simulate_fmu(
        fmu_path,
        fmi_type="CoSimulation",
        start_time=start,
        stop_time=stop,
        step_size=step,
        output_interval=step,
        start_values=parameters,
        output=outputs,
    )
    with open(os.path.join(out_dir, name + ".fmpy.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time"] + [f"{instance}.{o}" for o in outputs])
        for row in result:
            w.writerow([repr(float(x)) for x in row])
    print(f"{name}: {fmu_path}, fmpy simulated {len(result)} rows of {len(outputs)} outputs")
    return result
