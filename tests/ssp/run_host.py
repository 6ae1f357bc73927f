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
  fmpy-stepwise
            simulate_ssp's loop written out over fmpy's own pieces (read_ssd, its parameter
            handling, instantiate_fmu, do_step, get_value), with the two details in which
            simulate_ssp differs from the master as options: --fmpy-start zero (simulate_ssp:
            every input starts at 0 in the first step) or exchange (the master: inputs take the
            outputs at the start time, after initialisation), and --fmpy-time accumulated
            (simulate_ssp: t += H) or grid (the master: t_k = t_0 + k*H, steps t_(k+1) - t_k).

The CSV has a header `time,VAR...` and one row per communication point t_k = k*H, k = 1..N,
holding the values after the step that ends at t_k (all three hosts step Jacobi-style: every
component from the inputs of the previous point). Exit status 0 on success; any host error is
printed and gives 1.
"""

import argparse
import csv
import os
import shutil
import sys
import tempfile
import zipfile


def run_libcosim(ssp, stop, step, names, opts):
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


def run_ecos(ssp, stop, step, names, opts):
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


def fmpy_parameters(ssd):
    """The SSD's parameter sets as one fmpy parameter_set, names prefixed with the component."""
    from fmpy.ssp.ssd import ParameterSet, Parameter

    combined = ParameterSet(name="combined")
    for comp in ssd.system.elements:
        for binding in comp.parameterBindings:
            for pset in binding.parameterValues:
                for p in pset.parameters:
                    q = Parameter(name=comp.name + "." + p.name)
                    q.type, q.value = p.type, p.value
                    combined.parameters.append(q)
    return combined


def run_fmpy(ssp, stop, step, names, opts):
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import read_ssd

    combined = fmpy_parameters(read_ssd(ssp))
    # fmpy advances time by adding the step; stop half a step early to get exactly N steps
    n_steps = round(stop / step)
    res = simulate_ssp(ssp, stop_time=(n_steps - 0.5) * step, step_size=step,
                       parameter_set=combined)
    if len(res) != n_steps:
        raise SystemExit(f"fmpy: {len(res)} steps instead of {n_steps}")
    return [[(k + 1) * step] + [float(r[n]) for n in names] for k, r in enumerate(res)]


def run_fmpy_stepwise(ssp, stop, step, names, opts):
    from fmpy import extract
    from fmpy.ssp.simulation import (add_path, do_step, find_components, find_connectors,
                                     free_fmu, get_connections, get_value, instantiate_fmu)
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(ssp)
    add_path(ssd.system)
    components = find_components(ssd.system)
    connections = get_connections(ssd.system)
    unzipdir = extract(ssp)
    for connector in find_connectors(ssd.system):
        connector.value = 0.0
    params = fmpy_parameters(ssd)
    start = 0.0
    for component in components:
        instantiate_fmu(component, unzipdir, start, stop, params)
    if opts.fmpy_start == "exchange":
        for component in components:
            for connector in component.connectors:
                if connector.kind == "output":
                    connector.value = get_value(component, connector.name)
        for a, b in connections:
            b.value = a.value
    by_path = {c.path: c for c in find_connectors(ssd.system)}
    n_steps = round(stop / step)
    rows = []
    time = start
    for k in range(n_steps):
        if opts.fmpy_time == "grid":
            time = start + k * step
            h = (stop if k + 1 == n_steps else start + (k + 1) * step) - time
        else:
            h = step
        for component in components:
            do_step(component, time, h)
        for a, b in connections:
            b.value = a.value
        rows.append([(k + 1) * step] + [float(by_path[n].value) for n in names])
        if opts.fmpy_time == "accumulated":
            time += step
    for component in components:
        free_fmu(component)
    shutil.rmtree(unzipdir, ignore_errors=True)
    return rows


HOSTS = {"libcosim": run_libcosim, "ecos": run_ecos, "fmpy": run_fmpy,
         "fmpy-stepwise": run_fmpy_stepwise}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("host", choices=sorted(HOSTS))
    ap.add_argument("ssp")
    ap.add_argument("out")
    ap.add_argument("--stop-time", type=float, required=True)
    ap.add_argument("--step", type=float, required=True)
    ap.add_argument("--fmpy-start", choices=["zero", "exchange"], default="exchange")
    ap.add_argument("--fmpy-time", choices=["accumulated", "grid"], default="grid")
    ap.add_argument("names", nargs="+")
    a = ap.parse_args()
    ssp = os.path.abspath(a.ssp)
    out = os.path.abspath(a.out)
    if not zipfile.is_zipfile(ssp):
        raise SystemExit(f"{ssp} is not an SSP archive")
    # hosts unpack into the working folder or the temporary one; keep both private
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        rows = HOSTS[a.host](ssp, a.stop_time, a.step, a.names, a)
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
