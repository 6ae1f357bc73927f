"""One system from Python: the same bits as `master run`, results with units, parameters,
progress, the GIL released during runs, errors as exceptions with the master's messages."""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import threading
from sys import getswitchinterval, setswitchinterval
import zipfile
from pathlib import Path

import numpy as np
import pytest

import railfmu
from conftest import bits, passive, run_master


def test_a_run_from_python_equals_the_command_line_bit_for_bit(passive_file, master_cmd, tmp_path):
    cli_csv = tmp_path / "cli.csv"
    r = run_master(master_cmd, "run", passive_file, "-o", cli_csv)
    assert r.returncode == 0, r.stderr
    res = railfmu.System.load(passive_file).run()
    assert len(res) == 1001  # 1 s at 1 ms, both ends
    cli = railfmu.read_results(cli_csv)
    assert cli.header == res.header
    assert np.array_equal(bits(cli.values), bits(res.values))
    # written from Python, the file is the command line's byte for byte
    py_csv = tmp_path / "py.csv"
    res.to_csv(py_csv)
    assert py_csv.read_bytes() == cli_csv.read_bytes()
    # the bogie moves: the comparison is not one of empty tables
    assert np.max(np.abs(res["bogie.wheelset_front.lateral_displacement_relative"])) > 1e-6


def cli_run_and_base(dist, master_cmd, tmp_path):
    """`master run` of the passive system at 55 m/s, track seed 7, 0.5 s into cli.csv; and the
    description of the unchanged system (2 s) for Python to change the same way."""
    changed = tmp_path / "changed.json"
    changed.write_text(json.dumps(passive(dist, 0.5, **{"vehicle.speed": 55.0, "track.seed": 7})))
    cli_csv = tmp_path / "cli.csv"
    assert run_master(master_cmd, "run", changed, "-o", cli_csv).returncode == 0
    base = tmp_path / "base.json"
    base.write_text(json.dumps(passive(dist, 2.0)))
    return cli_csv, base


def test_start_values_from_python_equal_a_description_holding_them(dist, master_cmd, tmp_path):
    cli_csv, base = cli_run_and_base(dist, master_cmd, tmp_path)
    sys = railfmu.System.load(base)
    sys.set_parameter("bogie.vehicle.speed", np.float64(55.0))  # NumPy scalars are accepted
    sys.set_parameters({"bogie.track.seed": np.int64(7)})
    sys.stop_time = 0.5
    res = sys.run()
    assert np.array_equal(bits(res.values), bits(railfmu.read_results(cli_csv).values))
    # run-only values do not stick; another seed gives another track
    other = sys.run({"bogie.track.seed": 8})
    assert sys.parameters["bogie.track.seed"] == 7
    assert not np.array_equal(other.values, res.values)
    assert np.array_equal(bits(sys.run().values), bits(res.values))


def test_results_carry_units_into_pandas_and_numpy(passive_file):
    res = railfmu.System.load(passive_file).run(stop_time=0.2)
    df = res.to_pandas()
    assert df.index.name == "time"
    assert df.index[-1] == pytest.approx(0.2)
    assert list(df.columns) == res.names[1:]
    assert df.attrs["units"]["time"] == "s"
    assert df.attrs["units"]["bogie.wheelset_front.lateral_displacement_relative"] == "m"
    assert df.attrs["units"]["damper_left.damper.force"] == "N"
    assert df.attrs["summary"]["steps"] == 200
    assert np.array_equal(df["damper_left.damper.force"].to_numpy(), res["damper_left.damper.force [N]"])
    arr = res.to_numpy()
    assert arr.dtype.names[0] == "time"
    assert arr.dtype["damper_left.damper.force"].metadata == {"unit": "N"}
    assert np.array_equal(arr["time"], res.time)
    # a mapping of columns, as a DataFrame: iterating gives the names, len the rows
    assert list(res) == res.names == res.keys() and len(res) == 201
    assert all(np.array_equal(res[n], res.values[:, i]) for i, n in enumerate(res))
    with pytest.raises(TypeError, match=r"rows: results.values\[i\]"):
        res[0]


