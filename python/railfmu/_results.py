"""Results of a run (a table with units) and of a run set (a folder of runs)."""

from __future__ import annotations

import json
import os
import warnings
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
    """The recorded variables of one run: time plus one column per recorded variable, the
    columns of the results file ``master run`` writes.

    ``values`` holds the numbers exactly as the master computed them (the same bits as the
    ``results.csv`` that ``master run`` writes). Columns are named ``instance.variable``; units
    are in ``units`` and travel with :meth:`to_pandas` (``DataFrame.attrs["units"]``) and
    :meth:`to_numpy` (each field's dtype metadata ``{"unit": ...}``). Integers, Booleans (0/1)
    and Enumerations (their integers) are numbers too; a String variable is a column of texts,
    and an Enumeration is followed by the column of its item names (``name (item)``), as in
    the master's files: their texts are in ``texts`` (and in :meth:`to_pandas`,
    :meth:`to_numpy`, ``results[name]``), their entries in ``values`` are NaN.
    """

    def __init__(
        self,
        header: List[str],
        values: np.ndarray,
        summary: Optional[Dict[str, Any]] = None,
        full_rate: bool = False,
        texts: Optional[Mapping[str, Any]] = None,
        metadata: Optional[Dict[str, Any]] = None,
    ):
        values = np.asarray(values, dtype=float)
        if values.ndim != 2 or values.shape[1] != len(header):
            raise ValueError(f"{values.shape} values do not match {len(header)} columns")
        self.header: List[str] = list(header)
        """The CSV header: ``time [s]``, then ``instance.variable [unit]``."""
        self.values: np.ndarray = values
        """The table, one row per communication point, float64 (NaN in a text column)."""
        self.summary: Dict[str, Any] = dict(summary or {})
        """Run statistics: steps, rejected_steps, simulated_time_s, wall_time_s, realtime_ratio."""
        self.full_rate: bool = full_rate
        """Every communication point of the run is here (a run's own results): the signals
        carry their full band. False when unknown (a table read back: its file's metadata
        say, see :func:`assess_stability`)."""
        split = [split_label(h) for h in self.header]
        seen: Dict[str, str] = {}
        for label, (name, _) in zip(self.header, split):
            if name in seen:
                # columns are found by name (units apart): a second one would hide the first
                raise ValueError(f"columns '{seen[name]}' and '{label}' have the same name '{name}'")
            seen[name] = label
        self.names: List[str] = [n for n, _ in split]
        """Column names without units; the first is ``time``."""
        self.units: Dict[str, Optional[str]] = {n: u for n, u in split}
        """Unit of each column (None where the FMU declares none)."""
        self.texts: Dict[str, np.ndarray] = {}
        """The values of each text column (a String variable, an Enumeration's item names) by
        column name, as arrays of str (dtype object)."""
        for name, column in (texts or {}).items():
            if name not in self.units:
                raise ValueError(f"texts of '{name}', which is no column; columns: {', '.join(self.names)}")
            column = np.asarray(column, dtype=object)
            if column.shape != (len(self),):
                raise ValueError(f"{column.shape} texts of '{name}' do not match {len(self)} rows")
            self.texts[name] = column
        self.metadata: Optional[Dict[str, Any]] = metadata
        """What the master's results files carry besides the values (``<name>.meta.json``
        beside a CSV, inside a Parquet file): each column's type, unit and FMU variable, the
        sampling, the summary, ...; None when unknown (a CSV without its metadata file)."""

    @classmethod
    def _from_bytes(
        cls,
        header: List[str],
        data: bytes,
        summary: Optional[Dict[str, Any]] = None,
        full_rate: bool = False,
        texts: Optional[List[Any]] = None,
        metadata: Optional[Dict[str, Any]] = None,
    ) -> "Results":
        """From the native module's parts: ``texts`` as (column index, texts) pairs."""
        values = np.frombuffer(data, dtype=np.float64).reshape(-1, max(len(header), 1))
        named = {split_label(header[c])[0]: t for c, t in (texts or [])}
        return cls(header, values, summary, full_rate, named, metadata)

    @classmethod
    def _read(cls, path: PathLike) -> "Results":
        header, data, texts, meta = _railfmu.read_results(os.fspath(path))
        meta = json.loads(meta) if meta is not None else None
        summary = meta.get("summary") if meta is not None else None
        try:
            return cls._from_bytes(header, data, summary, texts=texts, metadata=meta)
        except ValueError as e:
            # a host's file with two columns of one name (the master never writes one)
            raise _railfmu.OutputError(f"'{os.fspath(path)}': {e}") from None

    @classmethod
    def read_csv(cls, path: PathLike) -> "Results":
        """Reads a ``results.csv`` written by the master, every value exactly as written (the
        texts of Strings and Enumeration items by the metadata file beside it)."""
        return cls._read(path)

    @classmethod
    def read_parquet(cls, path: PathLike) -> "Results":
        """Reads a Parquet results file written by the master: time and the recorded columns
        (Reals, Integers, Booleans as 0/1, Enumerations as integers with their item names,
        Strings as texts), every value as written; the run statistics from the file's
        metadata."""
        return cls._read(path)

    @property
    def time(self) -> np.ndarray:
        """The communication points [s]."""
        return self.values[:, 0]

    def __len__(self) -> int:
        """The number of rows (communication points), as ``len`` of a DataFrame."""
        return self.values.shape[0]

    def __iter__(self) -> Iterator[str]:
        """The column names, ``time`` first, as iterating a DataFrame gives its columns:
        ``for name in results: results[name]``."""
        return iter(self.names)

    def keys(self) -> List[str]:
        """The column names, ``time`` first."""
        return list(self.names)

    def __contains__(self, name: object) -> bool:
        return name in self.units or name in self.header

    def __getitem__(self, name: str) -> np.ndarray:
        """A column by name (``bogie.x``) or by its header label (``bogie.x [m]``): numbers,
        or the texts of a text column. Rows are ``values[i]`` or ``to_pandas().iloc[i]``."""
        if not isinstance(name, str):
            raise TypeError(
                f"a column is taken by its name (one of {', '.join(self.names[:4])}, ...), not by "
                f"{type(name).__name__} {name!r}; rows: results.values[i] or results.to_pandas().iloc[i]"
            )
        for i, (n, h) in enumerate(zip(self.names, self.header)):
            if name == n or name == h:
                return self.texts[n] if n in self.texts else self.values[:, i]
        raise KeyError(f"no column '{name}'; columns: {', '.join(self.names)}")

    def __repr__(self) -> str:
        return f"<Results {len(self)} rows x {len(self.names)} columns: {', '.join(self.names[:4])}{', ...' if len(self.names) > 4 else ''}>"

    def to_numpy(self) -> np.ndarray:
        """A structured array with one field per column (``time`` first): float64, or object
        (str) for a text column; each field's dtype carries ``metadata={"unit": unit}``."""
        dtype = np.dtype(
            [
                (n, np.dtype(object if n in self.texts else np.float64, metadata={"unit": u}))
                for n, u in zip(self.names, self.units.values())
            ]
        )
        out = np.empty(len(self), dtype=dtype)
        for i, n in enumerate(self.names):
            out[n] = self.texts[n] if n in self.texts else self.values[:, i]
        return out

    def to_pandas(self):
        """A ``pandas.DataFrame`` indexed by ``time`` [s], one column per recorded variable
        (texts for a String and an Enumeration's item names). ``df.attrs["units"]`` maps each
        column (and ``time``) to its unit, ``df.attrs["summary"]`` holds the run statistics."""
        import pandas as pd

        # a copy: the values are a read-only view of the results' bytes, which pandas 2 keeps
        # (every in-place edit of the frame failed) and pandas 3 copies on write
        df = pd.DataFrame(
            self.values[:, 1:].copy(),
            columns=self.names[1:],
            index=pd.Index(self.values[:, 0].copy(), name=self.names[0]),
        )
        for n, t in self.texts.items():
            df[n] = t
        df.attrs["units"] = dict(self.units)
        df.attrs["summary"] = dict(self.summary)
        return df

    def to_csv(self, path: PathLike) -> None:
        """Writes the table as ``master run`` does (atomically, shortest round-trip numbers,
        texts quoted as the master quotes them), with its metadata file beside it
        (``results.csv`` -> ``results.meta.json``: each column's type, unit and FMU variable,
        the sampling, the summary and the system as run), which :func:`read_results` and
        ``master assess`` read."""
        if Path(path).suffix.lower() in (".parquet", ".pq"):
            # CSV text under a Parquet name is a file nothing reads back
            raise _railfmu.OutputError(f"to_csv writes CSV: '{path}' names a Parquet file; give a .csv name, or use to_parquet")
        self._write(path, parquet=False)

    def to_parquet(self, path: PathLike) -> None:
        """Writes the table as ``master run -o results.parquet`` does (atomically): one Parquet
        file, its metadata (as :meth:`to_csv` writes beside a CSV) inside it under the key
        ``railfmu.results``, which :func:`read_results` and ``master assess`` read."""
        if Path(path).suffix.lower() not in (".parquet", ".pq"):
            raise _railfmu.OutputError(f"to_parquet writes Parquet: name '{path}' .parquet (or .pq)")
        self._write(path, parquet=True)

    def _write(self, path: PathLike, parquet: bool) -> None:
        texts = [(self.names.index(n), list(t)) for n, t in self.texts.items()]
        meta = json.dumps(self.metadata) if self.metadata is not None else None
        data = np.ascontiguousarray(self.values, dtype=np.float64).tobytes()
        summary = json.dumps(self.summary)
        # a run's own table has its full band; one read from a file has what its metadata
        # say; any other (e.g. built from every 20th row of another) records no sampling, so
        # that an assessment of the file notes it as one of the table does
        known = self.full_rate or (self.metadata is not None and self.metadata.get("sampling") is not None)
        _railfmu.write_results_file(os.fspath(path), self.header, data, texts, meta, summary, known, parquet)


