"""Parquet results of a run set: the folder `<out>/results` reads as one table with pandas,
every run with its name and parameters as columns, the units and FMU variables in the file
metadata, and the same values as the CSV of the same runs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import railfmu

from conftest import bits, run_master, speed_set


def test_a_parquet_run_set_folder_is_one_table_with_units_and_parameters(dist, master_cmd, tmp_path):
    set_file = tmp_path / "set.json"
    runs = speed_set(dist, [50.0, 60.0], seeds=[1, 2], stop_time=0.5)
    # a Real whose values are whole (0.0 throughout)
    runs["system"]["record"].append("bogie.initial.lateral_displacement")
    set_file.write_text(json.dumps(runs))
    r = run_master(master_cmd, "sweep", set_file, "-o", tmp_path / "pq", "--jobs", "2", "--format", "parquet")
    assert r.returncode == 0, r.stderr
    folder = tmp_path / "pq" / "results"
    table = pd.read_parquet(folder)
    # four runs of 501 rows each, in one call
    assert len(table) == 4 * 501
    runs = table.groupby("run")
    assert sorted(runs.groups) == ["run-000", "run-001", "run-002", "run-003"]
    # the run parameters are columns: each run has its speed and track seed
    params = runs[["bogie.vehicle.speed", "bogie.track.seed"]].first()
    assert sorted(map(tuple, params.to_numpy().tolist())) == [(50.0, 1.0), (50.0, 2.0), (60.0, 1.0), (60.0, 2.0)]
    # each of the type of its FMU variable: the seed an Integer, the speed a Real
    assert table["bogie.track.seed"].dtype == np.int32
    assert table["bogie.vehicle.speed"].dtype == np.float64
    # units, FMU variables and sampling in the file metadata
    meta = json.loads(pq.read_schema(folder / "run-000.parquet").metadata[b"railfmu.results"])
    columns = {c["name"]: c for c in meta["columns"]}
    force = columns["damper_left.damper.force"]
    assert force["unit"] == "N" and force["instance"] == "damper_left" and force["fmu_guid"]
    assert force["causality"] == "output"
    assert meta["sampling"]["rate_hz"] == 1000.0 and meta["sampling"]["decimation"] is None
    assert meta["parameters"]["bogie.vehicle.speed"] in (50.0, 60.0)
    assert meta["system"]["instances"][0]["name"] == "bogie"
    # the same runs as CSV carry the same values
    r = run_master(master_cmd, "sweep", set_file, "-o", tmp_path / "csv", "--jobs", "2", "--format", "csv")
    assert r.returncode == 0, r.stderr
    csv = pd.read_csv(tmp_path / "csv" / "run-002" / "results.csv")
    one = table[table["run"] == "run-002"]
    for label in csv.columns:
        assert np.array_equal(bits(one[label].to_numpy()), bits(csv[label].to_numpy())), label
        # pandas reads each column of either file as the same type: a Real as float64, whole
        # values too (a CSV's "0" read as int64)
        assert csv[label].dtype == one[label].dtype == np.float64, label
    csv_meta = json.loads((tmp_path / "csv" / "run-002" / "results.meta.json").read_text())
    assert csv_meta["columns"] == meta["columns"]
    # the Python package reads either run set to the same bits
    pq_set, csv_set = railfmu.read_results(tmp_path / "pq"), railfmu.read_results(tmp_path / "csv")
    assert np.array_equal(bits(pq_set["run-002"].values), bits(csv_set["run-002"].values))
    assert pq_set["run-002"].units["damper_left.damper.force"] == "N"
    assert pq_set["run-002"].summary["steps"] == 500


def test_master_run_writes_parquet_by_extension(passive_file, master_cmd, tmp_path):
    out = tmp_path / "one.parquet"
    r = run_master(master_cmd, "run", passive_file, "-o", out)
    assert r.returncode == 0, r.stderr
    table = pd.read_parquet(out)
    assert table.columns[0] == "time [s]" and len(table) == 1001
    assert "run" not in table.columns
    assert Path(out).with_suffix(".meta.json").exists() is False
    # the same run from Python, written by to_parquet: the same table and metadata
    res = railfmu.System.load(passive_file).run()
    mine = tmp_path / "mine.pq"
    res.to_parquet(mine)
    assert pd.read_parquet(mine).equals(table)
    meta = lambda p: json.loads(pq.read_schema(p).metadata[b"railfmu.results"])  # noqa: E731
    a, b = meta(out), meta(mine)
    for m in (a, b):
        m["summary"].pop("wall_time_s")
        m["summary"].pop("realtime_ratio")
    assert a == b
    back = railfmu.read_results(mine)
    assert np.array_equal(bits(back.values), bits(res.values))
    with pytest.raises(railfmu.OutputError, match="name .*mine.csv' .parquet"):
        res.to_parquet(tmp_path / "mine.csv")


def test_a_hosts_parquet_file_is_assessed_whatever_its_compression(tmp_path):
    # pandas writes snappy by default, other tools gzip: both read as our own zstd
    t = np.arange(0.0, 20.0, 0.001)
    df = pd.DataFrame({"time [s]": t, "a [m/s2]": 0.5 * np.sin(2 * np.pi * 4 * t)})
    verdicts = []
    for compression in ("snappy", "gzip", "zstd", None):
        path = tmp_path / f"host_{compression}.parquet"
        df.to_parquet(path, compression=compression, index=False)
        verdicts.append(str(railfmu.assess_stability(path, "a", 200.0)))
    assert len(set(verdicts)) == 1 and verdicts[0].endswith("max rms 0.356 m/s2, limit 5.390 m/s2: met>"), verdicts
