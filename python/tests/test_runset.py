"""Run sets on local threads: the same folders as `master sweep`, a progress callback, failures
kept per run, resuming skips finished runs (also after an interruption), and the folder reads
back."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import railfmu
from conftest import bits, run_master, speed_set


def csv_bytes(folder: Path) -> dict:
    return {p.parent.name: p.read_bytes() for p in sorted(folder.glob("*/results.csv"))}


def test_a_local_run_set_equals_master_sweep(dist, master_cmd, tmp_path):
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(speed_set(dist, [50.0, 60.0, 70.0, 80.0], seeds=[1, 2], stop_time=0.5)))
    r = run_master(master_cmd, "sweep", set_file, "-o", tmp_path / "cli", "--jobs", "2")
    assert r.returncode == 0, r.stderr
    calls = []
    res = railfmu.run_set(set_file, tmp_path / "py", threads=2, progress=lambda *a: calls.append(a))
    assert res.ok and len(res) == 8
    cli, py = csv_bytes(tmp_path / "cli"), csv_bytes(tmp_path / "py")
    assert len(py) == 8 and py == cli
    for name in res:
        assert (tmp_path / "py" / name / "system.json").read_bytes() == (tmp_path / "cli" / name / "system.json").read_bytes()
    assert sorted(c[0] for c in calls) == list(range(1, 9))
    assert {c[2] for c in calls} == set(res)
    assert all(c[1] == 8 and c[3] is None for c in calls)
    # the eight runs differ from each other (speeds and seeds reach the FMU)
    finals = {n: res[n].values[-1, 1] for n in res}
    assert len(set(finals.values())) == 8
    # read back: reports, per-run tables, one long DataFrame
    back = railfmu.read_results(tmp_path / "cli")
    assert isinstance(back, railfmu.RunSetResults) and back.ok
    assert np.array_equal(bits(back["run-005"].values), bits(res["run-005"].values))
    assert back["run-005"].summary["steps"] == 500
    table = back.summary_frame()
    assert list(table["bogie.vehicle.speed"]) == [50.0, 60.0, 70.0, 80.0] * 2  # keys in alphabetical order: seed outer
    long = back.to_pandas()
    assert long.index.names == ["run", "time"] and len(long) == 8 * 501
    assert long.attrs["units"]["damper_left.damper.force"] == "N"
    one = railfmu.read_results(tmp_path / "cli" / "run-005")
    assert one.summary["steps"] == 500


def test_a_failed_run_is_kept_and_the_others_go_on(dist, tmp_path):
    rs = speed_set(dist, [60.0], stop_time=0.2)
    # a value within the declared range that only the FMU refuses (speed > 0): that run fails
    rs["runs"] = [{"name": "standstill", "parameters": {"bogie.vehicle.speed": 0.0}}, {"name": "slow", "parameters": {"bogie.vehicle.speed": 40.0}}]
    res = railfmu.run_set(rs, tmp_path / "out", threads=2)
    assert not res.ok
    assert set(res) == {"run-000", "slow"}
    assert "'vehicle.speed': must be > 0" in res.failed["standstill"]
    with pytest.raises(KeyError, match="failed"):
        res["standstill"]
    sweep = json.loads((tmp_path / "out" / "sweep.json").read_text())
    assert [r["name"] for r in sweep] == ["run-000", "standstill", "slow"]
    assert not (tmp_path / "out" / "standstill" / "results.csv").exists()
    # it failed before its first row: no history
    assert res.history("standstill") is None
    with pytest.raises(KeyError, match="did not fail"):
        res.history("slow")


DERAILS = {
    "bogie.vehicle.speed": 150.0,
    "bogie.suspension.lateral_stiffness": 0.0,
    "bogie.suspension.longitudinal_stiffness": 0.0,
}


@pytest.mark.parametrize("format", ["csv", "parquet"])
def test_a_run_that_fails_midway_keeps_its_history_in_its_folder(dist, master_cmd, tmp_path, format):
    rs = speed_set(dist, [60.0], stop_time=2.0)
    rs["runs"] = [{"name": "derails", "parameters": DERAILS}]
    res = railfmu.run_set(rs, tmp_path / "py", threads=2, format=format)
    assert set(res) == {"run-000"} and "derailment" in res.failed["derails"]
    with pytest.raises(KeyError, match=r"\.history\('derails'\)"):
        res["derails"]
    history = res.history("derails")
    t = history.time
    assert 0.1 < t[-1] < 2.0 and len(t) == round(t[-1] / 1e-3) + 1
    assert history.summary["failed"]["time_s"] == t[-1]
    assert "derailment" in history.summary["failed"]["error"]
    assert (tmp_path / "py" / "derails" / f"history.{format}").is_file()
    # read as a file, beside the failed run's report (which has no summary), it keeps its own
    alone = railfmu.read_results(tmp_path / "py" / "derails" / f"history.{format}")
    assert alone.summary["failed"] == history.summary["failed"]
    # never in the results table, which holds completed runs only
    assert not (tmp_path / "py" / "results" / "derails.parquet").exists()
    # the command line writes the same history
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(rs))
    r = run_master(master_cmd, "sweep", set_file, "-o", tmp_path / "cli", "--format", format)
    assert r.returncode == 1 and "derails: FAILED:" in r.stdout, r.stderr
    assert f"(its history up to the failure is in {tmp_path / 'cli' / 'derails' / f'history.{format}'})" in r.stdout, r.stdout
    cli = railfmu.read_results(tmp_path / "cli").history("derails")
    assert np.array_equal(bits(cli.values), bits(history.values))


def test_a_misspelt_variable_refuses_the_set_before_it_touches_the_folder(dist, tmp_path):
    out = tmp_path / "out"
    railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0], stop_time=0.1)).run(out, threads=1)
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    rs = speed_set(dist, [60.0], stop_time=0.1)
    rs["runs"] = [{"name": "typo", "parameters": {"bogie.vehicle.sped": 70.0}}]
    with pytest.raises(railfmu.SystemDescriptionError, match=r"run 'typo'.*unknown variable 'vehicle.sped'.*did you mean 'vehicle.speed'"):
        railfmu.run_set(rs, out, threads=2)
    rs["runs"] = [{"name": "fast", "parameters": {"bogie.vehicle.speed": 250.0}}]
    with pytest.raises(railfmu.SystemDescriptionError, match=r"run 'fast'.*above its maximum 200"):
        railfmu.run_set(rs, out, threads=2)
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_a_resumed_set_skips_finished_runs(dist, tmp_path):
    rs = railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0, 70.0, 80.0], stop_time=0.3))
    out = tmp_path / "out"
    first = rs.run(out, threads=2)
    before = csv_bytes(out)
    # one run lost, one interrupted before its summary, one whose inputs changed
    shutil.rmtree(out / "run-001")
    (out / "run-002" / "summary.json").unlink()
    sys2 = json.loads((out / "run-003" / "system.json").read_text())
    sys2["stop_time"] = 0.2
    (out / "run-003" / "system.json").write_text(json.dumps(sys2))
    ran = []
    again = rs.run(out, threads=2, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == ["run-001", "run-002", "run-003"]
    assert again.ok and csv_bytes(out) == before
    assert [r["name"] for r in again.reports] == [r["name"] for r in first.reports]
    # nothing left to do
    ran.clear()
    rs.run(out, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert [n for n in ran if n] == []


def test_an_interrupted_resumed_set_lists_every_run(dist, tmp_path):
    rs = railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0, 70.0, 80.0], seeds=[1, 2], stop_time=1.0))
    out = tmp_path / "out"

    def interrupt(done, total, name, error):
        if name:
            raise KeyboardInterrupt

    def listed():
        sweep = json.loads((out / "sweep.json").read_text())
        assert [r["name"] for r in sweep] == rs.names
        for r in sweep:
            if r["ok"] or r["error"].startswith("cancelled"):
                # finished, or stopped at a communication point: its folder
                assert json.loads((out / r["name"] / "summary.json").read_text()) == r
                assert (out / r["name"] / "results.csv").is_file() == r["ok"]
            else:
                # not started: no folder
                assert r["error"] == "not run: the run set was interrupted before this run started"
                assert not (out / r["name"]).exists()
        return {r["name"] for r in sweep if r["ok"]}

    with pytest.raises(KeyboardInterrupt):
        rs.run(out, threads=1, progress=interrupt)
    first = listed()
    assert first and len(first) < len(rs)
    # interrupted again when resumed: sweep.json lists the kept runs too
    with pytest.raises(KeyboardInterrupt):
        rs.run(out, threads=1, resume=True, progress=interrupt)
    second = listed()
    assert first < second < set(rs.names)
    ran = []
    again = rs.run(out, threads=1, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == sorted(set(rs.names) - second)
    assert again.ok and listed() == set(rs.names)


def test_a_run_set_into_a_used_folder_holds_its_own_runs_and_replaces_nothing_else(dist, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("the user's")
    railfmu.run_set(speed_set(dist, [50.0, 60.0, 70.0], stop_time=0.2), out, format="parquet")
    railfmu.run_set(speed_set(dist, [55.0], stop_time=0.2), out, format="parquet")
    # the earlier set's other runs are gone (also from the table), the user's file is not
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "results", "run-000", "sweep.json"]
    assert [p.name for p in (out / "results").iterdir()] == ["run-000.parquet"]
    # a run whose folder would replace something that is not a run folder is refused
    rs = speed_set(dist, [55.0], stop_time=0.2)
    rs["runs"] = [{"name": "notes.txt", "parameters": {}}]
    with pytest.raises(railfmu.OutputError, match="not a run folder of an earlier sweep"):
        railfmu.run_set(rs, out)
    assert (out / "notes.txt").read_text() == "the user's"


def test_bad_run_set_options_raise_python_errors(dist, tmp_path):
    rs = speed_set(dist, [50.0], stop_time=0.2)
    for threads in (-1, 0, 1.5, True):
        with pytest.raises(ValueError, match="threads must be a whole number >= 1"):
            railfmu.run_set(rs, tmp_path / "out", threads=threads)
    # the cluster's workers run a Dask set: local threads beside a client are refused (the
    # check comes before the client is used, so any object stands for one)
    with pytest.raises(ValueError, match="give threads or client, not both"):
        railfmu.run_set(rs, tmp_path / "out", threads=2, client=object())
    with pytest.raises(TypeError, match="progress must be True, False, None or a callable"):
        railfmu.run_set(rs, tmp_path / "out", progress=5)
    # "no" is no False (it was taken as True)
    with pytest.raises(TypeError, match="resume must be True or False, got 'no'"):
        railfmu.run_set(rs, tmp_path / "out", resume="no")
    assert not (tmp_path / "out").exists()
    # a NumPy whole number is a whole number
    assert railfmu.run_set(rs, tmp_path / "numpy", threads=np.int64(1)).ok
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    with pytest.raises(railfmu.OutputError, match="cannot create the output folder"):
        railfmu.run_set(rs, a_file / "out")
    # a set in which no run succeeds warns, naming the first failure
    bad = speed_set(dist, [50.0, 60.0], stop_time=0.2)
    bad["product"] = {"bogie.vehicle.speed": [0.0, 0.0]}
    with pytest.warns(RuntimeWarning, match=r"no run of the set succeeded \(2 failed\).*'vehicle.speed': must be > 0"):
        res = railfmu.run_set(bad, tmp_path / "bad")
    assert len(res) == 0 and set(res.failed) == {"run-000", "run-001"}


def test_the_readme_run_set_expands_to_eight_resolved_runs():
    rs = railfmu.RunSet.load(Path(__file__).parents[1] / "examples" / "passive_speeds.json")
    assert len(rs) == 8 and rs.names[0] == "run-000"
    job = rs.jobs[5]
    assert job["parameters"] == {"bogie.track.seed": 2, "bogie.vehicle.speed": 66.67}
    assert job["system"]["instances"][0]["parameters"]["vehicle.speed"] == 66.67
    assert all(Path(i["fmu"]).is_absolute() for i in job["system"]["instances"])


def test_master_sweep_resume_keeps_complete_runs(dist, master_cmd, tmp_path):
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(speed_set(dist, [50.0, 60.0, 70.0, 80.0], stop_time=0.3)))
    out = tmp_path / "out"
    assert run_master(master_cmd, "sweep", set_file, "-o", out).returncode == 0
    before = csv_bytes(out)
    summaries = {n: (out / n / "summary.json").read_bytes() for n in before}
    shutil.rmtree(out / "run-001")
    (out / "run-002" / "results.csv").unlink()
    r = run_master(master_cmd, "sweep", set_file, "-o", out, "--resume")
    assert r.returncode == 0, r.stderr
    assert "2 complete run(s) kept, 2 run" in r.stdout
    assert csv_bytes(out) == before
    # kept runs were not run again: their summaries (with their wall times) are untouched
    for n in ("run-000", "run-003"):
        assert (out / n / "summary.json").read_bytes() == summaries[n]
    assert [s["name"] for s in json.loads((out / "sweep.json").read_text())] == sorted(before)
    r = run_master(master_cmd, "sweep", set_file, "-o", out, "--resume")
    assert "4 complete run(s) kept, 0 run" in r.stdout


def parquet_names(out: Path) -> list:
    return sorted(p.stem for p in (out / "results").glob("*.parquet"))


def test_a_run_set_resumed_in_another_format_runs_again_into_one_format(dist, master_cmd, tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    spec = speed_set(dist, [50.0, 60.0, 70.0], stop_time=0.3)
    rs = railfmu.RunSet.from_dict(spec)
    out = tmp_path / "py"
    rs.run(out, threads=2, format="csv")
    assert sorted(csv_bytes(out)) == rs.names
    ran = []
    rs.run(out, threads=2, resume=True, format="parquet", progress=lambda d, t, n, e: ran.append(n))
    # every run again, each in results/ and none left as CSV: the folder is one table
    assert sorted(n for n in ran if n) == rs.names
    assert parquet_names(out) == rs.names and csv_bytes(out) == {}
    assert not list(out.glob("*/results.meta.json"))
    table = pd.read_parquet(out / "results")
    assert sorted(table["run"].unique()) == rs.names
    # sweep.json names them relative to its folder (they read wherever the set ran from)
    assert [s["results"] for s in json.loads((out / "sweep.json").read_text())] == [
        f"results/{n}.parquet" for n in rs.names
    ]
    # the same format keeps every run
    ran.clear()
    rs.run(out, threads=2, resume=True, format="parquet", progress=lambda d, t, n, e: ran.append(n))
    assert [n for n in ran if n] == []
    # by size (short runs: CSV) as a fresh run set: every run again, no Parquet file left
    rs.run(out, threads=2, resume=True, progress=lambda d, t, n, e: ran.append(n))
    assert sorted(n for n in ran if n) == rs.names
    assert sorted(csv_bytes(out)) == rs.names and not (out / "results").exists()

    # master sweep: the same rule
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(spec))
    cli = tmp_path / "cli"
    r = run_master(master_cmd, "sweep", set_file, "-o", cli, "--format", "csv")
    assert r.returncode == 0, r.stderr
    r = run_master(master_cmd, "sweep", set_file, "-o", cli, "--resume", "--format", "parquet")
    assert r.returncode == 0, r.stderr
    assert "0 complete run(s) kept, 3 run" in r.stdout
    assert parquet_names(cli) == rs.names and csv_bytes(cli) == {}
    assert sorted(pd.read_parquet(cli / "results")["run"].unique()) == rs.names
    r = run_master(master_cmd, "sweep", set_file, "-o", cli, "--resume", "--format", "parquet")
    assert "3 complete run(s) kept, 0 run" in r.stdout
    # without --format the sweep decides by size first (CSV here) and runs every run again
    r = run_master(master_cmd, "sweep", set_file, "-o", cli, "--resume")
    assert r.returncode == 0, r.stderr
    assert "0 complete run(s) kept, 3 run" in r.stdout
    assert sorted(csv_bytes(cli)) == rs.names and not (cli / "results").exists()


def test_the_parameters_of_a_run_set_carry_their_units(dist, master_cmd, tmp_path):
    set_file = tmp_path / "set.json"
    set_file.write_text(json.dumps(speed_set(dist, [50.0, 60.0], stop_time=0.1)))
    r = run_master(master_cmd, "sweep", set_file, "-o", tmp_path / "cli", "--jobs", "1")
    assert r.returncode == 0, r.stderr
    units = {"bogie.track.seed": None, "bogie.vehicle.speed": "m/s"}
    for res in (railfmu.run_set(set_file, tmp_path / "py", threads=1), railfmu.read_results(tmp_path / "cli")):
        assert res.parameter_units == units
        table = res.summary_frame()
        assert table.attrs["units"]["bogie.vehicle.speed"] == "m/s"
        assert table.attrs["units"]["wall_time_s"] == "s"
        assert set(table.attrs["units"]) == set(table.columns)
    # FMUs that cannot be read any more: the table without the units, and a warning why
    moved = tmp_path / "moved"
    shutil.copytree(tmp_path / "cli", moved)
    for run in ("run-000", "run-001"):
        p = moved / run / "system.json"
        p.write_text(p.read_text().replace(str(dist), str(tmp_path / "nowhere")))
    with pytest.warns(RuntimeWarning, match="units are unknown.*nowhere"):
        table = railfmu.read_results(moved).summary_frame()
    assert table.attrs["units"]["bogie.vehicle.speed"] is None
    with pytest.raises(railfmu.FmuError, match="nowhere"):
        railfmu.read_results(moved).parameter_units


def test_a_set_that_fails_before_its_first_run_leaves_the_earlier_set_whole(dist, tmp_path):
    out = tmp_path / "out"
    railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0], stop_time=0.1)).run(out, threads=1)
    assert len(json.loads((out / "sweep.json").read_text())) == 2
    fmus = tmp_path / "fmus"
    shutil.copytree(dist, fmus)
    rs = railfmu.RunSet.from_dict(speed_set(fmus, [55.0, 65.0, 75.0], stop_time=0.1))
    (fmus / "Bogie2Dof.fmu").write_bytes(b"not a zip archive")
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    with pytest.raises(railfmu.Error):
        rs.run(out, threads=1)
    # refused before the folder is touched: the earlier set stays whole, its report with it
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_a_second_set_into_a_folder_in_use_is_refused(dist, master_cmd, tmp_path):
    import fcntl

    out = tmp_path / "out"
    railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0], stop_time=0.1)).run(out, threads=1)
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    # the lock a set writing into the folder holds (an flock on the folder itself)
    fd = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(railfmu.OutputError, match="another run set or study is writing into"):
            railfmu.RunSet.from_dict(speed_set(dist, [70.0], stop_time=0.1)).run(out, threads=1)
        set_file = tmp_path / "set.json"
        set_file.write_text(json.dumps(speed_set(dist, [70.0], stop_time=0.1)))
        r = run_master(master_cmd, "sweep", set_file, "-o", out)
        assert r.returncode == 1 and "another run set or study is writing into" in r.stderr, r.stderr
        assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    finally:
        os.close(fd)
    # released: the next set runs
    assert railfmu.RunSet.from_dict(speed_set(dist, [70.0], stop_time=0.1)).run(out, threads=1).ok
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_the_sweep_command_names_the_failed_runs_and_exits_1(dist, tmp_path):
    rs = speed_set(dist, [40.0], stop_time=0.2)
    rs["runs"] = [{"name": "standstill", "parameters": {"bogie.vehicle.speed": 0.0}}]
    path = tmp_path / "set.json"
    path.write_text(json.dumps(rs))
    cmd = [sys.executable, "-m", "railfmu", "sweep", str(path), "-o", str(tmp_path / "out"), "-q"]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stderr
    assert "error: 1 run(s) failed: standstill" in r.stderr, r.stderr
    assert "1 of 2 runs ok" in r.stdout, r.stdout
    assert "standstill: FAILED: " in r.stdout, r.stdout
    assert (tmp_path / "out" / "run-000" / "results.csv").is_file()
    # --jobs means nothing on a Dask cluster: refused before anything is read or written
    cmd = [sys.executable, "-m", "railfmu", "sweep", str(path), "-o", str(tmp_path / "dask")]
    r = subprocess.run(cmd + ["-j", "2", "--dask-scheduler", "tcp://127.0.0.1:1"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stderr
    assert "error: --jobs: the runs go to the Dask scheduler's workers" in r.stderr, r.stderr
    assert not (tmp_path / "dask").exists()


def test_a_bad_option_is_refused_before_the_earlier_sets_results_are_touched(dist, tmp_path):
    rs = railfmu.RunSet.from_dict(speed_set(dist, [50.0, 60.0], stop_time=0.2))
    out = tmp_path / "out"
    first = rs.run(out, threads=2, format="csv")
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    for options, error in [
        ({"format": "CSV "}, ValueError),
        ({"format": "pq"}, ValueError),
        ({"format": 3}, TypeError),
        ({"retries": -1}, ValueError),
        ({"retries": "x"}, ValueError),
        ({"client": object(), "ship_fmus": False}, TypeError),
    ]:
        with pytest.raises(error):
            rs.run(out, resume=True, **options)
        after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
        assert after == before, options
    assert railfmu.read_results(out).ok and len(first) == 2
    # more threads than a machine has, or than runs: as many as there are runs
    again = rs.run(tmp_path / "many", threads=2**70)
    assert again.ok and len(again) == 2
    # an empty path is not taken for the working folder
    with pytest.raises(ValueError, match="empty path"):
        rs.run("")


def test_a_users_folders_beside_the_runs_are_kept(dist, tmp_path):
    out = tmp_path / "project"
    vehicle = out / "my_vehicle"
    vehicle.mkdir(parents=True)
    (vehicle / "system.json").write_text("{}")
    (vehicle / "notes.txt").write_text("mine")
    report = out / "report"
    report.mkdir()
    (report / "summary.json").write_text('{"pages": 3}')
    res = railfmu.RunSet.from_dict(speed_set(dist, [50.0], stop_time=0.2)).run(out, threads=1)
    assert res.ok
    assert (vehicle / "notes.txt").read_text() == "mine" and (report / "summary.json").is_file()


def test_descriptions_given_as_python_values(dist, tmp_path):
    # NumPy numbers and arrays are numbers and lists
    rs = speed_set(dist, [50.0], stop_time=0.2)
    rs["product"] = {"bogie.vehicle.speed": np.linspace(50.0, 60.0, 2), "bogie.track.seed": [np.int64(1)]}
    assert len(railfmu.RunSet.from_dict(rs)) == 2
    # a NaN is named where it is (JSON has no NaN)
    rs["product"]["bogie.vehicle.speed"] = [50.0, float("nan")]
    with pytest.raises(railfmu.SystemDescriptionError, match=r"product\.bogie\.vehicle\.speed\[1\]: nan"):
        railfmu.RunSet.from_dict(rs)
    system = speed_set(dist, [50.0], stop_time=0.2)["system"]
    system["step"] = float("inf")
    with pytest.raises(railfmu.SystemDescriptionError, match="step: inf"):
        railfmu.System.from_dict(system)
    # a range, a pandas Series and a path are what they read as; anything else is named by its
    # type (the message was empty)
    import pandas as pd

    rs["product"] = {"bogie.track.seed": range(1, 3), "bogie.vehicle.speed": pd.Series([50.0, 60.0])}
    assert len(railfmu.RunSet.from_dict(rs)) == 4
    system = speed_set(dist, [50.0], stop_time=0.2)["system"]
    system["instances"][1]["fmu"] = Path(system["instances"][1]["fmu"])
    assert railfmu.System.from_dict(system)
    rs["product"] = {"bogie.track.seed": [1], "bogie.vehicle.speed": pd.Series([50.0, float("nan")])}
    with pytest.raises(railfmu.SystemDescriptionError, match=r"product\.bogie\.vehicle\.speed\[1\]: nan"):
        railfmu.RunSet.from_dict(rs)
    rs["product"] = {"bogie.track.seed": {1, 2}}
    with pytest.raises(railfmu.SystemDescriptionError, match="set {1, 2} is not a value JSON holds"):
        railfmu.RunSet.from_dict(rs)


def test_a_run_set_does_not_write_over_or_remove_its_own_inputs(dist, tmp_path):
    """As `master sweep`: a run-set file saved as <out>/sweep.json is not replaced by the report,
    and a base system in a run folder the set replaces is refused, before anything changes."""
    out = tmp_path / "out"
    out.mkdir()
    set_file = out / "sweep.json"
    text = json.dumps(speed_set(dist, [50.0, 60.0], stop_time=0.05))
    set_file.write_text(text)
    with pytest.raises(railfmu.OutputError, match="same file as the input"):
        railfmu.run_set(set_file, out)
    assert set_file.read_text() == text
    railfmu.run_set(speed_set(dist, [50.0, 60.0], stop_time=0.05), tmp_path / "b", format="csv")
    base = tmp_path / "b" / "run-001" / "system.json"
    before = base.read_bytes()
    (tmp_path / "rs_b.json").write_text(json.dumps({"base": str(base), "product": {"bogie.track.seed": [3, 4]}}))
    with pytest.raises(railfmu.OutputError, match="run-001"):
        railfmu.run_set(tmp_path / "rs_b.json", tmp_path / "b")
    assert base.read_bytes() == before
    assert sorted(p.name for p in (tmp_path / "b").iterdir()) == ["run-000", "run-001", "sweep.json"]


def test_a_resumed_parquet_set_keeps_every_runs_parameter_columns(dist, master_cmd, tmp_path):
    """A resume writes the runs it makes with the constant columns of the whole set: a Parquet
    folder reads with its first file's columns, so a parameter only a kept run has was dropped
    from every run (locally, and by `master sweep --resume`)."""
    import pandas as pd

    def runs(speeds):
        return {
            **speed_set(dist, speeds, stop_time=0.1),
            "runs": [{"name": "soft", "parameters": {"bogie.vehicle.speed": 60.0, "bogie.suspension.lateral_stiffness": 1e5}}],
        }

    def soft_stiffness(folder: Path):
        table = pd.read_parquet(folder / "results")
        assert "bogie.suspension.lateral_stiffness" in table.columns, list(table.columns)
        return table[table["run"] == "soft"]["bogie.suspension.lateral_stiffness"].unique().tolist()

    out = tmp_path / "py"
    railfmu.run_set(runs([50.0, 60.0]), out, format="parquet")
    assert soft_stiffness(out) == [1e5]
    # run-000 is computed again (its speed changed), the others kept
    ran = []
    railfmu.RunSet.from_dict(runs([55.0, 60.0])).run(out, resume=True, format="parquet", progress=lambda d, t, n, e: ran.append(n))
    assert [n for n in ran if n] == ["run-000"]
    assert soft_stiffness(out) == [1e5]
    cli = tmp_path / "cli"
    set_file = tmp_path / "set.json"
    for speeds in ([50.0, 60.0], [55.0, 60.0]):
        set_file.write_text(json.dumps(runs(speeds)))
        r = run_master(master_cmd, "sweep", set_file, "-o", cli, "--resume", "--format", "parquet")
        assert r.returncode == 0, r.stderr
    assert "2 complete run(s) kept, 1 run" in r.stdout
    assert soft_stiffness(cli) == [1e5]


def test_malformed_run_set_summaries_are_named(dist, tmp_path):
    for text, why in [
        ("[1, 2]", "entry 0 is not a run report"),
        ('[{"name": "x"}]', "entry 0 is not a run report"),
        ("null", "a list of run reports expected, got NoneType"),
        ('[{"name": 5, "ok": true}]', "entry 0 is not a run report"),
        ('[{"name": "../x", "ok": true}]', "is not a folder name"),
        ('[{"name": "x", "ok": true, "summary": 5}]', "must be objects"),
    ]:
        folder = tmp_path / f"set{abs(hash(text))}"
        folder.mkdir()
        (folder / "sweep.json").write_text(text)
        with pytest.raises(railfmu.OutputError, match="is not a run-set summary") as e:
            railfmu.read_results(folder)
        assert why in str(e.value), (text, str(e.value))
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "sweep.json").write_text("[]")
    df = railfmu.read_results(empty).summary_frame()
    assert len(df) == 0 and df.index.name == "run"
    # a run folder's summary.json that is not a report is left out (the statistics come
    # from the results' metadata), not an error
    run = railfmu.RunSet.from_dict(speed_set(dist, [50.0], stop_time=0.2)).run(tmp_path / "one", threads=1)
    folder = tmp_path / "one" / next(iter(run))
    for text in ("[1, 2]", '{"ok": true, "summary": 5}'):
        (folder / "summary.json").write_text(text)
        assert railfmu.read_results(folder).summary == run.reports[0]["summary"]


def test_two_columns_of_one_name_are_refused():
    with pytest.raises(ValueError, match="columns 'x \\[m\\]' and 'x \\[mm\\]' have the same name 'x'"):
        railfmu.Results(["time [s]", "x [m]", "y [N]", "x [mm]"], np.array([[0.0, 1.0, 2.0, 3.0]]))
    # a list of rows is taken as an array
    r = railfmu.Results(["time [s]", "x [m]"], [[0.0, 1.0], [0.1, 2.0]])
    assert r.values.shape == (2, 2)
