"""Replays each instance of a co-simulation run by the master alone in fmpy, feeding it the inputs
the master recorded, and compares its outputs with the master's recording.

Usage: python drive_with_fmpy.py SYSTEM.json MASTER.csv [REPORT.json] [--rtol 1e-9]

SYSTEM.json is the master's system description (FMU paths relative to its folder), MASTER.csv the
results of `master run` on it, recording at least every connected input and the outputs to check
(the master's default record: all outputs and connected inputs). For every instance, fmpy's
simulate_fmu runs its FMU with the same parameters and communication step (step * step_multiple)
and an input table built so that the value fmpy sets before each fmi2DoStep is exactly the one
the master set:

* The master records at t_k after macro step k-1 and the exchange. Jacobi: every input set then
  is the one used by the step from t_k, so the row of t_k. Gauss-Seidel (instances step in
  `order`, each one's outputs are copied to the connected inputs right after its step): an input
  whose source steps *before* the target in the order was set during macro step k, before the
  target stepped, so the step from t_k used the row of t_{k+1}; one whose source steps after the
  target still holds the row of t_k.
* fmpy (fmpy/simulation.py, simulateCS) applies inputs with Input.apply(t) before
  fmi2ExitInitializationMode and with after_event=True before each fmi2DoStep(t), linearly
  interpolating the table at t; at a table time equal to t the interpolation weight of the other
  point is exactly 0, so the value is the table's. At t0 the input the master had at
  initialisation (row 0) and the one of the first step (row 0 or 1) differ, so the table starts
  with [t0 - H: row 0, t0: row 0, t0: first step's value] -- a double time point is an input
  event and Input.apply takes the value before it during initialisation and after it at the
  first step. Table times are fmpy's own communication points t0 + n*H.

The order is `order` from SYSTEM.json or, as the master derives it, a stable topological order of
the edges source -> target for each connection whose target input feeds through directly to an
output (ModelStructure/Outputs), cycles broken at the lowest remaining index.

Prints one line per instance and writes REPORT.json ({instance: {"rows", "values",
"max_rel_diff", "worst", "input_shift", "ok"}}); exits 1 if any instance disagrees beyond rtol.
Limitations: every instance's step_multiple must divide the number of macro steps; String
variables are not exchanged; a Gauss-Seidel order that steps an instance with direct
feedthrough before the source of that input (both every macro step) is not replayed: the master
then reads that instance's outputs again after the source has set its inputs, and the instances
stepped in between used values no row records.
"""
import argparse
import csv
import json
import os
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu


def split_ref(s):
    inst, _, var = s.partition(".")
    return inst, var


def topological_order(n, edges):
    indeg = [0] * n
    for a, b in edges:
        if a != b:
            indeg[b] += 1
    done = [False] * n
    order = []
    while len(order) < n:
        nxt = next((i for i in range(n) if not done[i] and indeg[i] == 0), None)
        if nxt is None:
            nxt = next(i for i in range(n) if not done[i])
        done[nxt] = True
        order.append(nxt)
        for a, b in edges:
            if a == nxt and a != b and not done[b]:
                indeg[b] = max(0, indeg[b] - 1)
    return order


def feedthrough_inputs(md):
    """Names of inputs that some output depends on directly."""
    names = set()
    for u in md.outputs:
        for d in (u.dependencies or []):
            if d.causality == "input":
                names.add(d.name)
    return names