def test_progress_and_the_gil_released_during_a_run(passive_file):
    sys = railfmu.System.load(passive_file)
    seen = []
    sys.run(progress=lambda k, n: seen.append((k, n)))
    assert seen[-1] == (1000, 1000)
    assert all(a[0] < b[0] for a, b in zip(seen, seen[1:]))
    assert len(seen) >= 50
    # The GIL is released while the FMUs run: this thread's Python loop goes on between the
    # progress calls of a run on another thread (which would all see the same count if the
    # run held the GIL). The run is long (30 s simulated, some 60 ms of wall time) and the
    # interpreter's switch interval short, so the loop gets the GIL many times during the run
    # however fast the FMUs are.
    ticks = [0]
    at = []
    done = threading.Event()

    def run():
        try:
            sys.run(stop_time=30.0, progress=lambda k, n: at.append(ticks[0]))
        finally:
            done.set()

    interval = getswitchinterval()
    setswitchinterval(1e-4)
    try:
        t = threading.Thread(target=run)
        t.start()
        while not done.is_set():
            ticks[0] += 1
        t.join()
    finally:
        setswitchinterval(interval)
    assert len(at) >= 100 and at[-1] > at[0]


def test_bad_input_raises_with_the_masters_message_and_changes_nothing(passive_file, dist, tmp_path):
    sys = railfmu.System.load(passive_file)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"unknown variable 'vehicle.sped'.*did you mean 'vehicle.speed'"):
        sys.set_parameter("bogie.vehicle.sped", 70.0)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"unknown instance 'bogey'"):
        sys.run({"bogey.vehicle.speed": 70.0})
    with pytest.raises(railfmu.SystemDescriptionError, match=r"1.5 is not a 32-bit integer"):
        sys.set_parameter("bogie.track.seed", 1.5)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"cannot take the value \"fast\""):
        sys.run({"bogie.vehicle.speed": "fast"})
    with pytest.raises(railfmu.SystemDescriptionError, match=r"not a finite number"):
        sys.run({"bogie.vehicle.speed": float("nan")})
    with pytest.raises(TypeError, match=r"not list"):
        sys.run({"bogie.vehicle.speed": [1.0]})
    # outside the range the model description declares: refused here, not in every run
    with pytest.raises(railfmu.SystemDescriptionError, match=r"250 m/s is above its maximum 200 m/s \(declared by model 'Bogie2Dof' for 'vehicle.speed'\)"):
        sys.set_parameter("bogie.vehicle.speed", 250.0)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"with the run's arguments: bogie.track.seed: -1 is below its minimum 0"):
        sys.run({"bogie.track.seed": -1})
    # a stop time that does not fit the step: said of the argument, not at the file's line
    with pytest.raises(railfmu.SystemDescriptionError, match=r"with the run's arguments: step: stop_time - start_time = 0.0015 s") as e:
        sys.run(stop_time=0.0015)
    assert "line" not in str(e.value)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"stop_time"):
        sys.stop_time = -1.0
    assert sys.parameters == {} and sys.stop_time == 1.0
    # a value only the FMU refuses: the exception carries the FMU's own reason (its log is
    # not seen in a notebook or on a Dask worker)
    with pytest.raises(railfmu.SimulationError, match=r"fmi2Error: .*'vehicle.speed': must be > 0, got 0"):
        sys.run({"bogie.vehicle.speed": 0.0}, stop_time=0.01)
    assert len(sys.run(stop_time=0.01)) == 11  # still usable
    # that failure came at the start: no history
    with pytest.raises(railfmu.SimulationError) as failed:
        sys.run({"bogie.vehicle.speed": 0.0}, stop_time=0.01)
    assert failed.value.history is None
    assert railfmu.SimulationError("made by hand").history is None
    # a failure midway (a bogie without secondary suspension derails at 150 m/s): the error
    # carries the history up to it, its summary saying where and why
    derail = {
        "bogie.vehicle.speed": 150.0,
        "bogie.suspension.lateral_stiffness": 0.0,
        "bogie.suspension.longitudinal_stiffness": 0.0,
    }
    with pytest.raises(railfmu.SimulationError, match="derailment") as failed:
        sys.run(derail, stop_time=2.0)
    history = failed.value.history
    assert "history" not in str(failed.value) and str(failed.value).count("derailment") >= 1
    t = history.time
    assert 0.1 < t[-1] < 2.0 and len(t) == round(t[-1] / 1e-3) + 1
    assert history.summary["failed"]["time_s"] == t[-1]
    assert "derailment" in history.summary["failed"]["error"]
    # files: missing, malformed JSON (line and column), broken FMU
    with pytest.raises(railfmu.SystemDescriptionError, match=r"cannot read"):
        railfmu.System.load(tmp_path / "nope.json")
    bad = tmp_path / "bad.json"
    bad.write_text('{"instances": [\n  {"name": "a", "fmu": 3}\n]}')
    with pytest.raises(railfmu.SystemDescriptionError, match=r"line 2"):
        railfmu.System.load(bad)
    broken = tmp_path / "Broken.fmu"
    broken.write_bytes(b"PK\x03\x04 this is not a zip archive")
    d = passive(dist, 1.0)
    d["instances"][1]["fmu"] = str(broken)
    with pytest.raises(railfmu.FmuError, match=r"Broken.fmu"):
        railfmu.System.from_dict(d)
    # an FMU whose zip lacks its binary
    nobin = tmp_path / "NoBinary.fmu"
    with zipfile.ZipFile(dist / "PassiveYawDamper.fmu") as src, zipfile.ZipFile(nobin, "w") as dst:
        for item in src.infolist():
            if not item.filename.startswith("binaries/"):
                dst.writestr(item, src.read(item))
    d["instances"][1]["fmu"] = str(nobin)
    with pytest.raises(railfmu.FmuError) as e:
        railfmu.System.from_dict(d)
    assert "NoBinary.fmu" in str(e.value)
    assert issubclass(railfmu.FmuError, railfmu.Error)


