"""Run sets on a dask.distributed LocalCluster of 2 worker processes: the same results as the
local run set bit for bit (CSV and Parquet, the format chosen by size as locally), a killed
worker does not lose the set, bad input fails its own run only, the command line reaches the
cluster too, and the workers' FMU cache stays bounded."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import _thread
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import railfmu
from conftest import ROOT, bits, speed_set

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def csv_bytes(folder: Path) -> dict:
    return {p.parent.name: p.read_bytes() for p in sorted(folder.glob("*/results.csv"))}


def eight_runs(dist, stop_time=0.5):
    return railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0, 70.0, 80.0], seeds=[1, 2], stop_time=stop_time))


def test_a_cluster_run_set_equals_the_local_one_bit_for_bit(dist, client, tmp_path):
    rs = eight_runs(dist)
    local = rs.run(tmp_path / "local", threads=2)
    calls = []
    remote = rs.run(tmp_path / "dask", client=client, progress=lambda *a: calls.append(a))
    assert remote.ok and len(remote) == 8
    assert csv_bytes(tmp_path / "dask") == csv_bytes(tmp_path / "local")
    for name in remote:
        assert (tmp_path / "dask" / name / "system.json").read_bytes() == (tmp_path / "local" / name / "system.json").read_bytes()
    assert sorted(c[0] for c in calls) == list(range(1, 9))
    # both workers took part
    assert len({r["summary"]["wall_time_s"] for r in remote.reports}) == 8
    assert [r["parameters"] for r in remote.reports] == [r["parameters"] for r in local.reports]
    # the FMUs were shipped: each worker has its own copy of each, named by content
    from railfmu.dask import _fmu_cache_dir

    for folder in client.run(_fmu_cache_dir).values():
        copies = {p.name for p in Path(folder).glob("*/*.fmu")}
        assert {"Bogie2Dof.fmu", "PassiveYawDamper.fmu"} <= copies
    # the same set again at once: its FMUs are scattered anew while the scheduler may still be
    # releasing the first set's copies
    again = rs.run(tmp_path / "again", client=client)
    assert again.ok, again.failed
    assert csv_bytes(tmp_path / "again") == csv_bytes(tmp_path / "local")
    # the same with the FMUs read from their (shared) paths
    rs.run(tmp_path / "shared", client=client, ship_fmus=False)
    assert csv_bytes(tmp_path / "shared") == csv_bytes(tmp_path / "local")


def parquet_meta(path: Path) -> dict:
    return json.loads(pq.read_schema(path).metadata[b"railfmu.results"])


def test_a_cluster_run_set_writes_the_parquet_table_of_the_local_one(dist, client, tmp_path):
    rs = railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0], seeds=[1, 2], stop_time=0.5))
    local = rs.run(tmp_path / "local", threads=2, format="parquet")
    remote = rs.run(tmp_path / "dask", client=client, format="parquet")
    assert local.ok and remote.ok and len(remote) == 4
    assert not list((tmp_path / "dask").glob("*/results.csv"))
    # the folder is one table in one call: every run with its name and parameters
    folder = tmp_path / "dask" / "results"
    table = pd.read_parquet(folder)
    assert len(table) == 4 * 501
    params = table.groupby("run")[["bogie.vehicle.speed", "bogie.track.seed"]].first()
    assert sorted(map(tuple, params.to_numpy().tolist())) == [(50.0, 1.0), (50.0, 2.0), (60.0, 1.0), (60.0, 2.0)]
    # units and FMU variables came back from the workers
    meta = parquet_meta(folder / "run-001.parquet")
    force = {c["name"]: c for c in meta["columns"]}["damper_left.damper.force"]
    assert force["unit"] == "N" and force["causality"] == "output" and force["instance"] == "damper_left"
    assert force["fmu_guid"]
    # the local run set's table and metadata, value for value (wall times aside)
    mine = parquet_meta(tmp_path / "local" / "results" / "run-001.parquet")
    for key in ("columns", "sampling", "run", "parameters", "system"):
        assert meta[key] == mine[key], key
    # each parameter column of the type the local table gives it: the seed (an Integer of the
    # FMU) as int32, not as a float
    theirs, ours = (pq.read_schema(t / "run-001.parquet") for t in (folder, tmp_path / "local" / "results"))
    for name in ("bogie.vehicle.speed", "bogie.track.seed"):
        assert theirs.field(name).type == ours.field(name).type, name
    assert str(theirs.field("bogie.track.seed").type) == "int32"
    assert meta["summary"]["steps"] == mine["summary"]["steps"] == 500
    expected = pd.read_parquet(tmp_path / "local" / "results")
    assert list(table.columns) == list(expected.columns)
    a, b = (t.sort_values(["run", "time [s]"], kind="stable") for t in (table, expected))
    for label in table.columns:
        if label == "run":
            assert list(a[label]) == list(b[label])
        else:
            assert np.array_equal(bits(a[label].to_numpy()), bits(b[label].to_numpy())), label
    # the Python package reads it back as a run set
    assert railfmu.read_results(tmp_path / "dask")["run-001"].units["damper_left.damper.force"] == "N"


def test_the_cluster_chooses_the_format_by_size_as_a_local_run_set(dist, client, tmp_path):
    # 8 columns: Parquet from 25 000 rows (25 s at 1 kHz) on, CSV below
    for stop_time, layout in ((24.99, "{run}/results.csv"), (25.0, "results/{run}.parquet")):
        rs = railfmu.RunSet.from_dict(speed_set(dist, [50.0], stop_time=stop_time))
        for where, options in (("local", {"threads": 1}), ("dask", {"client": client})):
            out = tmp_path / f"{where}-{stop_time}"
            res = rs.run(out, **options)
            assert res.ok, res.failed
            assert (out / layout.format(run="run-000")).is_file(), (where, stop_time, sorted(out.rglob("*")))
            assert res.reports[0]["results"] == str(out / layout.format(run="run-000"))


def test_bad_input_fails_its_own_run_and_no_worker(dist, client, tmp_path):
    pids = set(client.run(os.getpid).values())
    rs = speed_set(dist, [60.0], stop_time=0.2)
    rs["runs"] = [
        {"name": "typo", "parameters": {"bogie.vehicle.sped": 70.0}},
        {"name": "wrong_type", "parameters": {"bogie.track.seed": 1.5}},
        {"name": "negative", "parameters": {"bogie.vehicle.speed": -5.0}},
    ]
    # shipping the FMUs, this process checks every run first, as a local set does: refused
    # before the output folder is touched
    with pytest.raises(railfmu.SystemDescriptionError, match="vehicle.sped"):
        railfmu.run_set(rs, tmp_path / "out", client=client)
    assert not (tmp_path / "out").exists()
    # with shared FMUs the workers alone read them: each bad run fails on its own
    res = railfmu.run_set(rs, tmp_path / "out", client=client, ship_fmus=False)
    assert set(res) == {"run-000"}
    assert "unknown variable 'vehicle.sped'" in res.failed["typo"]
    assert "is not a 32-bit integer" in res.failed["wrong_type"]
    assert "negative" in res.failed
    # a broken FMU fails every run of the set, with the master's message, on the workers
    broken = tmp_path / "Broken.fmu"
    broken.write_bytes(b"PK\x03\x04 not a zip archive")
    rs = speed_set(dist, [60.0, 70.0], stop_time=0.2)
    rs["system"]["instances"][1]["fmu"] = str(broken)
    with pytest.raises(railfmu.FmuError, match="Broken.fmu"):
        railfmu.run_set(rs, tmp_path / "broken", client=client, retries=0)
    assert not (tmp_path / "broken").exists()
    with pytest.warns(RuntimeWarning, match="no run of the set succeeded"):
        res = railfmu.run_set(rs, tmp_path / "broken", client=client, retries=0, ship_fmus=False)
    assert len(res) == 0 and len(res.failed) == 2
    assert all("FmuError" in e and "Broken.fmu" in e for e in res.failed.values()), res.failed
    assert set(client.run(os.getpid).values()) == pids  # no worker crashed


def test_a_run_that_fails_midway_on_the_cluster_keeps_the_local_history(dist, client, tmp_path):
    rs = speed_set(dist, [60.0], stop_time=2.0)
    rs["runs"] = [
        {
            "name": "derails",
            "parameters": {
                "bogie.vehicle.speed": 150.0,
                "bogie.suspension.lateral_stiffness": 0.0,
                "bogie.suspension.longitudinal_stiffness": 0.0,
            },
        }
    ]
    local = railfmu.run_set(rs, tmp_path / "local", threads=1)
    remote = railfmu.run_set(rs, tmp_path / "dask", client=client)
    assert remote.failed == local.failed and "derailment" in remote.failed["derails"]
    a = (tmp_path / "local" / "derails" / "history.csv").read_bytes()
    assert (tmp_path / "dask" / "derails" / "history.csv").read_bytes() == a
    assert remote.history("derails").summary["failed"] == local.history("derails").summary["failed"]


def test_a_killed_worker_does_not_lose_the_set_and_a_resumed_set_skips_finished_runs(dist, client, tmp_path):
    rs = eight_runs(dist, stop_time=1.0)
    local = rs.run(tmp_path / "local", threads=2)
    pids = client.run(os.getpid)
    victim = sorted(pids.values())[0]
    killed = []

    def kill_once(done, total, name, error):
        if not killed:
            os.kill(victim, signal.SIGKILL)
            killed.append(name)

    res = rs.run(tmp_path / "dask", client=client, progress=kill_once)
    assert killed and res.ok and len(res) == 8
    assert csv_bytes(tmp_path / "dask") == csv_bytes(tmp_path / "local")
    client.wait_for_workers(2, timeout=60)
    assert victim not in client.run(os.getpid).values()
    # resumed on the cluster: only the removed runs run again
    for name in ("run-002", "run-007"):
        (tmp_path / "dask" / name / "results.csv").unlink()
    ran = []
    again = rs.run(tmp_path / "dask", client=client, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == ["run-002", "run-007"]
    assert again.ok and csv_bytes(tmp_path / "dask") == csv_bytes(tmp_path / "local")


def test_an_interrupted_set_leaves_a_whole_folder_that_a_resumed_set_completes(dist, client, tmp_path):
    rs = eight_runs(dist, stop_time=1.0)
    local = rs.run(tmp_path / "local", threads=2)
    assert local.ok
    out = tmp_path / "dask"
    rs.run(out, threads=2)  # an earlier set's report, which must not outlive what follows

    def stop_after_first(error_type, finished):
        def progress(done, total, name, error):
            if name:
                finished.append(name)
                raise error_type("stop")

        return progress

    def check(finished, cancelled):
        # every run has its report: the finished ones with their folders as on the local
        # threads, the others cancelled without a folder (the earlier set's one removed)
        sweep = json.loads((out / "sweep.json").read_text())
        assert [r["name"] for r in sweep] == rs.names
        assert {r["name"] for r in sweep if r["ok"]} == set(finished)
        for r in sweep:
            if r["ok"]:
                assert json.loads((out / r["name"] / "summary.json").read_text()) == r
            else:
                assert r["error"] == cancelled and r["results"] is None
                assert not (out / r["name"]).exists()
        assert csv_bytes(out) == {n: b for n, b in csv_bytes(tmp_path / "local").items() if n in finished}
        assert not [p for p in out.iterdir() if p.name.startswith(".")]

    first = []
    with pytest.raises(KeyboardInterrupt):
        rs.run(out, client=client, progress=stop_after_first(KeyboardInterrupt, first))
    assert len(first) == 1
    check(first, "cancelled: the run set was interrupted before this run finished")
    # resumed and stopped again (an exception of the progress callback): the kept run is
    # listed too
    second = []
    with pytest.raises(ValueError, match="stop"):
        rs.run(out, client=client, resume=True, progress=stop_after_first(ValueError, second))
    assert len(second) == 1 and second != first
    check(first + second, "cancelled: the run set stopped before this run finished (ValueError: stop)")
    # resumed to the end: only the runs not finished run
    ran = []
    again = rs.run(out, client=client, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == sorted(set(rs.names) - set(first + second))
    assert again.ok and csv_bytes(out) == csv_bytes(tmp_path / "local")
    assert [r["name"] for r in json.loads((out / "sweep.json").read_text()) if r["ok"]] == rs.names


def test_an_interrupted_set_stops_the_runs_under_way_on_the_workers(dist, client, tmp_path):
    """A cancelled future stops a task only before it starts: the runs already going on the
    workers are stopped through the set's stop event (they ran to their end before, minutes for
    long runs). Measured by the workers' CPU time once the set has raised."""
    d = speed_set(dist, [60.0, 70.0], stop_time=6000.0)  # about 10 s of work each, uninterrupted
    d["system"]["record"] = ["bogie.wheelset_front.lateral_displacement_relative"]
    rs = railfmu.RunSet.from_dict(d)

    def cpu_seconds():
        return sum(client.run(time.process_time).values())

    timer = threading.Timer(2.0, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            rs.run(tmp_path / "out", client=client)
    finally:
        timer.cancel()
    sweep = json.loads((tmp_path / "out" / "sweep.json").read_text())
    assert [r["ok"] for r in sweep] == [False, False]
    # each run polls the event about once a second, then stops at its next step; without the
    # event both workers stay busy for another 8 s
    time.sleep(2.0)
    before = cpu_seconds()
    time.sleep(2.0)
    busy = cpu_seconds() - before
    assert busy < 1.0, f"the workers used {busy:.1f} s of CPU in 2 s, 2 s after the set stopped"


def test_a_client_that_loses_its_scheduler_stops_the_set_as_an_interrupted_one(dist, client, tmp_path):
    """A scheduler of its own (the module's LocalCluster runs its scheduler in this process),
    killed once the first run has arrived: the set raises SchedulerLostError, the runs not
    finished are cancelled, not failed, and the module's cluster completes the set."""
    rs = eight_runs(dist, stop_time=1.0)
    local = rs.run(tmp_path / "local", threads=2)
    assert local.ok
    addr_file = tmp_path / "scheduler.json"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    scheduler = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--scheduler-file", str(addr_file), "--port", "0", "--no-dashboard"],
        **quiet,
    )
    worker = None
    own = None
    try:
        deadline = time.monotonic() + 60
        while not addr_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(addr_file), "--nthreads", "1", "--no-dashboard"],
            **quiet,
        )
        own = distributed.Client(scheduler_file=str(addr_file), timeout=60)
        own.wait_for_workers(1, timeout=60)
        arrived = []

        def kill_scheduler(done, total, name, error):
            if name:
                arrived.append((name, error))
                if scheduler.poll() is None:
                    scheduler.kill()

        out = tmp_path / "dask"
        with pytest.raises(railfmu.SchedulerLostError) as lost:
            rs.run(out, client=own, progress=kill_scheduler)
        assert isinstance(lost.value, ConnectionError) and isinstance(lost.value, railfmu.Error)
        # a run or two may arrive before the scheduler is gone
        assert 1 <= len(arrived) < 8 and all(error is None for _, error in arrived)
        assert f"lost its scheduler after {len(arrived)} of the 8 runs submitted" in str(lost.value)
    finally:
        scheduler.kill()
        if worker is not None:
            worker.kill()
        if own is not None:
            own.close(timeout=5)
    # the runs that arrived are whole; every other run is cancelled, none reported as failed
    sweep = json.loads((out / "sweep.json").read_text())
    assert [r["name"] for r in sweep] == rs.names
    finished = [r["name"] for r in sweep if r["ok"]]
    assert sorted(finished) == sorted(name for name, _ in arrived)
    for r in sweep:
        if not r["ok"]:
            assert r["error"].startswith("cancelled: the run set stopped before this run finished (SchedulerLostError: ")
    assert csv_bytes(out) == {n: b for n, b in csv_bytes(tmp_path / "local").items() if n in finished}
    # resumed on a working cluster: only the cancelled runs run
    ran = []
    again = rs.run(out, client=client, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == sorted(set(rs.names) - set(finished))
    assert again.ok and csv_bytes(out) == csv_bytes(tmp_path / "local")


def test_the_command_line_runs_a_set_on_the_cluster(dist, client, master_cmd, tmp_path):
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(speed_set(dist, [50.0, 70.0], stop_time=0.2)))
    local = railfmu.run_set(set_file, tmp_path / "local", threads=1)
    addr = client.scheduler.address
    r = subprocess.run(
        [sys.executable, "-m", "railfmu", "sweep", str(set_file), "-o", str(tmp_path / "cli"), "--dask-scheduler", addr, "-q"],
        capture_output=True, text=True, check=False,
    )
    assert r.returncode == 0, r.stderr
    assert "2 of 2 runs ok" in r.stdout
    assert csv_bytes(tmp_path / "cli") == csv_bytes(tmp_path / "local")
    assert local.ok
    # `master sweep --dask-scheduler` hands the set to the Python package
    env = dict(os.environ, RAILFMU_PYTHON=sys.executable)
    r = subprocess.run(
        [str(master_cmd), "sweep", str(set_file), "-o", str(tmp_path / "master"), "--dask-scheduler", addr],
        capture_output=True, text=True, check=False, env=env,
    )
    assert r.returncode == 0, r.stderr
    assert csv_bytes(tmp_path / "master") == csv_bytes(tmp_path / "local")
    # and its results format: Parquet, one table with the run parameters
    r = subprocess.run(
        [str(master_cmd), "sweep", str(set_file), "-o", str(tmp_path / "pq"), "--dask-scheduler", addr, "--format", "parquet"],
        capture_output=True, text=True, check=False, env=env,
    )
    assert r.returncode == 0, r.stderr
    assert not list((tmp_path / "pq").glob("*/results.csv"))
    table = pd.read_parquet(tmp_path / "pq" / "results")
    assert sorted(table.groupby("run")["bogie.vehicle.speed"].first().tolist()) == [50.0, 70.0]
    env["RAILFMU_PYTHON"] = str(tmp_path / "no-python")
    r = subprocess.run(
        [str(master_cmd), "sweep", str(set_file), "-o", str(tmp_path / "none"), "--dask-scheduler", addr],
        capture_output=True, text=True, check=False, env=env,
    )
    assert r.returncode == 1 and "needs the Python package railfmu" in r.stderr


