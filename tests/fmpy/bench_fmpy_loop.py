"""fmpy driving MassSpring + SpringDamperMass in a Python loop (fmpy.fmi2.FMU2Slave), the same
coupling as the master's Gauss-Seidel in feedthrough order: step ms, copy its position and
velocity to sdm, step sdm, copy its coupling force to ms. Used by the master's benchmark
crates/rail-study/benches/coupled_vs_monolithic.rs.

Usage: python bench_fmpy_loop.py DIST_DIR STOP_TIME STEP REPEATS
Prints `fmpy_wall_per_sim_s <seconds>`: wall time of the stepping loop (after initialisation,
reading every output after each step as the master records them) per simulated second, best of
REPEATS; and `fmpy_final <ms.position> <sdm.position>` at the stop time.
"""
import shutil
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

MS_PARAMS = {"mass": 1.0, "stiffness": 100.0, "damping": 0.5, "initial_position": 0.1}
SDM_PARAMS = {"mass": 0.5, "coupling_stiffness": 200.0, "coupling_damping": 1.0,
              "ground_stiffness": 0.0, "ground_damping": 0.0}


def load(path, name):
    md = read_model_description(path)
    d = extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return fmu, vr, d


def run(dist, stop, h):
    ms, msv, d1 = load(f"{dist}/MassSpring.fmu", "ms")
    sdm, sdv, d2 = load(f"{dist}/SpringDamperMass.fmu", "sdm")
    try:
        for fmu, vr, params in ((ms, msv, MS_PARAMS), (sdm, sdv, SDM_PARAMS)):
            fmu.instantiate()
            fmu.setupExperiment(startTime=0.0, stopTime=stop)
            fmu.setReal([vr[k] for k in params], list(params.values()))
            fmu.enterInitializationMode()
        ms_out = [msv["position"], msv["velocity"]]
        sdm_in = [sdv["input_position"], sdv["input_velocity"]]
        f_out, f_in = [sdv["coupling_force"]], [msv["force"]]
        sdm.setReal(sdm_in, ms.getReal(ms_out))
        ms.setReal(f_in, sdm.getReal(f_out))
        ms.exitInitializationMode()
        sdm.exitInitializationMode()
        sdm.setReal(sdm_in, ms.getReal(ms_out))
        ms.setReal(f_in, sdm.getReal(f_out))
        n = int(round(stop / h))
        started = time.perf_counter()
        for k in range(n):
            t = k * h
            hk = (k + 1) * h - t
            ms.doStep(currentCommunicationPoint=t, communicationStepSize=hk)
            sdm.setReal(sdm_in, ms.getReal(ms_out))
            sdm.doStep(currentCommunicationPoint=t, communicationStepSize=hk)
            ms.setReal(f_in, sdm.getReal(f_out))
            # the master records every output after each step: read them too
            ms.getReal(ms_out)
            sdm.getReal([sdv["position"], sdv["velocity"], sdv["coupling_force"]])
        wall = time.perf_counter() - started
        final = (ms.getReal([msv["position"]])[0], sdm.getReal([sdv["position"]])[0])
        for fmu in (ms, sdm):
            fmu.terminate()
            fmu.freeInstance()
        return wall, final
    finally:
        shutil.rmtree(d1, ignore_errors=True)
        shutil.rmtree(d2, ignore_errors=True)


def main(dist, stop, h, repeats):
    stop, h, repeats = float(stop), float(h), int(repeats)
    best, final = None, None
    for _ in range(repeats):
        wall, final = run(dist, stop, h)
        best = wall if best is None else min(best, wall)
    print(f"fmpy_wall_per_sim_s {best / stop!r}")
    print(f"fmpy_final {final[0]!r} {final[1]!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:5]))