def test_variables_and_description(passive_file):
    sys = railfmu.System.load(passive_file)
    assert sys.instances == ["bogie", "damper_left", "damper_right"]
    speed = [v for v in sys.variables("bogie") if v["name"] == "vehicle.speed"]
    assert len(speed) == 1 and speed[0]["unit"] == "m/s"
    assert sys.columns[0] == "time [s]"
    assert Path(sys.description["instances"][0]["fmu"]).is_absolute()
    with pytest.raises(KeyError, match="bogey"):
        sys.variables("bogey")


def test_ctrl_c_stops_a_run_and_raises_keyboard_interrupt(passive_file):
    script = f"""
import sys, railfmu
s = railfmu.System.load({str(passive_file)!r})
def started(k, n):
    if k == n // 100:
        print("started", flush=True)
try:
    s.run(stop_time=3000.0, progress=started)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(3)
"""
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 3, err
    assert out.strip() == "interrupted"


def test_an_ssp_loads_and_runs_as_the_command_line_runs_it(passive_file, master_cmd, tmp_path):
    # the passive system exported by the master, then run from the .ssp by both
    ssp = tmp_path / "passive.ssp"
    r = run_master(master_cmd, "export-ssp", passive_file, ssp)
    assert r.returncode == 0, r.stderr
    cli_csv = tmp_path / "cli.csv"
    r = run_master(master_cmd, "run", ssp, "-o", cli_csv)
    assert r.returncode == 0, r.stderr
    res = railfmu.System.load(ssp).run()
    cli = railfmu.read_results(cli_csv)
    assert cli.header == res.header
    assert np.array_equal(bits(cli.values), bits(res.values))
    # both record each FMU by the archive and member it comes from (not its unpacked copy)
    fmus = [i["fmu"] for i in res.metadata["system"]["instances"]]
    assert fmus == [i["fmu"] for i in cli.metadata["system"]["instances"]]
    assert fmus[0] == f"{ssp.resolve()}:resources/Bogie2Dof.fmu", fmus
    assert np.max(np.abs(res["bogie.wheelset_front.lateral_displacement_relative"])) > 1e-6
    # the variables to record, as `master run --record` names them: the same columns and values
    names = ["bogie.wheelset_front.lateral_displacement_relative", "damper_left.damper.force"]
    few = railfmu.System.load(ssp, record=names).run()
    r = run_master(master_cmd, "run", ssp, "--record", *names, "-o", tmp_path / "few.csv")
    assert r.returncode == 0, r.stderr
    cli_few = railfmu.read_results(tmp_path / "few.csv")
    assert few.header == cli_few.header and len(few.header) == 3
    assert np.array_equal(bits(few.values), bits(cli_few.values))
    assert np.array_equal(bits(few[names[1]]), bits(res[names[1]]))
    with pytest.raises(railfmu.SystemDescriptionError, match="unknown variable 'bogie.nope'"):
        railfmu.System.load(ssp, record=["bogie.nope"])
    with pytest.raises(TypeError, match="record must be a list"):
        railfmu.System.load(ssp, record="bogie.x")
    # any iterable of names, a generator too
    assert railfmu.System.load(ssp, record=(n for n in names)).columns == few.header
    # a broken SSP raises with the master's message naming the file
    broken = tmp_path / "broken.ssp"
    broken.write_bytes(b"not a zip")
    with pytest.raises(railfmu.Error, match="broken.ssp"):
        railfmu.System.load(broken)