def test_a_set_resumed_on_the_cluster_in_another_format_runs_again_into_one_format(dist, client, master_cmd, tmp_path):
    spec = speed_set(dist, [50.0, 70.0], stop_time=0.2)
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(spec))
    rs = railfmu.RunSet.from_dict(spec)
    out = tmp_path / "out"
    assert rs.run(out, threads=1, format="csv").ok
    env = dict(os.environ, RAILFMU_PYTHON=sys.executable)
    addr = client.scheduler.address

    def resume(*options):
        return subprocess.run(
            [str(master_cmd), "--quiet", "sweep", str(set_file), "-o", str(out), "--dask-scheduler", addr, "--resume", *options],
            capture_output=True, text=True, check=False, env=env,
        )

    r = resume("--format", "parquet")
    assert r.returncode == 0, r.stderr
    assert not list(out.glob("*/results.csv"))
    assert sorted(p.stem for p in (out / "results").glob("*.parquet")) == rs.names
    assert sorted(pd.read_parquet(out / "results")["run"].unique()) == rs.names
    summaries = {n: (out / n / "summary.json").read_bytes() for n in rs.names}
    assert resume("--format", "parquet").returncode == 0
    assert {n: (out / n / "summary.json").read_bytes() for n in rs.names} == summaries  # kept
    # no format: by size over every job as a fresh set (CSV for these short runs), all again
    ran = []
    again = rs.run(out, client=client, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert again.ok and sorted(n for n in ran if n) == rs.names
    assert sorted(csv_bytes(out)) == rs.names and not (out / "results").exists()


def test_the_fmu_cache_of_the_workers_stays_bounded(monkeypatch, tmp_path):
    from railfmu import dask as rdask

    # the workers' temporary folder (TMPDIR), as tempfile reads it
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    root = rdask._fmu_cache_dir()
    assert root.parent == tmp_path and root.is_dir()
    assert root.stat().st_mode & 0o777 == 0o700, "private to its user"
    now = time.time()
    hour, day = 3600, 24 * 3600

    def plant(name, unused_s, content=b"fmu"):
        folder = root / name
        folder.mkdir()
        (folder / "Model.fmu").write_bytes(content)
        os.utime(folder, (now - unused_s, now - unused_s))
        return folder

    def unpack(content):
        digest = hashlib.sha256(content).hexdigest()
        return Path(rdask._local_copy(digest, "New.fmu", content))

    # not cache entries: never touched, however old
    mine = root / "not-an-entry"
    mine.mkdir()
    os.utime(mine, (now - 30 * day, now - 30 * day))
    (root / "note.txt").write_text("kept")

    def entries():
        return {p.name for p in root.iterdir() if p.is_dir() and p != mine and not p.name.startswith(".")}

    old = plant("0" * 32, 8 * day)
    recent = plant("1" * 32, 2 * day)
    path = unpack(b"first")
    assert path.read_bytes() == b"first" and path.parent.name in entries()
    assert not old.exists()  # unused for more than 7 days
    assert recent.is_dir() and mine.is_dir() and (root / "note.txt").read_text() == "kept"
    assert not [p for p in root.iterdir() if p.name.startswith(".")]  # nothing left aside
    # a copy found again is marked as used, not written again
    os.utime(path.parent, (now - 8 * day, now - 8 * day))
    inode = path.stat().st_ino
    assert unpack(b"first") == path and path.stat().st_ino == inode
    assert path.parent.stat().st_mtime > now - 60
    # beyond the 16 most recently used, those not used for an hour go, least recently used
    # first
    aged = [plant(f"{k:030x}aa", 2 * day + (k + 1) * hour) for k in range(20)]
    in_use = [plant(f"{k:030x}bb", 10 * 60) for k in range(5)]
    second = unpack(b"second").parent
    kept = {second.name, path.parent.name, recent.name} | {f.name for f in in_use + aged[:8]}
    assert entries() == kept and len(kept) == 16
    # those used within the hour stay, even beyond 16 (a worker may be reading them)
    in_use += [plant(f"{k:030x}cc", 10 * 60) for k in range(18)]
    third = unpack(b"third").parent
    assert entries() == {third.name, second.name, path.parent.name} | {f.name for f in in_use}
    assert mine.is_dir() and (root / "note.txt").read_text() == "kept"
    assert not [p for p in root.iterdir() if p.name.startswith(".")]


def test_the_fmu_cache_replaces_a_damaged_copy_and_refuses_a_folder_others_can_write(monkeypatch, tmp_path):
    from railfmu import dask as rdask

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    content = b"an FMU's bytes"
    digest = hashlib.sha256(content).hexdigest()
    path = Path(rdask._local_copy(digest, "Model.fmu", content))
    assert path.read_bytes() == content
    # damaged in place at the same size (a hand, a disk): found by its hash, written again
    path.write_bytes(b"x" * len(content))
    assert Path(rdask._local_copy(digest, "Model.fmu", content)).read_bytes() == content
    # our cache folder opened to others (an earlier version under a umask of 002) is made
    # private again
    root = rdask._fmu_cache_dir()
    root.chmod(0o777)
    assert Path(rdask._local_copy(digest, "Model.fmu", content)).read_bytes() == content
    assert root.stat().st_mode & 0o777 == 0o700
    # a link in its place, to a folder someone else prepared
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    shutil.rmtree(root)
    root.symlink_to(elsewhere)
    with pytest.raises(RuntimeError, match="is not a folder"):
        rdask._local_copy(digest, "Model.fmu", content)
    assert not any(elsewhere.iterdir())


def test_the_command_line_reports_an_unreachable_scheduler_and_bad_options_as_errors(dist, tmp_path):
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(speed_set(dist, [50.0], stop_time=0.1)))
    cmd = [sys.executable, "-m", "railfmu", "sweep", str(set_file), "-o", str(tmp_path / "out"), "-q"]
    env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="1s")
    r = subprocess.run(cmd + ["--dask-scheduler", "tcp://127.0.0.1:9"], capture_output=True, text=True, env=env, check=False)
    assert r.returncode == 1 and r.stderr.startswith("error: cannot reach the Dask scheduler 'tcp://127.0.0.1:9'"), r.stderr
    assert "Traceback" not in r.stderr
    r = subprocess.run(cmd + ["-j", "0"], capture_output=True, text=True, check=False)
    assert r.returncode == 2 and "must be 1 or more, got 0" in r.stderr and "Traceback" not in r.stderr


