"""Run sets: a base system plus parameter variations (the master's run-set JSON), run on local
threads or as Dask tasks, into the master's run-set folder."""

from __future__ import annotations

import contextlib
import json
import operator
import os
import warnings
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Union

import numpy as np

from . import _railfmu
from ._json import description_json
from ._log import emit as emit_log, forwarded
from ._progress import bar, check_progress
from ._results import RunSetResults

PathLike = Union[str, "os.PathLike[str]"]


@contextlib.contextmanager
def _folder_lock(folder: Path):
    """An exclusive ``flock`` on the run-set folder itself while a set writes into it (no file
    is created), the lock ``master sweep`` takes: a second set into the same folder, from
    Python or the command line, is refused instead of mixing its runs with this one's."""
    try:
        import fcntl
    except ImportError:  # not on Windows: no lock there
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise _railfmu.OutputError(
                f"another run set or study is writing into '{folder}' (a `master sweep`, "
                "`master study` or a Python run set): wait for it or choose another output folder"
            ) from None
        yield
    finally:
        os.close(fd)
DoneCallback = Callable[[int, int, str, Optional[str]], Any]



def _usable_cores() -> int:
    """The cores this process may run on (its affinity mask: a batch job's allocation, a
    ``taskset``), as ``master sweep`` counts them; all the machine's where there is no mask."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except (AttributeError, OSError):
        return os.cpu_count() or 1

class RunSet:
    """A run set expanded into self-contained jobs: each job is its name, its parameters and
    its resolved system description (FMU paths absolute), exactly as ``master sweep`` runs it.

    >>> rs = RunSet.load("python/examples/passive_speeds.json")
    >>> [j["name"] for j in rs.jobs]
    """

    def __init__(self, base_json: str, label: str, jobs_json: List[str]):
        self._base_json = base_json
        self._label = label
        self._jobs_json = list(jobs_json)
        self._names = [json.loads(j)["name"] for j in self._jobs_json]
        # the files the set reads (its run-set file, its base system, the FMUs): a set must not
        # write over them, nor replace or remove a run folder that holds one
        fmus = [i.get("fmu", "") for i in json.loads(base_json).get("instances", [])]
        self._inputs = [p for p in [label, *fmus] if isinstance(p, str) and os.path.isfile(p)]

    @classmethod
    def load(cls, path: PathLike) -> "RunSet":
        """Reads a run-set file (``base`` or inline ``system``, ``product``, ``runs``)."""
        rs = cls(*_railfmu.load_run_set(os.fspath(path)))
        rs._inputs.append(os.fspath(path))
        return rs

    @classmethod
    def from_dict(cls, runset: Mapping[str, Any], base_dir: PathLike = ".", label: str = "<dict>") -> "RunSet":
        """A run set given as a dict; paths relative to ``base_dir``."""
        return cls(*_railfmu.run_set_from_json(description_json(runset, label), os.fspath(base_dir), label))

    @property
    def base(self) -> Dict[str, Any]:
        """The base system description (FMU paths absolute)."""
        return json.loads(self._base_json)

    @property
    def jobs(self) -> List[Dict[str, Any]]:
        """Each job: ``name``, ``parameters`` (``instance.variable`` -> value), ``system``."""
        return [json.loads(j) for j in self._jobs_json]

    @property
    def names(self) -> List[str]:
        """The run names (also their folder names), in job order."""
        return list(self._names)

    def __len__(self) -> int:
        return len(self._jobs_json)

    def __repr__(self) -> str:
        return f"<RunSet {self._label}: {len(self)} runs>"

    def run(
        self,
        output_dir: PathLike,
        *,
        threads: Optional[int] = None,
        client: Any = None,
        progress: Union[None, bool, DoneCallback] = None,
        resume: bool = False,
        ship_fmus: bool = True,
        retries: int = 3,
        format: Optional[str] = None,
    ) -> RunSetResults:
        """Runs every job and writes the run-set folder: ``<output_dir>/<run>/`` with
        ``system.json`` and ``summary.json``, the results in ``<output_dir>/<run>/results.csv``
        or ``<output_dir>/results/<run>.parquet``, and ``<output_dir>/sweep.json`` with every
        run's report in job order. A failed run is reported in its own summary and the others
        go on.

        * ``format``: ``"csv"`` or ``"parquet"`` (the ``results/`` folder reads as one table,
          every run with its name and parameters as columns: ``pandas.read_parquet``); None:
          Parquet from 200 000 values (rows x columns) per run on, as ``master sweep``.

        * ``client=None``: on ``threads`` local threads (default: the cores this process may use), the GIL released.
        * ``client=dask.distributed.Client(...)``: one Dask task per run (see
          :mod:`railfmu.dask`); the results come back to this process, which writes the folder.
          ``threads`` is refused with it (the cluster's workers run the tasks).
        * ``resume=True``: runs already complete in ``output_dir`` (ok, results present in the
          results format of this call, same resolved system) are kept and not run again. The
          format is decided first (``format``, else by size over every job, as a fresh run
          set): runs kept in the other format are run again, so the folder stays in one format.
        * ``progress``: True for a bar, or ``f(done, total, run_name, error_or_None)``.

        A set stopped part way (Ctrl-C, an exception of ``progress``) ends as ``master sweep``
        ends it, then raises: no further run starts, a run stopped at a communication point
        is written as a cancelled (failed) run, a run not started (locally) or not finished
        (on Dask) has no folder (an earlier set's folder of its name is removed), and
        ``sweep.json`` lists every run with its outcome, so ``resume=True`` runs only what is
        missing. A set of 100 000 runs stops at once.
        """
        if threads is not None:
            # a whole number, NumPy's included (operator.index), not a bool or a float
            try:
                count = -1 if isinstance(threads, (bool, np.bool_)) else operator.index(threads)
            except TypeError:
                count = -1
            if count < 1:
                raise ValueError(f"threads must be a whole number >= 1 (or None: the cores this process may use), got {threads!r}")
            threads = count
        if not isinstance(resume, (bool, np.bool_)):
            raise TypeError(f"resume must be True or False, got {resume!r}")
        if threads is not None and client is not None:
            # the workers of the Dask cluster take the runs as they come: no local threads
            raise ValueError("threads: the runs go to the Dask client's workers; give threads or client, not both")
        # every option checked before the folder is touched: a misspelt one must not cost the
        # earlier set's results
        if format is not None:
            if not isinstance(format, str):
                raise TypeError(f"format must be 'csv', 'parquet' or None, got {format!r}")
            if format not in ("csv", "parquet"):
                raise ValueError(f"format must be 'csv', 'parquet' or None, got {format!r}")
        check_progress(progress)
        if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
            raise ValueError(f"retries must be a whole number >= 0, got {retries!r}")
        if client is not None and not all(callable(getattr(client, m, None)) for m in ("submit", "scatter")):
            raise TypeError(f"client must be a dask.distributed.Client (or None: local threads), got {type(client).__name__}")
        if isinstance(output_dir, (str, bytes)) and len(output_dir) == 0:
            # an empty path would be the working folder, which is not chosen by accident
            raise ValueError("output_dir is an empty path; name a folder ('.' for the working folder)")
        out = Path(os.fsdecode(output_dir))
        system = None
        if client is None or ship_fmus:
            # the FMUs loaded and every run's start values checked (names, types, declared
            # ranges) before anything is written or removed: a misspelt variable is refused
            # here, not failed run by run. On a cluster too, when this process ships the FMUs
            # (it reads them anyway); with shared FMUs their paths may be the workers' only.
            with forwarded():
                system = _railfmu.PreparedSystem.from_json(self._base_json, "", self._label)
                system.check_jobs(self._jobs_json)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise _railfmu.OutputError(f"cannot create the output folder '{out}': {e}") from e
        # one set at a time in a folder (the lock `master sweep` takes too): a second one
        # would mix its runs into this one's
        with _folder_lock(out):
            reports: List[Optional[str]] = [None] * len(self)
            if resume:
                # decided over every job before the kept runs, as a fresh run set decides it
                if format is None:
                    format = self._format_by_size(client, ship_fmus, retries)
                for i, j in enumerate(self._jobs_json):
                    reports[i] = _railfmu.completed_report(os.fspath(out), j, format)
            todo = [i for i, r in enumerate(reports) if r is None]
            # before anything is removed: the report would not replace an input (a run-set file
            # saved as <out>/sweep.json), and no input lies in a run folder the set replaces or
            # removes (an earlier run's system.json as the base)
            _railfmu.check_run_set_inputs(
                os.fspath(out), self._inputs, self._jobs_json, [self._jobs_json[i] for i in todo]
            )
            # this set's runs only: nothing of the user's is replaced by a run folder, and an
            # earlier set's other runs are removed (the kept ones are in this set)
            _railfmu.prepare_run_folder(os.fspath(out), self._jobs_json)
            # the earlier set's report goes with its runs: a set that fails before its first run
            # (an unreadable FMU) leaves no report of runs that are no longer there
            remove_sweep_report(out)
            # the earlier runs of the names about to be computed go before the first starts:
            # a set killed midway leaves none of them beside this set's (a file of the user's
            # in such a folder is refused first)
            _railfmu.clear_earlier_runs(os.fspath(out), [self._jobs_json[i] for i in todo])
            total, done = len(self), len(self) - len(todo)
            with bar(progress, "runs") as cb:
                if cb is not None and done:
                    cb(done, total, "", None)

                def on_done(name: str, error: Optional[str]) -> None:
                    nonlocal done
                    done += 1
                    emit_log()  # the messages of the runs so far, as they finish
                    if cb is not None:
                        cb(done, total, name, error)

                if todo:
                    jobs = [self._jobs_json[i] for i in todo]
                    # the runs kept by a resume: their parameters are columns of every table
                    kept = [j for j, r in zip(self._jobs_json, reports) if r is not None]
                    new: List[Optional[str]] = [None] * len(jobs)
                    local_runs = False
                    try:
                        if client is None and system is not None:
                            # no more threads than runs (a count beyond any machine's, 2**70,
                            # is then no error after the folder was prepared)
                            threads = min(threads or _usable_cores(), len(jobs))
                            local_runs = True
                            with forwarded():
                                new = system.run_jobs(jobs, os.fspath(out), threads, on_done, format, kept)
                        else:
                            from .dask import run_jobs_on_cluster

                            run_jobs_on_cluster(
                                client,
                                self._base_json,
                                self._label,
                                jobs,
                                out,
                                on_done,
                                ship_fmus=ship_fmus,
                                retries=retries,
                                format=format,
                                reports=new,
                                kept_json=kept,
                            )
                    except BaseException:
                        # stopped part way (Ctrl-C, an exception of `progress`, ...): the runners
                        # end every started set with a report per run (finished, cancelled or
                        # not started), as `master sweep` does; sweep.json lists them all, the
                        # kept ones too, so that `resume=True` carries on from it
                        if local_runs:
                            new = _reports_of_stopped_set(out, jobs)
                        if all(r is not None for r in new):
                            for i, r in zip(todo, new):
                                reports[i] = r
                            with contextlib.suppress(Exception):  # the set's own exception is raised
                                _railfmu.write_sweep(os.fspath(out), [r for r in reports if r is not None])
                        raise
                    for i, r in zip(todo, new):
                        reports[i] = r
            final = [r for r in reports if r is not None]
            _railfmu.write_sweep(os.fspath(out), final)
            results = RunSetResults(out, [json.loads(r) for r in final])
            if results.reports and all(not r.get("ok") for r in results.reports):
                # as `master sweep` exits with status 1: a set with no result is not quietly empty
                first = results.reports[0]
                warnings.warn(
                    f"no run of the set succeeded ({len(results.reports)} failed); the first, "
                    f"'{first.get('name')}': {first.get('error')}",
                    RuntimeWarning,
                    stacklevel=2,
                )
            return results

    def _format_by_size(self, client: Any, ship_fmus: bool, retries: int) -> str:
        """The results format a fresh run of every job chooses by size ("csv" or "parquet")."""
        if client is None:
            return _railfmu.results_format_by_size(self._base_json, self._label, self._jobs_json)
        from .dask import results_format

        return results_format(client, self._base_json, self._label, self._jobs_json, ship_fmus=ship_fmus, retries=retries)


def remove_sweep_report(out: Path) -> None:
    """Removes ``<out>/sweep.json`` before the runs of a set are written, as ``master sweep``
    does: a set stopped part way never leaves an earlier set's report looking current."""
    path = out / "sweep.json"
    try:
        path.unlink()
    except FileNotFoundError:
        pass
    except OSError as e:
        raise _railfmu.OutputError(f"cannot remove the earlier report '{path}': {e}") from e


def _reports_of_stopped_set(out: Path, jobs_json: List[str]) -> List[Optional[str]]:
    """The reports (JSON) of the local runs of ``jobs_json`` that were stopped part way, as
    their runner wrote them in ``<out>/sweep.json`` before it raised (every run: finished,
    cancelled or not started); None for each when it wrote none."""
    names = [json.loads(j)["name"] for j in jobs_json]
    try:
        written = json.loads((out / "sweep.json").read_text(encoding="utf-8"))
        if [r["name"] for r in written] == names:
            return [json.dumps(r) for r in written]
    except (OSError, ValueError, TypeError, KeyError):
        pass
    return [None] * len(names)


def run_set(
    runset: Union[PathLike, Mapping[str, Any], RunSet],
    output_dir: PathLike,
    **options: Any,
) -> RunSetResults:
    """Loads a run set (a file, a dict or a :class:`RunSet`) and runs it (see
    :meth:`RunSet.run` for the options: threads, client, progress, resume, ship_fmus,
    retries, format)."""
    if isinstance(runset, RunSet):
        rs = runset
    elif isinstance(runset, Mapping):
        rs = RunSet.from_dict(runset)
    else:
        rs = RunSet.load(runset)
    return rs.run(output_dir, **options)