def test_strings_and_enumerations_are_the_columns_the_command_line_writes(dist, master_cmd, tmp_path):
    # a String (the contact table) and an Enumeration (the force law) recorded beside numbers
    desc = {
        "instances": [
            {
                "name": "bogie",
                "fmu": str(dist / "Bogie2Dof.fmu"),
                "parameters": {"contact.model": "nonlinear", "contact.table": "AA"},
            }
        ],
        "stop_time": 0.01,
        "step": 0.001,
        "record": [
            "bogie.wheelset_front.lateral_displacement",
            "bogie.contact.model",
            "bogie.contact.table",
            "bogie.track.seed",
        ],
    }
    path = tmp_path / "typed.json"
    path.write_text(json.dumps(desc))
    sys = railfmu.System.load(path)
    res = sys.run()
    header = [
        "time [s]",
        "bogie.wheelset_front.lateral_displacement [m]",
        "bogie.contact.model",
        "bogie.contact.model (item)",
        "bogie.contact.table",
        "bogie.track.seed",
    ]
    assert res.header == header and sys.columns == header
    assert list(res["bogie.contact.table"]) == ["AA"] * 11
    assert list(res["bogie.contact.model (item)"]) == ["nonlinear"] * 11
    assert np.all(res["bogie.contact.model"] == 1.0)
    df = res.to_pandas()
    assert list(df.columns) == res.names[1:]
    assert list(df["bogie.contact.table"]) == ["AA"] * 11
    assert list(df["bogie.contact.model (item)"]) == ["nonlinear"] * 11
    assert res.to_numpy()["bogie.contact.table"][0] == "AA"
    # the command line's CSV and Parquet read back to the same columns, values and texts
    for name in ("cli.csv", "cli.parquet"):
        r = run_master(master_cmd, "run", path, "-o", tmp_path / name)
        assert r.returncode == 0, r.stderr
        cli = railfmu.read_results(tmp_path / name)
        assert cli.header == res.header, name
        assert np.array_equal(bits(cli.values), bits(res.values)), name
        assert cli.texts.keys() == res.texts.keys(), name
        for k in res.texts:
            assert list(cli.texts[k]) == list(res.texts[k]), (name, k)
    # written from Python, the CSV is the command line's byte for byte
    res.to_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    # a run set's results read back with their texts too, in either format
    for fmt in ("csv", "parquet"):
        runs = railfmu.RunSet.from_dict({"system": desc}).run(tmp_path / fmt, format=fmt, threads=1)
        assert list(runs["base"]["bogie.contact.table"]) == ["AA"] * 11, fmt
        assert runs["base"].header == header, fmt


