"""Runs an SSP in a third-party co-simulation host and writes the values it reports as CSV.

    run_host.py HOST SYSTEM.ssp OUT.csv --stop-time T --step H INSTANCE.VARIABLE...

HOST is one of
  libcosim  libcosimpy's CosimExecution.from_ssp_file: the SSP's own parameter bindings, its
            osp:FixedStepAlgorithm step; values through a last-value observer after each step.
  ecos      ecospy's EcosSimulation(ssp_path=...): the SSP's own parameter bindings, which Ecos
            applies only when initialised with the parameter sets' name (read from the
            archive's .ssv files, which must all have the same name); values by
            "instance::variable" after each step.
  fmpy      fmpy.ssp.simulation.simulate_ssp: reads the SSD's structure but not its parameter
            bindings, so the sets are read with fmpy's own read_ssv from the archive and passed
            as its parameter_set argument (names prefixed with the component, as fmpy expects);
            values are fmpy's connector values.

The CSV has a header `time,VAR...` and one row per communication point t_k = k*H, k = 1..N,
holding the values after the step that ends at t_k (all three hosts step Jacobi-style: every
component from the inputs of the previous point). Exit status 0 on success; any host error is
printed and gives 1.
"""

import argparse
import csv
import os
import sys
import tempfile
import zipfile


def run_libcosim(ssp, stop, step, names):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.WARNING)

    ex = CosimExecution.from_ssp_file(ssp_path=ssp)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    refs = []
    for n in names:
        inst, var = n.split(".", 1)
        idx = ex.slave_index_from_instance_name(inst)
        vrs = [v.reference for v in ex.slave_variables(idx) if v.name.decode() == var]
        if not vrs:
            raise SystemExit(f"libcosim: no variable {var} in {inst}")
        refs.append((idx, vrs[0]))
    n_steps = round(stop / step)
    rows = []
    for k in range(1, n_steps + 1):
        ex.step()
        rows.append([k * step] + [obs.last_real_values(i, [vr])[0] for i, vr in refs])
    return rows


def run_ecos(ssp, stop, step, names):
    from ecospy import EcosSimulation

    from xml.etree import ElementTree

    with zipfile.ZipFile(ssp) as z:
        names_of_sets = {ElementTree.fromstring(z.read(n)).get("name")
                         for n in z.namelist() if n.endswith(".ssv")}
    if len(names_of_sets) > 1:
        raise SystemExit(f"ecos: parameter sets of several names {sorted(names_of_sets)}")
    sim = EcosSimulation(step_size=step, ssp_path=ssp)
    if not sim.init(parameter_set=names_of_sets.pop() if names_of_sets else None):
        raise SystemExit("ecos: init failed")
    ids = [n.replace(".", "::", 1) for n in names]
    n_steps = round(stop / step)
    rows = []
    for k in range(1, n_steps + 1):
        sim.step()
        rows.append([k * step] + [sim.get_real(i) for i in ids])
    sim.terminate()
    return rows


def run_fmpy(ssp, stop, step, names):
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import ParameterSet, Parameter, read_ssd

    ssd = read_ssd(ssp)
    combined = ParameterSet(name="combined")
    for comp in ssd.system.elements:
        for binding in comp.parameterBindings:
            for pset in binding.parameterValues:
                for p in pset.parameters:
                    q = Parameter(name=comp.name + "." + p.name)
                    q.type, q.value = p.type, p.value
                    combined.parameters.append(q)
    # fmpy advances time by adding the step; stop half a step early to get exactly N steps
    n_steps = round(stop / step)
    res = simulate_ssp(ssp, stop_time=(n_steps - 0.5) * step, step_size=step,
                       parameter_set=combined)
    if len(res) != n_steps:
        raise SystemExit(f"fmpy: {len(res)} steps instead of {n_steps}")
    return [[(k + 1) * step] + [float(r[n]) for n in names] for k, r in enumerate(res)]


HOSTS = {"libcosim": run_libcosim, "ecos": run_ecos, "fmpy": run_fmpy}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("host", choices=sorted(HOSTS))
    ap.add_argument("ssp")
    ap.add_argument("out")
    ap.add_argument("--stop-time", type=float, required=True)
    ap.add_argument("--step", type=float, required=True)
    ap.add_argument("names", nargs="+")
    a = ap.parse_args()
    ssp = os.path.abspath(a.ssp)
    out = os.path.abspath(a.out)
    if not zipfile.is_zipfile(ssp):
        raise SystemExit(f"{ssp} is not an SSP archive")
    # hosts unpack into the working folder or the temporary one; keep both private
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        rows = HOSTS[a.host](ssp, a.stop_time, a.step, a.names)
    with open(out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time"] + a.names)
        for r in rows:
            w.writerow([repr(float(x)) for x in r])
    print(f"{a.host}: {len(rows)} rows")


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # a host's own error: report, fail
        print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
