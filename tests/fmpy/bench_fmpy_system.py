"""fmpy driving the FMUs of one of our JSON system descriptions in a Python loop
(fmpy.fmi2.FMU2Slave), coupled as the master's Gauss-Seidel does: instances stepped in the
system's "order", each instance's connected inputs set from the latest outputs just before it
steps. Used by the benchmark tests/benches/ratios/.

Usage: python bench_fmpy_system.py SYSTEM.json STOP_TIME REPEATS
Prints `fmpy_wall_per_sim_s <seconds>`: wall time of the stepping loop (after initialisation,
reading the recorded outputs after each step as the master does) per simulated second, best of
REPEATS.
"""
import json
import os
import shutil
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave


def run(system_path, stop):
    base = os.path.dirname(os.path.abspath(system_path))
    with open(system_path) as f:
        system = json.load(f)
    h = float(system["step"])
    instances, dirs = {}, []
    try:
        for inst in system["instances"]:
            path = os.path.join(base, inst["fmu"])
            md = read_model_description(path)
            d = extract(path)
            dirs.append(d)
            fmu = FMU2Slave(guid=md.guid, unzipDirectory=d,
                            modelIdentifier=md.coSimulation.modelIdentifier,
                            instanceName=inst["name"])
            vr = {v.name: (v.valueReference, v.type) for v in md.modelVariables}
            fmu.instantiate()
            fmu.setupExperiment(startTime=0.0, stopTime=stop)
            for name, value in inst.get("parameters", {}).items():
                ref, kind = vr[name]
                if kind == "Real":
                    fmu.setReal([ref], [float(value)])
                else:
                    fmu.setInteger([ref], [int(value)])
            fmu.enterInitializationMode()
            instances[inst["name"]] = (fmu, vr)
        # connections grouped by the receiving instance: (source fmu, source vr, target vr)
        incoming = {name: [] for name in instances}
        for c in system["connections"]:
            src, src_var = c["from"].split(".", 1)
            dst, dst_var = c["to"].split(".", 1)
            incoming[dst].append((instances[src][0], instances[src][1][src_var][0],
                                  instances[dst][1][dst_var][0]))
        recorded = {}
        for ref in system.get("record", []):
            name, var = ref.split(".", 1)
            recorded.setdefault(name, []).append(instances[name][1][var][0])
        order = system.get("order") or [i["name"] for i in system["instances"]]

        def set_inputs(name):
            conns = incoming[name]
            if conns:
                values = [src.getReal([ref])[0] for src, ref, _ in conns]
                instances[name][0].setReal([t for _, _, t in conns], values)

        for name in order:
            set_inputs(name)
        for name in order:
            instances[name][0].exitInitializationMode()
        n = int(round(stop / h))
        started = time.perf_counter()
        for k in range(n):
            t = k * h
            hk = (k + 1) * h - t
            for name in order:
                set_inputs(name)
                instances[name][0].doStep(currentCommunicationPoint=t, communicationStepSize=hk)
            for name, refs in recorded.items():
                instances[name][0].getReal(refs)
        wall = time.perf_counter() - started
        for fmu, _ in instances.values():
            fmu.terminate()
            fmu.freeInstance()
        return wall
    finally:
        for d in dirs:
            shutil.rmtree(d, ignore_errors=True)


def main(system_path, stop, repeats):
    stop, repeats = float(stop), int(repeats)
    best = min(run(system_path, stop) for _ in range(repeats))
    print(f"fmpy_wall_per_sim_s {best / stop!r}")


if __name__ == "__main__":
    main(*sys.argv[1:])