def test_an_fmu_given_as_a_description_is_refused_saying_how_to_describe_a_system(dist):
    fmu = dist / "Bogie2Dof.fmu"
    with pytest.raises(railfmu.SystemDescriptionError, match=r"is an FMU, not a system description") as e:
        railfmu.System.load(fmu)
    message = str(e.value)
    assert "UTF-8" not in message and str(fmu) in message
    # the system the message suggests loads and runs
    suggested = json.loads(message.split("System.from_dict(", 1)[1].split("), or", 1)[0])
    assert suggested["instances"][0]["fmu"] == str(fmu)
    assert len(railfmu.System.from_dict(suggested).run(stop_time=0.01)) == 11
    with pytest.raises(railfmu.SystemDescriptionError, match=r"is an FMU, not a run-set description.*RunSet.from_dict"):
        railfmu.RunSet.load(fmu)


def test_to_csv_writes_the_metadata_file_the_command_line_writes(dist, master_cmd, tmp_path):
    cli_csv, base = cli_run_and_base(dist, master_cmd, tmp_path)
    res = railfmu.System.load(base).run({"bogie.vehicle.speed": 55.0, "bogie.track.seed": 7}, stop_time=0.5)
    py_csv = tmp_path / "py.csv"
    res.to_csv(py_csv)
    assert py_csv.read_bytes() == cli_csv.read_bytes()
    cli_meta = json.loads((tmp_path / "cli.meta.json").read_text())
    py_meta = json.loads((tmp_path / "py.meta.json").read_text())
    # the same metadata but for the wall time of the run: columns, sampling, the system as run
    for m in (cli_meta, py_meta):
        m["summary"].pop("wall_time_s")
        m["summary"].pop("realtime_ratio")
    assert py_meta == cli_meta
    assert py_meta["system"]["stop_time"] == 0.5
    assert py_meta["system"]["instances"][0]["parameters"]["vehicle.speed"] == 55.0
    assert py_meta["sampling"]["rate_hz"] == 1000.0
    # read back, the results keep their metadata, and write it again
    back = railfmu.read_results(py_csv)
    assert back.metadata == res.metadata
    back.to_csv(tmp_path / "again.csv")
    assert (tmp_path / "again.csv").read_bytes() == py_csv.read_bytes()
    assert (tmp_path / "again.meta.json").read_bytes() == (tmp_path / "py.meta.json").read_bytes()


def test_results_files_that_cannot_be_written_or_read_fail_whole(dist, master_cmd, tmp_path):
    cli_csv, base = cli_run_and_base(dist, master_cmd, tmp_path)
    res = railfmu.read_results(cli_csv)
    # a folder where the metadata goes: refused before the CSV is written
    (tmp_path / "new.meta.json").mkdir()
    with pytest.raises(railfmu.OutputError, match="new.meta.json': it exists and is not a regular file"):
        res.to_csv(tmp_path / "new.csv")
    assert not (tmp_path / "new.csv").exists()
    # an existing pair is replaced as a pair
    res.to_csv(tmp_path / "z.csv")
    short = railfmu.Results(res.header, res.values[:10])
    short.to_csv(tmp_path / "z.csv")
    assert len(railfmu.read_results(tmp_path / "z.csv")) == 10
    # an empty table is refused as one, not as a panic of the writer
    with pytest.raises(railfmu.OutputError, match="needs a time column"):
        railfmu.Results([], np.zeros((0, 0))).to_csv(tmp_path / "empty.csv")
    assert not (tmp_path / "empty.csv").exists()
    # CSV text under a Parquet name would not read back
    with pytest.raises(railfmu.OutputError, match="names a Parquet file"):
        res.to_csv(tmp_path / "r.parquet")
    with pytest.raises(railfmu.OutputError, match="names a Parquet file"):
        res.to_csv(tmp_path / "r.PQ")
    assert not (tmp_path / "r.PQ").exists()
    assert not (tmp_path / "r.parquet").exists()
    # a FIFO is refused without reading it (a read would block: nobody writes to it)
    fifo = tmp_path / "fifo.csv"
    os.mkfifo(fifo)
    with pytest.raises(railfmu.OutputError, match="not a regular file"):
        railfmu.Results.read_csv(fifo)