def test_a_parquet_set_resumed_on_the_cluster_keeps_every_runs_parameter_columns(dist, client, tmp_path):
    """The cluster's writer gets the constant columns of the whole set as the local one does:
    a Parquet folder reads with its first file's columns, and a parameter only a kept run
    has was dropped from every run written on the resume."""

    def runs(speeds):
        return {
            **speed_set(dist, speeds, stop_time=0.1),
            "runs": [{"name": "soft", "parameters": {"bogie.vehicle.speed": 60.0, "bogie.suspension.lateral_stiffness": 1e5}}],
        }

    out = tmp_path / "dask"
    railfmu.run_set(runs([50.0, 60.0]), out, format="parquet", client=client)
    ran = []
    again = railfmu.RunSet.from_dict(runs([55.0, 60.0])).run(
        out, resume=True, format="parquet", client=client, progress=lambda d, t, n, e: ran.append(n)
    )
    assert again.ok and [n for n in ran if n] == ["run-000"]
    table = pd.read_parquet(out / "results")
    assert "bogie.suspension.lateral_stiffness" in table.columns, list(table.columns)
    assert table[table["run"] == "soft"]["bogie.suspension.lateral_stiffness"].unique().tolist() == [1e5]
    # the file the cluster wrote on the resume has the column itself
    assert "bogie.suspension.lateral_stiffness" in pq.read_schema(out / "results" / "run-000.parquet").names