class RunSetResults(Mapping[str, Results]):
    """A run-set folder: ``sweep.json`` plus one folder per run (``system.json``,
    ``results.csv``, ``summary.json``; Parquet results in ``results/<run>.parquet``). A mapping
    from run name to its :class:`Results` (read when first asked for; failed runs have none:
    their rows up to the failure are :meth:`history`)."""

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
            why = _not_reports(reports)
            if why:
                raise _railfmu.OutputError(f"'{path}' is not a run-set summary: {why}")
        self.reports: List[Dict[str, Any]] = list(reports)
        """Each run's report in job order: name, parameters, ok, error, summary, results (and
        history, for a run that failed after its first row)."""
        self._cache: Dict[str, Results] = {}
        self._parameter_units: Optional[Dict[str, Optional[str]]] = None

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
                    more = f" (its history up to the failure: .history('{name}'))" if r.get("history") else ""
                    raise KeyError(f"run '{name}' failed: {r.get('error')}{more}")
                parquet = self.folder / "results" / f"{name}.parquet"
                if parquet.is_file():
                    res = Results.read_parquet(parquet)
                else:
                    res = Results.read_csv(self.folder / name / "results.csv")
                res.summary = dict(r.get("summary") or {})
                self._cache[name] = res
                return res
        raise KeyError(f"no run '{name}' in {self.folder}")

    def history(self, name: str) -> Optional[Results]:
        """The rows of failed run ``name`` up to its failure (``history.csv`` or
        ``history.parquet`` in its folder; ``summary["failed"]`` gives the time and the
        error), or None when it failed before its first row. Raises KeyError for a run that
        is not in the set or did not fail."""
        for r in self.reports:
            if r["name"] == name:
                if r["ok"]:
                    raise KeyError(f"run '{name}' did not fail: its results are [{name!r}]")
                if not r.get("history"):
                    return None
                folder = self.folder / name
                parquet = folder / "history.parquet"
                if parquet.is_file():
                    return Results.read_parquet(parquet)
                return Results.read_csv(folder / "history.csv")
        raise KeyError(f"no run '{name}' in {self.folder}")

    def __repr__(self) -> str:
        return f"<RunSetResults {self.folder}: {len(self)} of {len(self.reports)} runs ok>"

    @property
    def parameter_units(self) -> Dict[str, Optional[str]]:
        """The unit of each parameter of the set (``instance.variable`` -> unit, None where
        its FMU declares none), from the model descriptions of the FMUs a run's
        ``system.json`` names. Raises :class:`FmuError` when they cannot be read."""
        if self._parameter_units is None:
            names = list(dict.fromkeys(k for r in self.reports for k in r.get("parameters", {})))
            units: List[Optional[str]] = [None] * len(names)
            systems = (self.folder / r["name"] / "system.json" for r in self.reports)
            system = next((p for p in systems if p.is_file()), None)
            if names and system is not None:
                units = _railfmu.parameter_units(os.fspath(system), names)
            self._parameter_units = dict(zip(names, units))
        return dict(self._parameter_units)

    def summary_frame(self):
        """One row per run: its parameters, ok, error and run statistics (pandas).
        ``df.attrs["units"]`` maps each column to its unit: a parameter's as its FMU declares
        it (see :attr:`parameter_units`), seconds for ``simulated_time_s`` and
        ``wall_time_s``, None for the others."""
        import pandas as pd

        rows = []
        for r in self.reports:
            row: Dict[str, Any] = {"run": r["name"], **r.get("parameters", {}), "ok": r["ok"], "error": r.get("error")}
            row.update(r.get("summary") or {})
            rows.append(row)
        if not rows:
            return pd.DataFrame(columns=["ok", "error"], index=pd.Index([], name="run"))
        df = pd.DataFrame(rows).set_index("run")
        try:
            parameters = self.parameter_units
        except _railfmu.Error as e:
            warnings.warn(f"the parameters' units are unknown: {e}", RuntimeWarning, stacklevel=2)
            parameters = {}
        seconds = {"simulated_time_s": "s", "wall_time_s": "s"}
        df.attrs["units"] = {c: parameters.get(c, seconds.get(c)) for c in df.columns}
        return df

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


