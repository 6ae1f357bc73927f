"""Benchmark: a run set on a dask.distributed LocalCluster of 2 workers against 1, against
local threads, and the per-task overhead of the cluster.

    .venv/bin/python python/bench/dask_speedup.py [--runs 8] [--stop-time 5]

The run set is the study's kind of sweep: the passive-damper system (systems/passive.json:
Bogie2Dof + two PassiveYawDamper FMUs, 1 ms Gauss-Seidel) over running speeds and track seeds.
Every figure is measured in this one invocation; the machine's load average is printed beside
them (other processes on the machine slow the parallel figures first). The per-task overhead is
the wall time per task of runs one step long (nothing to simulate) on the cluster, minus the
same on a local thread: scheduling, shipping the job in and the results out, writing the folder.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import railfmu

ROOT = Path(__file__).resolve().parents[2]


def run_set(runs: int, stop_time: float) -> railfmu.RunSet:
    base = json.loads((ROOT / "systems" / "passive.json").read_text())
    for inst in base["instances"]:
        inst["fmu"] = str((ROOT / "dist" / Path(inst["fmu"]).name).resolve())
    base["stop_time"] = stop_time
    speeds = [50.0 + 40.0 * i / max(runs // 2 - 1, 1) for i in range(max(runs // 2, 1))]
    return railfmu.RunSet.from_dict({"system": base, "product": {"bogie.vehicle.speed": speeds, "bogie.track.seed": [1, 2][: max(1, runs // len(speeds))]}})


def timed(f) -> float:
    t = time.perf_counter()
    res = f()
    dt = time.perf_counter() - t
    assert res.ok, res.failed
    return dt


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=8)
    p.add_argument("--stop-time", type=float, default=5.0, help="simulated time per run [s]")
    p.add_argument("--overhead-tasks", type=int, default=40)
    a = p.parse_args()
    from distributed import Client, LocalCluster

    rs = run_set(a.runs, a.stop_time)
    tiny = run_set(a.overhead_tasks, 0.001)
    out = Path(tempfile.mkdtemp(prefix="railfmu-bench-"))
    load_before = os.getloadavg()
    t_local1 = timed(lambda: rs.run(out / "local1", threads=1))
    t_local2 = timed(lambda: rs.run(out / "local2", threads=2))
    tiny_local = timed(lambda: tiny.run(out / "tiny-local", threads=1))
    times = {}
    for n in (1, 2):
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
            # warm-up: the workers import railfmu and prepare the system once
            rs.run(out / f"warm{n}", client=client)
            times[n] = timed(lambda: rs.run(out / f"dask{n}", client=client))
            if n == 1:
                tiny_dask = timed(lambda: tiny.run(out / "tiny-dask", client=client))
    load_after = os.getloadavg()
    print(f"run set: {len(rs)} runs of {a.stop_time} s simulated (passive system), {os.cpu_count()} cores")
    print(f"load average (1 min) before {load_before[0]:.2f}, after {load_after[0]:.2f}")
    print(f"local, 1 thread      {t_local1:8.3f} s")
    print(f"local, 2 threads     {t_local2:8.3f} s   speed-up {t_local1 / t_local2:.2f}x over 1 thread")
    print(f"LocalCluster, 1 worker  {times[1]:8.3f} s")
    print(f"LocalCluster, 2 workers {times[2]:8.3f} s   speed-up {times[1] / times[2]:.2f}x over 1 worker")
    print(f"per-task overhead (1 worker vs 1 local thread, {len(tiny)} one-step runs): "
          f"{1e3 * (tiny_dask - tiny_local) / len(tiny):.1f} ms per task "
          f"(cluster {1e3 * tiny_dask / len(tiny):.1f} ms, local {1e3 * tiny_local / len(tiny):.1f} ms per run)")


if __name__ == "__main__":
    main()