def test_an_ssps_step_stop_time_and_algorithm_are_set_as_the_command_line_sets_them(passive_file, master_cmd, tmp_path):
    ssp = tmp_path / "passive.ssp"
    assert run_master(master_cmd, "export-ssp", passive_file, ssp).returncode == 0
    cli_csv = tmp_path / "cli.csv"
    options = ["--step", "0.002", "--stop-time", "0.5", "--algorithm", "gauss-seidel"]
    r = run_master(master_cmd, "run", ssp, "-o", cli_csv, *options)
    assert r.returncode == 0, r.stderr
    sys = railfmu.System.load(ssp, step=0.002, stop_time=0.5, algorithm="gauss-seidel")
    d = sys.description
    assert (d["step"], d["stop_time"], d["algorithm"]) == (0.002, 0.5, "gauss-seidel")
    res = sys.run()
    assert len(res) == 251
    cli = railfmu.read_results(cli_csv)
    assert cli.header == res.header
    assert np.array_equal(bits(cli.values), bits(res.values))
    # the master's export keeps the description's Gauss-Seidel (in its annotation); Jacobi,
    # as other hosts run the archive, gives other results
    assert railfmu.System.load(ssp).description["algorithm"] == "gauss-seidel"
    jacobi = railfmu.System.load(ssp, step=0.002, stop_time=0.5, algorithm="jacobi").run()
    assert jacobi.header == res.header and not np.array_equal(jacobi.values, res.values)
    assert railfmu.System.load(ssp).description["step"] == 0.001
    # an SSD without a stop time or a step: the message names the argument to give it with
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(ssp) as z:
        z.extractall(folder)
    ssd = folder / "SystemStructure.ssd"
    text = ssd.read_text()
    for attribute in ('stopTime="1.0"', 'stepSize="0.001"', 'baseStepSize="0.001"'):
        assert attribute in text
        text = text.replace(attribute, "")
    ssd.write_text(text)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"no stop time.*System.load\(\.\.\., stop_time=") as e:
        railfmu.System.load(ssd)
    assert "--" not in str(e.value)
    with pytest.raises(railfmu.SystemDescriptionError, match=r"no communication step.*System.load\(\.\.\., step=") as e:
        railfmu.System.load(ssd, stop_time=0.5)
    assert "--" not in str(e.value)
    assert len(railfmu.System.load(ssd, stop_time=0.5, step=0.002).run()) == 251
    # a JSON description takes them too, in place of its own; a value that does not fit is
    # named as System.load's, not as the file's
    changed = railfmu.System.load(passive_file, step=0.002, stop_time=0.5, algorithm="jacobi")
    assert (changed.description["step"], changed.description["algorithm"]) == (0.002, "jacobi")
    assert len(changed.run()) == 251
    with pytest.raises(railfmu.SystemDescriptionError, match=r"with System.load's stop_time, step: step: .*not an integer multiple") as e:
        railfmu.System.load(passive_file, step=0.003, stop_time=0.5)
    assert "--" not in str(e.value) and " line " not in str(e.value)
    with pytest.raises(ValueError, match=r"algorithm 'seidel': expected 'jacobi' or 'gauss-seidel'"):
        railfmu.System.load(ssp, algorithm="seidel")


def test_a_runs_results_are_held_about_twice_at_their_peak(dist):
    """A long run's values are copied once from Rust into Python, not three times (the peak
    was 4.2 times the result: the output, its expanded table, a byte vector and the bytes).
    Measured by the peak resident size of a fresh interpreter around one run."""
    script = f"""
import json, resource, sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
from pathlib import Path
import railfmu
from conftest import passive
system = railfmu.System.from_dict(passive(Path({str(dist)!r}), 200.0))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
res = system.run()
growth = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
print(json.dumps({{"growth_kib": growth, "result_kib": res.values.nbytes / 1024}}))
"""
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    m = json.loads(r.stdout)
    assert m["result_kib"] > 10_000  # 200 000 rows: large beside the interpreter's noise
    ratio = m["growth_kib"] / m["result_kib"]
    assert ratio < 3.0, f"peak growth {ratio:.2f} times the result"


