"""EN 14363 assessment from Python: the same numbers as `master assess`, on a run's results in
memory and on its file; bad input raises AssessmentError with the command's message."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import railfmu
from conftest import passive, run_master

SIGNALS = ["bogie.wheelset_front.lateral_acceleration", "bogie.wheelset_rear.lateral_acceleration"]


@pytest.fixture(scope="module")
def hunting(dist: Path) -> railfmu.Results:
    """The passive bogie at 320 km/h (above its critical speed) for 12 s."""
    sys = railfmu.System.from_dict(passive(dist, 12.0), label="passive-320")
    return sys.run({"bogie.vehicle.speed": 320.0 / 3.6})


def test_a_runs_results_are_assessed_as_the_command_line_assesses_their_file(hunting, master_cmd, tmp_path):
    a = railfmu.assess_stability(hunting, SIGNALS, 320.0, skip_s=5.0)
    assert a.quantity == "acceleration" and a.unit == "m/s2"
    assert a.limit == pytest.approx(5.39, abs=1e-9)
    assert set(a.signals) == set(SIGNALS)
    assert a.max_rms == max(s.max_rms for s in a.signals.values())
    assert a.stable == (a.max_rms <= a.limit)
    assert a.notes == [], "a run's own results carry their full band"
    for s in a.signals.values():
        assert 2.0 < s.dominant_frequency_hz < 8.0
        assert len(s.window_centre_m) == len(s.rms) > 10
        assert np.all(np.diff(s.window_centre_m) == pytest.approx(10.0))
    # the command line on the same values written to a file
    path = tmp_path / "hunting.csv"
    hunting.to_csv(path)
    out = tmp_path / "assess"
    args = ["assess", path, "--speed", "320", "--skip", "5", "--out", out]
    for s in SIGNALS:
        args += ["--signal", s]
    r = run_master(master_cmd, *args)
    assert r.returncode == 0, r.stderr
    with open(out / "assess_summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(SIGNALS)
    for row in rows:
        s = a.signals[row["signal"]]
        assert s.max_rms == pytest.approx(float(row["max rms [m/s2]"]), rel=1e-12)
        assert s.dominant_frequency_hz == pytest.approx(float(row["dominant frequency [Hz]"]), rel=1e-12)
        assert (row["stable"] == "true") == s.stable
    # and from Python on the file: the same numbers; its metadata file records how it was
    # sampled, and without it a note says the band could not be checked
    f = railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0)
    assert f.max_rms == pytest.approx(a.max_rms, rel=1e-12)
    assert f.notes == []
    path.with_suffix(".meta.json").unlink()
    f = railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0)
    assert f.max_rms == pytest.approx(a.max_rms, rel=1e-12)
    assert len(f.notes) == 1
    # every 20th row, no anti-aliasing filter: a table of unknown sampling, noted as such in
    # memory and in the file it is written to (not recorded as a full band it does not have)
    every20 = railfmu.Results(hunting.header, hunting.values[::20])
    assert len(railfmu.assess_stability(every20, SIGNALS, 320.0, skip_s=5.0).notes) == 1
    every20.to_csv(tmp_path / "every20.csv")
    assert json.loads((tmp_path / "every20.meta.json").read_text())["sampling"] is None
    f = railfmu.assess_stability(tmp_path / "every20.csv", SIGNALS, 320.0, skip_s=5.0)
    assert len(f.notes) == 1 and "its metadata has no sampling" in f.notes[0], f.notes
    df = a.to_pandas()
    assert list(df.columns) == ["signal", "window_centre_m", "rms"]
    assert df.attrs["limit"] == a.limit and len(df) == sum(len(s.rms) for s in a.signals.values())


def test_the_hunting_bogie_exceeds_the_limit_and_the_slow_one_does_not(hunting, dist):
    assert not railfmu.assess_stability(hunting, SIGNALS, 320.0, skip_s=5.0).stable
    sys = railfmu.System.from_dict(passive(dist, 12.0), label="passive-220")
    slow = sys.run({"bogie.vehicle.speed": 220.0 / 3.6})
    assert railfmu.assess_stability(slow, SIGNALS, 220.0, skip_s=5.0).stable


def test_what_cannot_be_assessed_raises_with_the_reason(hunting, tmp_path):
    with pytest.raises(railfmu.AssessmentError, match="no_such_signal"):
        railfmu.assess_stability(hunting, "no_such_signal", 320.0)
    with pytest.raises(railfmu.AssessmentError, match="window"):
        railfmu.assess_stability(hunting, SIGNALS, 320.0, skip_s=11.5)
    with pytest.raises(railfmu.AssessmentError, match="speed"):
        railfmu.assess_stability(hunting, SIGNALS, -1.0)
    with pytest.raises(railfmu.AssessmentError, match="quantity 'jerk'"):
        railfmu.assess_stability(hunting, SIGNALS, 320.0, quantity="jerk")
    with pytest.raises(railfmu.AssessmentError, match="speed_kmh = nan: not a finite number"):
        railfmu.assess_stability(hunting, SIGNALS, float("nan"))
    # a text is no speed, even one that reads as a number
    with pytest.raises(TypeError, match="speed_kmh must be a number, got '320'"):
        railfmu.assess_stability(hunting, SIGNALS, "320")
    # a text is no switch, a number no list of names, a DataFrame no source
    with pytest.raises(TypeError, match="accept_narrow_band must be True or False, got 'no'"):
        railfmu.assess_stability(hunting, SIGNALS, 320.0, accept_narrow_band="no")
    with pytest.raises(TypeError, match="signals must be a column name or a list of column names"):
        railfmu.assess_stability(hunting, 5, 320.0)
    # names as NumPy or pandas hold them
    by_array = railfmu.assess_stability(hunting, np.array(SIGNALS), 320.0, skip_s=5.0)
    assert by_array.max_rms == railfmu.assess_stability(hunting, SIGNALS, 320.0, skip_s=5.0).max_rms
    with pytest.raises(TypeError, match="got DataFrame \\(a DataFrame: assess the Results"):
        railfmu.assess_stability(hunting.to_pandas(), SIGNALS, 320.0)
    # a dominant frequency below 2.1 Hz: assessed in a clamped band, with a note
    t = np.arange(0.0, 12.0, 0.001)
    slow = railfmu.Results(["time [s]", "g [m/s2]"], np.column_stack([t, np.sin(2 * np.pi * 1.0 * t)]), full_rate=True)
    a = railfmu.assess_stability(slow, "g", 100.0, skip_s=1.0)
    assert a.signals["g"].band_hz[0] == pytest.approx(0.1)
    assert any("clamped to 0.1 Hz" in n for n in a.notes), a.notes
    with pytest.raises(railfmu.OutputError, match="missing.csv"):
        railfmu.assess_stability(tmp_path / "missing.csv", SIGNALS, 320.0)
    assert issubclass(railfmu.AssessmentError, railfmu.Error)
    # a NaN inside the time column (it passes every comparison of the steps)
    t = np.arange(0.0, 20.0, 0.001)
    t[50] = np.nan
    bad = railfmu.Results(["time [s]", "g [m/s2]"], np.column_stack([t, 1000.0 * np.sin(2 * np.pi * 5 * t)]))
    with pytest.raises(railfmu.AssessmentError, match="the time column \\(first column\\) holds NaN at sample 51"):
        railfmu.assess_stability(bad, "g", 200.0)


def test_messages_name_the_python_arguments_not_the_command_options(hunting, tmp_path):
    cases = [
        ({"signals": []}, "signals: none given"),
        ({"speed_kmh": -1.0}, "speed_kmh = -1: must be a speed > 0 km/h"),
        ({"skip_s": -1.0}, "skip_s = -1: must be a time >= 0 s"),
        ({"f0_hz": -2.0}, "f0_hz = -2: must be a frequency > 0 Hz"),
        ({"bogie_mass_t": 80.0}, r"bogie_mass_t = 80: must be in \(0, 60\) t"),
        ({"quantity": "guiding_force"}, "wheel_load_kn: needed for guiding forces"),
        ({"quantity": "guiding-force", "wheel_load_kn": -5.0},
         "wheel_load_kn = -5: must be a static wheel load within 1 .. 300 kN"),
        ({"quantity": "guiding_force", "wheel_load_kn": 1e300},
         "wheel_load_kn = 1e300: must be a static wheel load within 1 .. 300 kN"),
        # huge values: refused in short form (1e308 made windows without end until memory ran out)
        ({"speed_kmh": 1e308}, "speed_kmh = 1e308: must be a rail vehicle's speed in km/h, at most 1000 km/h"),
        ({"skip_s": 1e308}, "at 320 km/h minus 1e308 s skipped covers 0 m, less than one 100 m window"),
    ]
    for change, message in cases:
        args = {"signals": SIGNALS, "speed_kmh": 320.0, **change}
        with pytest.raises(railfmu.AssessmentError, match=message) as e:
            railfmu.assess_stability(hunting, **args)
        assert "--" not in str(e.value), change
    # a file whose metadata records too narrow a band: refused, naming the argument to pass
    path = tmp_path / "narrow.csv"
    hunting.to_csv(path)
    meta = {
        "version": 1,
        "sampling": {"rate_hz": 1000.0, "passband_hz": 3.0, "decimation": None},
        "columns": [],
        "summary": hunting.summary,
    }
    path.with_suffix(".meta.json").write_text(json.dumps(meta))
    with pytest.raises(railfmu.AssessmentError, match=r"accept_narrow_band=True") as e:
        railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0)
    assert "--" not in str(e.value)
    a = railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0, accept_narrow_band=True)
    assert len(a.notes) == 1 and "accept_narrow_band=True" in a.notes[0] and "--" not in a.notes[0]


def test_a_file_with_text_columns_is_assessed_on_its_numeric_signals(dist, hunting, tmp_path):
    # the passive run again, recording an Enumeration and a String beside the accelerations
    desc = passive(dist, 12.0)
    desc["record"] = list(desc["record"]) + ["bogie.contact.model", "bogie.contact.table"]
    res = railfmu.System.from_dict(desc).run({"bogie.vehicle.speed": 320.0 / 3.6})
    path = tmp_path / "typed.csv"
    res.to_csv(path)
    assert "bogie.contact.model (item)" in path.read_text().splitlines()[0]
    a = railfmu.assess_stability(hunting, SIGNALS, 320.0, skip_s=5.0)
    f = railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0)
    assert f.max_rms == pytest.approx(a.max_rms, rel=1e-12)
    with pytest.raises(railfmu.AssessmentError, match=r"column 'bogie.contact.table' is not a number.*is not numeric"):
        railfmu.assess_stability(path, ["bogie.contact.table"], 320.0, skip_s=5.0)


def test_results_read_back_are_assessed_with_the_sampling_their_metadata_records(hunting, tmp_path):
    """A table decimated too far for the band is refused as a file and as `Results` read back
    from it alike (in memory, the metadata's sampling was ignored and the aliased rms assessed);
    and the running speed it records is checked against `speed_kmh` as for the file."""
    import copy

    meta = copy.deepcopy(hunting.metadata)
    meta["sampling"] = {
        "rate_hz": 20.0,
        "passband_hz": 4.5,
        "decimation": {"factor": 50, "source_rate_hz": 1000.0, "filter": "butterworth low-pass, forward-backward", "filter_order": 4, "cutoff_hz": 4.0},
    }
    path = tmp_path / "dec.csv"
    railfmu.Results(hunting.header, hunting.values[::50], summary=hunting.summary, metadata=meta).to_csv(path)
    with pytest.raises(railfmu.AssessmentError, match="carry"):
        railfmu.assess_stability(path, SIGNALS, 320.0, skip_s=5.0)
    back = railfmu.read_results(path)
    assert back.metadata["sampling"]["rate_hz"] == 20.0
    with pytest.raises(railfmu.AssessmentError, match="carry"):
        railfmu.assess_stability(back, SIGNALS, 320.0, skip_s=5.0)
    # the full-rate file read back: assessed as the run in memory, its speed checked
    hunting.to_csv(tmp_path / "full.csv")
    full = railfmu.read_results(tmp_path / "full.csv")
    a, b = (railfmu.assess_stability(r, SIGNALS, 320.0, skip_s=5.0) for r in (hunting, full))
    assert a.max_rms == b.max_rms
    with pytest.raises(railfmu.AssessmentError, match="not the running speed its metadata records"):
        railfmu.assess_stability(full, SIGNALS, 320.0 / 3.6, skip_s=5.0)
