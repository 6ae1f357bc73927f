"""Results of a run (a table with units) and of a run set (a folder of runs)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Dict, Iterator, List, Mapping, Optional, Union

import numpy as np

from . import _railfmu

PathLike = Union[str, "os.PathLike[str]"]


def split_label(label: str) -> "tuple[str, Optional[str]]":
    """Splits a column label ``"name [unit]"`` into name and unit (None when it has none)."""
    if label.endswith("]") and " [" in label:
        name, unit = label[:-1].rsplit(" [", 1)
        if name:
            return name, unit
    return label, None


class Results:
    """The recorded variables of one run: time plus one column per recorded variable.

    ``values`` holds the numbers exactly as the master computed them (the same bits as the
    ``results.csv`` that ``master run`` writes). Columns are named ``instance.variable``; units
    are in ``units`` and travel with :meth:`to_pandas` (``DataFrame.attrs["units"]``) and
    :meth:`to_numpy` (each field's dtype metadata ``{"unit": ...}``).
    """

    def __init__(
        self,
        header: List[str],
        values: np.ndarray,
        summary: Optional[Dict[str, Any]] = None,
        full_rate: bool = False,
    ):
        if values.ndim != 2 or values.shape[1] != len(header):
            raise ValueError(f"{values.shape} values do not match {len(header)} columns")
        self.header: List[str] = list(header)
        """The CSV header: ``time [s]``, then ``instance.variable [unit]``."""
        self.values: np.ndarray = values
        """The table, one row per communication point, float64."""
        self.summary: Dict[str, Any] = dict(summary or {})
        """Run statistics: steps, rejected_steps, simulated_time_s, wall_time_s, realtime_ratio."""
        self.full_rate: bool = full_rate
        """Every communication point of the run is here (a run's own results): the signals
        carry their full band. False when unknown (a table read back: its file's metadata
        say, see :func:`assess_stability`)."""
        split = [split_label(h) for h in self.header]
        self.names: List[str] = [n for n, _ in split]
        """Column names without units; the first is ``time``."""
        self.units: Dict[str, Optional[str]] = {n: u for n, u in split}
        """Unit of each column (None where the FMU declares none)."""

    @classmethod
    def _from_bytes(
        cls, header: List[str], data: bytes, summary: Optional[Dict[str, Any]] = None, full_rate: bool = False
    ) -> "Results":
        values = np.frombuffer(data, dtype=np.float64).reshape(-1, max(len(header), 1))
        return cls(header, values, summary, full_rate)

    @classmethod
    def read_csv(cls, path: PathLike) -> "Results":
        """Reads a ``results.csv`` written by the master, every value exactly as written."""
        header, data = _railfmu.read_csv(os.fspath(path))
        return cls._from_bytes(header, data)

    @classmethod
    def read_parquet(cls, path: PathLike) -> "Results":
        """Reads a Parquet results file written by the master (needs pyarrow): time and the
        recorded numeric columns (Reals, Integers, Booleans as 0/1, Enumerations as integers),
        every value as written; the run statistics from the file's metadata."""
        import pyarrow.parquet as pq

        try:
            table = pq.read_table(os.fspath(path))
        except (OSError, ValueError) as e:
            raise _railfmu.OutputError(f"cannot read '{path}': {e}") from None
        raw = (table.schema.metadata or {}).get(b"railfmu.results")
        if raw is None:
            raise _railfmu.OutputError(f"'{path}' has no railfmu.results metadata: not written by the master")
        meta = json.loads(raw)
        header = [table.column_names[0]] + [c["label"] for c in meta["columns"] if c.get("ty") != "String"]
        values = np.column_stack([table.column(h).to_numpy().astype(np.float64) for h in header])
        return cls(header, values, meta.get("summary"))

    @property
    def time(self) -> np.ndarray:
        """The communication points [s]."""
        return self.values[:, 0]

    def __len__(self) -> int:
        return self.values.shape[0]

    def __contains__(self, name: object) -> bool:
        return name in self.units or name in self.header

    def __getitem__(self, name: str) -> np.ndarray:
        """A column by name (``bogie.x``) or by its header label (``bogie.x [m]``)."""
        for i, (n, h) in enumerate(zip(self.names, self.header)):
            if name == n or name == h:
                return self.values[:, i]
        raise KeyError(f"no column '{name}'; columns: {', '.join(self.names)}")

    def __repr__(self) -> str:
        return f"<Results {len(self)} rows x {len(self.names)} columns: {', '.join(self.names[:4])}{', ...' if len(self.names) > 4 else ''}>"

    def to_numpy(self) -> np.ndarray:
        """A structured array with one float64 field per column (``time`` first); each field's
        dtype carries ``metadata={"unit": unit}``."""
        dtype = np.dtype(
            [(n, np.dtype(np.float64, metadata={"unit": u})) for n, u in zip(self.names, self.units.values())]
        )
        out = np.empty(len(self), dtype=dtype)
        for i, n in enumerate(self.names):
            out[n] = self.values[:, i]
        return out

    def to_pandas(self):
        """A ``pandas.DataFrame`` indexed by ``time`` [s], one column per recorded variable.
        ``df.attrs["units"]`` maps each column (and ``time``) to its unit, ``df.attrs["summary"]``
        holds the run statistics."""
        import pandas as pd

        df = pd.DataFrame(self.values[:, 1:], columns=self.names[1:], index=pd.Index(self.values[:, 0], name=self.names[0]))
        df.attrs["units"] = dict(self.units)
        df.attrs["summary"] = dict(self.summary)
        return df

    def to_csv(self, path: PathLike) -> None:
        """Writes the table as ``master run`` does (atomically, shortest round-trip numbers)."""
        _railfmu.write_csv(os.fspath(path), self.header, np.ascontiguousarray(self.values, dtype=np.float64).tobytes())


class RunSetResults(Mapping[str, Results]):
    """A run-set folder: ``sweep.json`` plus one folder per run (``system.json``,
    ``results.csv``, ``summary.json``; Parquet results in ``results/<run>.parquet``). A mapping
    from run name to its :class:`Results` (read when first asked for; failed runs have none)."""

    def __init__(self, folder: PathLike, reports: Optional[List[Dict[str, Any]]] = None):
        self.folder: Path = Path(folder)
        if reports is None:
            path = self.folder / "sweep.json"
            try:
                reports = json.loads(path.read_text())
            except OSError as e:
                raise _railfmu.OutputError(f"cannot read '{path}': {e}") from None
            except ValueError as e:
                raise _railfmu.OutputError(f"'{path}' is not a run-set summary: {e}") from None
        self.reports: List[Dict[str, Any]] = list(reports)
        """Each run's report in job order: name, parameters, ok, error, summary, results."""
        self._cache: Dict[str, Results] = {}

    @property
    def ok(self) -> bool:
        """Whether every run succeeded."""
        return all(r["ok"] for r in self.reports)

    @property
    def failed(self) -> Dict[str, str]:
        """Name -> error message of each failed run."""
        return {r["name"]: r.get("error") or "" for r in self.reports if not r["ok"]}

    def __len__(self) -> int:
        return sum(1 for r in self.reports if r["ok"])

    def __iter__(self) -> Iterator[str]:
        return (r["name"] for r in self.reports if r["ok"])

    def __getitem__(self, name: str) -> Results:
        if name in self._cache:
            return self._cache[name]
        for r in self.reports:
            if r["name"] == name:
                if not r["ok"]:
                    raise KeyError(f"run '{name}' failed: {r.get('error')}")
                parquet = self.folder / "results" / f"{name}.parquet"
                if parquet.is_file():
                    res = Results.read_parquet(parquet)
                else:
                    res = Results.read_csv(self.folder / name / "results.csv")
                res.summary = dict(r.get("summary") or {})
                self._cache[name] = res
                return res
        raise KeyError(f"no run '{name}' in {self.folder}")

    def __repr__(self) -> str:
        return f"<RunSetResults {self.folder}: {len(self)} of {len(self.reports)} runs ok>"

    def summary_frame(self):
        """One row per run: its parameters, ok, error and run statistics (pandas)."""
        import pandas as pd

        rows = []
        for r in self.reports:
            row: Dict[str, Any] = {"run": r["name"], **r.get("parameters", {}), "ok": r["ok"], "error": r.get("error")}
            row.update(r.get("summary") or {})
            rows.append(row)
        return pd.DataFrame(rows).set_index("run")

    def to_pandas(self):
        """All successful runs in one DataFrame indexed by (run, time); units in
        ``attrs["units"]``."""
        import pandas as pd

        frames = {name: self[name].to_pandas() for name in self}
        if not frames:
            return pd.DataFrame()
        df = pd.concat(frames, names=["run"])
        units: Dict[str, Optional[str]] = {}
        for f in frames.values():
            units.update(f.attrs.get("units", {}))
        df.attrs = {"units": units}
        return df


def read_results(path: PathLike) -> Union[Results, RunSetResults]:
    """Reads results back: a run-set folder (with ``sweep.json``) gives a
    :class:`RunSetResults`; a run folder (with ``results.csv``) or a CSV file gives a
    :class:`Results`, with the run's statistics when its ``summary.json`` is beside it."""
    p = Path(path)
    if p.is_dir() and (p / "sweep.json").is_file():
        return RunSetResults(p)
    if p.suffix == ".parquet":
        return Results.read_parquet(p)
    csv = p / "results.csv" if p.is_dir() else p
    if not csv.is_file():
        raise _railfmu.OutputError(f"'{p}' holds neither sweep.json nor results.csv")
    res = Results.read_csv(csv)
    summary = csv.parent / "summary.json"
    if summary.is_file():
        try:
            s = json.loads(summary.read_text())
            res.summary = dict(s.get("summary") or {}) if "ok" in s else dict(s)
        except (OSError, ValueError):
            pass
    return res