def test_arguments_of_the_wrong_type_raise_type_errors_naming_them(passive_file):
    s = railfmu.System.load(passive_file)
    with pytest.raises(TypeError, match="parameters must be a mapping of 'instance.variable' to a value, not list"):
        s.run(["bogie.vehicle.speed", 50.0])
    # True is not 1 s, '2' is not 2 s
    for bad in (True, "2"):
        with pytest.raises(TypeError, match="stop_time must be a number of seconds"):
            s.run(stop_time=bad)
        with pytest.raises(TypeError, match="stop_time must be a number of seconds"):
            s.stop_time = bad
        with pytest.raises(TypeError, match="step must be a number of seconds"):
            railfmu.System.load(passive_file, step=bad)
    # a number is no progress callback (it was taken as True)
    with pytest.raises(TypeError, match="progress must be True, False, None or a callable"):
        s.run(stop_time=0.01, progress=5)
    assert s.stop_time == 1.0
    # a stop time whose results would pass the recorded-values limit: refused when set, as
    # System.load refuses it, not when the run starts
    for attempt in (lambda: setattr(s, "stop_time", 99999.0), lambda: s.run(stop_time=99999.0)):
        with pytest.raises(railfmu.SystemDescriptionError, match="more than the 500000000 allowed"):
            attempt()
    assert s.stop_time == 1.0
    # NumPy numbers are numbers
    s.stop_time = np.float32(0.25)
    assert s.stop_time == 0.25
    assert len(s.run(stop_time=np.int64(1))) == 1001


def test_read_results_names_what_is_missing(tmp_path):
    with pytest.raises(railfmu.OutputError, match="no such file or folder"):
        railfmu.read_results(tmp_path / "missing.csv")
    with pytest.raises(railfmu.OutputError, match="holds neither sweep.json nor results.csv"):
        railfmu.read_results(tmp_path)


def test_errors_cross_process_boundaries_as_themselves(passive_file):
    """A railfmu error pickles (as Dask and process pools send it back) into its own class."""
    import pickle

    s = railfmu.System.load(passive_file)
    with pytest.raises(railfmu.SystemDescriptionError) as raised:
        s.run({"bogie.vehicle.speed": -5.0}, stop_time=0.01)
    again = pickle.loads(pickle.dumps(raised.value))
    assert type(again) is railfmu.SystemDescriptionError and isinstance(again, railfmu.Error)
    assert str(again) == str(raised.value)
    for cls in (railfmu.Error, railfmu.FmuError, railfmu.SimulationError, railfmu.OutputError, railfmu.AssessmentError):
        assert cls.__module__ == "railfmu"
        assert type(pickle.loads(pickle.dumps(cls("x")))) is cls
    # copies share the loaded FMUs but not their settings
    import copy

    for twin in (copy.copy(s), copy.deepcopy(s)):
        twin.stop_time = 0.5
        twin.set_parameter("bogie.vehicle.speed", 60.0)
        assert s.stop_time == 1.0 and s.parameters == {}
        assert len(twin.run()) == 501
    # a System does not pickle, and says what to send instead; its description loads again
    with pytest.raises(TypeError, match="send its description"):
        pickle.dumps(s)
    again = railfmu.System.from_dict(pickle.loads(pickle.dumps(s.description)))
    assert np.array_equal(bits(again.run(stop_time=0.01).values), bits(s.run(stop_time=0.01).values))


def test_the_fmus_messages_go_to_pythons_logging(passive_file, capfd, caplog):
    # a damper that may take one internal step per communication step discards the first
    sys = railfmu.System.load(passive_file)
    with caplog.at_level(logging.WARNING, logger="railfmu"):
        with pytest.raises(railfmu.SimulationError):
            sys.run({"damper_left.solver.max_internal_steps": 1}, stop_time=0.1)
    found = [r for r in caplog.records if r.name == "railfmu" and "FMU instance 'damper_left'" in r.getMessage()]
    assert found and found[0].levelno == logging.WARNING, caplog.records
    assert "max_internal_steps" in found[0].getMessage()
    # not printed to the process's stderr besides (a notebook's user does not see it there)
    assert "FMU instance" not in capfd.readouterr().err
    # above the logger's level, nothing is kept
    caplog.clear()
    with caplog.at_level(logging.ERROR, logger="railfmu"):
        with pytest.raises(railfmu.SimulationError):
            sys.run({"damper_left.solver.max_internal_steps": 1}, stop_time=0.1)
    assert not [r for r in caplog.records if r.name == "railfmu"], caplog.records