def _not_reports(reports: Any) -> Optional[str]:
    """Why ``reports`` (a ``sweep.json`` read) is not a list of run reports; None if it is."""
    if not isinstance(reports, list):
        return f"a list of run reports expected, got {type(reports).__name__}"
    for k, r in enumerate(reports):
        if not (isinstance(r, dict) and isinstance(r.get("name"), str) and isinstance(r.get("ok"), bool)):
            return f"entry {k} is not a run report (an object with a text 'name' and a true/false 'ok')"
        if r["name"] in ("", ".", "..") or any(c in r["name"] for c in "/\\\0"):
            return f"entry {k}: run name {r['name']!r} is not a folder name"
        if not isinstance(r.get("parameters", {}), dict) or not isinstance(r.get("summary") or {}, dict):
            return f"entry {k} ('{r['name']}'): 'parameters' and 'summary' must be objects"
    return None


def read_results(path: PathLike) -> Union[Results, RunSetResults]:
    """Reads results back: a run-set folder (with ``sweep.json``) gives a
    :class:`RunSetResults`; a run folder (with ``results.csv``), a CSV file or a ``.parquet``
    file (``master run --format parquet``, or one run of a run set's ``results/``) gives a
    :class:`Results`, with the run's statistics (a CSV's from the ``summary.json`` beside it, a
    Parquet file's from its metadata)."""
    p = Path(path)
    if p.is_dir() and (p / "sweep.json").is_file():
        return RunSetResults(p)
    if p.suffix == ".parquet":
        return Results.read_parquet(p)
    if not p.exists():
        raise _railfmu.OutputError(f"'{p}': no such file or folder")
    csv = p / "results.csv" if p.is_dir() else p
    if not csv.is_file():
        raise _railfmu.OutputError(
            f"'{p}' holds neither sweep.json nor results.csv (a folder of a run or a run set, "
            "a results CSV or a .parquet file)"
        )
    res = Results.read_csv(csv)
    summary = csv.parent / "summary.json"
    if summary.is_file():
        try:
            s = json.loads(summary.read_text())
            # a run's report, or a run summary of its own; anything else is not the run's
            # (a failed run's report has none: its history file keeps its own, which says
            # when and why it failed)
            if isinstance(s, dict) and csv.name == "results.csv":
                inner = s.get("summary") if "ok" in s else s
                if isinstance(inner, dict) or inner is None:
                    res.summary = dict(inner or {})
        except (OSError, ValueError):
            pass
    return res