def read_master_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = [h.split(" [")[0] for h in rows[0]]
    data = np.array([[float(x) for x in r] for r in rows[1:]])
    return header, data


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("system")
    ap.add_argument("master_csv")
    ap.add_argument("report", nargs="?")
    ap.add_argument("--rtol", type=float, default=1e-9)
    args = ap.parse_args()

    with open(args.system) as f:
        system = json.load(f)
    base = os.path.dirname(os.path.abspath(args.system))
    insts = system["instances"]
    names = [i["name"] for i in insts]
    index = {n: k for k, n in enumerate(names)}
    fmus = [i["fmu"] if os.path.isabs(i["fmu"]) else os.path.join(base, i["fmu"]) for i in insts]
    mds = [read_model_description(p) for p in fmus]
    conns = system.get("connections", [])
    algorithm = system.get("algorithm", "gauss-seidel")
    t0 = float(system.get("start_time", 0.0))
    stop = float(system["stop_time"])
    h = float(system["step"])
    n_steps = int(round((stop - t0) / h))

    if system.get("order"):
        order = [index[n] for n in system["order"]]
    else:
        edges = []
        for c in conns:
            (fi, _), (ti, tv) = split_ref(c["from"]), split_ref(c["to"])
            if tv in feedthrough_inputs(mds[index[ti]]):
                edges.append((index[fi], index[ti]))
        order = topological_order(len(insts), edges)
    pos = {i: p for p, i in enumerate(order)}

    header, data = read_master_csv(args.master_csv)
    col = {h: j for j, h in enumerate(header)}
    if len(data) != n_steps + 1:
        print(f"{args.master_csv}: {len(data)} rows, expected {n_steps + 1}", file=sys.stderr)
        return 1
    t_master = data[:, 0]

    report = {}
    failed = False
    for i, inst in enumerate(insts):
        name = inst["name"]
        md = mds[i]
        m = int(inst.get("step_multiple", 1))
        if n_steps % m:
            print(f"{name}: step_multiple {m} does not divide {n_steps} steps: not replayed")
            failed = True
            continue
        H = m * h
        n_own = n_steps // m
        ks = np.arange(n_own + 1) * m  # the master's rows at this instance's points
        types = {v.name: v.type for v in md.modelVariables}

        # inputs: (variable, shift)
        inputs = []
        for c in conns:
            (fi, _), (ti, tv) = split_ref(c["from"]), split_ref(c["to"])
            if ti != name:
                continue
            if c["to"] not in col:
                print(f"{name}: input {c['to']} was not recorded by the master", file=sys.stderr)
                return 1
            s = int(algorithm == "gauss-seidel" and pos[index[fi]] < pos[i])
            inputs.append((tv, s))
        signal = None
        if inputs:
            t_own = t0 + np.arange(n_own) * H  # fmpy's communication points
            times = np.concatenate(([t0 - H, t0], t_own))
            dtype = [("time", np.double)] + [
                (v, np.double if types[v] == "Real" else (np.bool_ if types[v] == "Boolean" else np.int32))
                for v, _ in inputs
            ]
            signal = np.zeros(len(times), dtype=dtype)
            signal["time"] = times
            for v, s in inputs:
                u = data[:, col[f"{name}.{v}"]]
                vals = np.concatenate(([u[0], u[0]], u[ks[:-1] + s]))
                signal[v] = vals

        outputs = [
            v.name
            for v in md.modelVariables
            if v.causality == "output" and v.type in ("Real", "Integer", "Boolean") and f"{name}.{v.name}" in col
        ]
        # The master records after the exchange: a direct-feedthrough output shows the inputs
        # set *after* the step, whereas fmpy's recorder samples right after fmi2DoStep, before
        # it applies the next inputs. So sample in step_finished (called after each step):
        # set the inputs the master had at that row, then read the outputs (fmpy sets the next
        # step's inputs itself before stepping again).
        by_type = {"Real": [], "Integer": [], "Boolean": []}
        for v in outputs:
            by_type[types[v]].append(v)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        samples = []

        def step_finished(time, recorder):
            fmu = recorder.fmu
            k = ks[len(samples) + 1]
            for v, _ in inputs:
                x = data[k, col[f"{name}.{v}"]]
                if types[v] == "Real":
                    fmu.setReal([vr[v]], [float(x)])
                elif types[v] == "Integer":
                    fmu.setInteger([vr[v]], [int(round(x))])
                else:
                    fmu.setBoolean([vr[v]], [x != 0.0])
            row = {}
            if by_type["Real"]:
                row.update(zip(by_type["Real"], fmu.getReal([vr[v] for v in by_type["Real"]])))
            if by_type["Integer"]:
                row.update(zip(by_type["Integer"], fmu.getInteger([vr[v] for v in by_type["Integer"]])))
            if by_type["Boolean"]:
                row.update(zip(by_type["Boolean"], fmu.getBoolean([vr[v] for v in by_type["Boolean"]])))
            samples.append(row)
            return True

        result = simulate_fmu(
            fmus[i],
            fmi_type="CoSimulation",
            start_time=t0,
            stop_time=stop,
            step_size=H,
            output_interval=H,
            start_values=dict(inst.get("parameters", {})),
            input=signal,
            output=outputs,
            step_finished=step_finished,
        )
        if len(result) != n_own + 1 or len(samples) != n_own:
            print(f"{name}: fmpy gave {len(result)} rows and {len(samples)} steps, expected {n_own + 1}")
            failed = True
            continue
        worst, worst_at, count = 0.0, None, 0
        for v in outputs:
            ours = data[ks, col[f"{name}.{v}"]]
            # row 0: fmpy's recorder after initialisation; then the samples after each step
            theirs = np.array([float(result[v][0])] + [float(r[v]) for r in samples])
            scale = max(np.max(np.abs(theirs)), 1e-300)
            denom = np.maximum(np.maximum(np.abs(ours), np.abs(theirs)), 1e-6 * scale)
            rel = np.abs(ours - theirs) / denom
            j = int(np.argmax(rel))
            if rel[j] > worst:
                worst, worst_at = float(rel[j]), f"{v} at t = {float(t_master[ks[j]])!r}: master {float(ours[j])!r}, fmpy {float(theirs[j])!r}"
            count += len(ours)
        ok = worst <= args.rtol and count > 0
        failed |= not ok
        report[name] = {
            "rows": int(n_own + 1),
            "values": int(count),
            "max_rel_diff": worst,
            "worst": worst_at,
            "input_shift": {v: s for v, s in inputs},
            "ok": bool(ok),
        }
        shifts = ", ".join(f"{v}{'+1' if s else ''}" for v, s in inputs) or "none"
        print(
            f"instance {name}: {count} values in {n_own + 1} rows, inputs [{shifts}], "
            f"max relative difference {worst:.3e}: {'ok' if ok else 'DIFFERENT ' + str(worst_at)}"
        )
    if args.report:
        with open(args.report, "w") as f:
            json.dump(report, f, indent=2)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
