"""Run sets on a Dask cluster (``dask.distributed``): one task per run.

Each task is self-contained: the base system's resolved description and one job (its name,
parameters and resolved system) go in, the run's table with its units and FMU variables (or its
error) comes out. The client writes the run's folder with the master's own writer, in CSV or
Parquet (``<out>/results/<run>.parquet`` with the run parameters as columns; by default chosen
by size as ``master sweep`` does), so a run-set folder made on a cluster is the one ``master
sweep`` makes, value for value, and the workers need no access to the output folder.

FMUs reach the workers in one of two ways:

* ``ship_fmus=True`` (default): the client reads each FMU file once, scatters its bytes to every
  worker (``Client.scatter(..., broadcast=True)``, once per run set, not once per task) and each
  worker keeps a copy in its FMU cache (below), named by the file's SHA-256. This works on any
  deployment (LocalCluster, dask-jobqueue on Slurm/PBS, cloud clusters) without a shared file
  system, and the workers run exactly the bytes the client has.
* ``ship_fmus=False``: the workers open the FMU paths of the description as they are (absolute
  paths on the client). Use it when all nodes see the FMUs on one shared file system (typical on
  HPC): nothing is copied.

The FMU cache of a worker machine is the folder ``railfmu-fmus-<uid>`` in the workers' temporary
folder (``tempfile.gettempdir()``: set ``TMPDIR`` in the workers' environment to move it), shared
by the workers of one user on that machine: one sub-folder per FMU, named by its SHA-256, holding
the FMU under its file name, written atomically. A task marks the copies it uses as used (the
sub-folder's modification time). It stays bounded: whenever a worker writes a new copy, it
removes the copies not used for 7 days and, beyond the 16 most recently used, those not used for
an hour (a copy is only read while a worker prepares the system, so an hour is ample). A copy is
first renamed aside (``.removed-*``), then removed, so no worker finds it half-removed; one
removed and needed again is written again. Nothing else in the folder is touched. The folder is
private (made 0700, and made so again when found open to others); one that belongs to another
user, or that stays writable by others, is refused (the workers would run any FMU put there). A worker checks the SHA-256 of a copy before its first
use and writes a damaged one again.

A worker prepares a system (unpacks and loads its FMUs) once and keeps it for the later tasks of
the same run set. A simulation that fails is the run's result (its error is kept in its
``summary.json``), not a task failure; a task whose worker dies is run again by Dask
(``retries``, and Dask's own rescheduling of a lost worker's tasks). A client that loses its
scheduler cannot get the other results: the set stops as an interrupted one does (the runs not
finished are listed as cancelled in sweep.json, without a folder) and raises :class:`SchedulerLostError`; ``resume=True`` on a
working cluster completes it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import stat
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Tuple

from . import _railfmu
from ._log import forwarded



class SchedulerLostError(_railfmu.Error, ConnectionError):
    """The Dask client lost its scheduler during a run set: the runs that had not finished are
    listed as cancelled in sweep.json (which lists every run), without a folder, and
    ``resume=True`` on a working cluster runs them."""


_PREPARED: Dict[Any, "_railfmu.PreparedSystem"] = {}
_PREPARED_LOCK = threading.Lock()
_KEEP_PREPARED = 4


def _fmu_cache_dir() -> Path:
    """This user's FMU cache folder, made private (0700) when new. One that another user
    could write to (made by them first under a shared temporary folder, or opened to others)
    is refused: the workers would run whatever FMU was put there."""
    root = Path(tempfile.gettempdir()) / f"railfmu-fmus-{os.getuid() if hasattr(os, 'getuid') else 'user'}"
    try:
        root.mkdir(mode=0o700)
    except FileExistsError:
        pass
    if hasattr(os, "getuid"):
        st = os.lstat(root)
        if not stat.S_ISDIR(st.st_mode):
            raise RuntimeError(f"FMU cache '{root}' is not a folder (a link or a file): remove it")
        if st.st_uid != os.getuid():
            raise RuntimeError(f"FMU cache '{root}' belongs to another user (uid {st.st_uid}): remove it")
        if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
            # ours, opened to others (made by an earlier version under a umask of 002): closed
            # again; refused where the file system keeps no such modes
            with contextlib.suppress(OSError):
                os.chmod(root, 0o700)
            if os.lstat(root).st_mode & (stat.S_IWGRP | stat.S_IWOTH):
                raise RuntimeError(
                    f"FMU cache '{root}' is writable by other users and cannot be made private "
                    "(a file system without Unix modes?): set TMPDIR of the workers to a private folder"
                )
    return root


# Copies this worker found intact: path -> (inode, size, modification time in ns) when their
# SHA-256 was checked (a copy is hashed once per worker, not on every run).
_verified: Dict[str, Tuple[int, int, int]] = {}


def _stamp(path: Path) -> Tuple[int, int, int]:
    st = path.stat()
    return (st.st_ino, st.st_size, st.st_mtime_ns)


def _intact(path: Path, digest: str, size: int) -> bool:
    """Whether the cached copy at ``path`` holds the FMU of ``digest`` (its bytes hashed once,
    then recognised by its file stamp)."""
    try:
        stamp = _stamp(path)
    except OSError:
        return False
    if stamp[1] != size:
        return False
    if _verified.get(str(path)) == stamp:
        return True
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return False
    if h.hexdigest() != digest:
        return False
    _verified[str(path)] = stamp
    return True


# The FMU cache's bounds (see the module's documentation).
_CACHE_MAX_AGE_S = 7 * 24 * 3600
_CACHE_KEEP = 16
_CACHE_IN_USE_S = 3600
_CACHE_ENTRY = re.compile(r"[0-9a-f]{32}")
# Prefix of a cache entry renamed aside to be removed.
_CACHE_REMOVED = ".removed-"


def _local_copy(digest: str, name: str, data: bytes) -> str:
    """Path of this worker's copy of an FMU (written once, atomically)."""
    folder = _fmu_cache_dir() / digest[:32]
    path = folder / name
    # a copy damaged since it was written (a full disk, a hand) is written again
    if _intact(path, digest, len(data)):
        try:
            os.utime(folder)  # used now: kept by the cache's trimming
            return str(path)
        except OSError:  # removed in between as unused: written again
            pass
    if hashlib.sha256(data).hexdigest() != digest:
        raise RuntimeError(f"FMU '{name}' arrived damaged (SHA-256 differs)")
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".tmp-")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    _trim_cache(folder.parent, folder.name)
    return str(path)


def _trim_cache(root: Path, current: str) -> None:
    """Removes the cache entries of ``root`` not used for ``_CACHE_MAX_AGE_S`` and, beyond the
    ``_CACHE_KEEP`` most recently used (``current`` among them), those not used for
    ``_CACHE_IN_USE_S``. Each is renamed aside first (atomic: another worker finds the entry
    whole or not at all), then removed; one used again meanwhile is put back. Never fails the
    task: what cannot be removed stays."""
    now = time.time()
    entries = []
    try:
        with os.scandir(root) as it:
            for e in it:
                try:
                    if not e.is_dir(follow_symlinks=False):
                        continue
                    used = e.stat(follow_symlinks=False).st_mtime
                except OSError:
                    continue
                if e.name.startswith(_CACHE_REMOVED):
                    # left by a worker that died while removing it
                    if now - used > _CACHE_IN_USE_S:
                        shutil.rmtree(e.path, ignore_errors=True)
                elif _CACHE_ENTRY.fullmatch(e.name) and e.name != current:
                    entries.append((used, e.name))
    except OSError:
        return
    entries.sort(reverse=True)
    for rank, (used, name) in enumerate(entries, start=2):  # `current` is the most recent
        unused = now - used
        if unused <= _CACHE_MAX_AGE_S and (rank <= _CACHE_KEEP or unused <= _CACHE_IN_USE_S):
            continue
        aside = root / f"{_CACHE_REMOVED}{name}-{uuid.uuid4().hex[:8]}"
        try:
            os.rename(root / name, aside)
            if aside.stat().st_mtime != used:  # used again just before the rename: put back
                os.rename(aside, root / name)
                continue
        except OSError:  # removed by another worker meanwhile
            continue
        shutil.rmtree(aside, ignore_errors=True)


def _localise(description: Dict[str, Any], paths: Dict[str, str]) -> Dict[str, Any]:
    d = dict(description)
    d["instances"] = [dict(i, fmu=paths.get(i["fmu"], i["fmu"])) for i in d["instances"]]
    return d


def _fmu_stamps(base_json: str) -> tuple:
    """What tells whether the system's FMU files changed since a worker loaded them (a rebuild
    on a shared file system keeps the paths): size, modification and status-change times, inode."""
    stamps = []
    try:
        instances = json.loads(base_json).get("instances", [])
    except ValueError:
        return ()
    for inst in instances:
        try:
            st = os.stat(inst.get("fmu", ""))
            stamps.append((st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino))
        except (OSError, TypeError, AttributeError):
            stamps.append(None)
    return tuple(stamps)


def _prepared(base_json: str, label: str) -> "_railfmu.PreparedSystem":
    # keyed on the FMU files' stamps too: a system whose FMUs were rebuilt is loaded again
    # (its runs would otherwise fail as run on a changed FMU, for as long as the worker lives)
    key = (base_json, _fmu_stamps(base_json))
    with _PREPARED_LOCK:
        system = _PREPARED.get(key)
        if system is None:
            system = _railfmu.PreparedSystem.from_json(base_json, "", label)
            if len(_PREPARED) >= _KEEP_PREPARED:
                _PREPARED.pop(next(iter(_PREPARED)))
            _PREPARED[key] = system
        return system


def format_task(base_json: str, label: str, jobs_json: List[str]) -> str:
    """The results format chosen by size, from the FMUs as a worker reads them from their paths
    (a shared file system the client does not see). FMUs no one can read make every run fail
    on its own: no results file, so the format does not matter then."""
    try:
        return _railfmu.results_format_by_size(base_json, label, jobs_json)
    except _railfmu.Error:
        return "csv"


def run_task(
    base_json: str,
    label: str,
    job_json: str,
    fmus: Optional[Dict[str, Tuple[str, str, bytes]]] = None,
    stop_event: Optional[str] = None,
) -> Dict[str, Any]:
    """The task a worker runs: one job of a run set. ``fmus`` maps each FMU path of the
    description to (SHA-256, file name, bytes) when the FMUs are shipped. ``stop_event``: the
    name of the set's ``distributed.Event``, which the client sets when the set stops (Ctrl-C):
    a run still going then stops at its next communication point, instead of running to its end
    for nobody (a cancelled future does not stop a task already running). Returns the run's
    ``header``, ``data`` (float64 bytes), ``summary_json`` and ``columns_json`` (the columns'
    units and FMU variables), or its ``error`` (with a run that failed after its first row,
    the others hold its history up to the failure)."""
    if fmus:
        paths = {p: _local_copy(digest, name, data) for p, (digest, name, data) in fmus.items()}
        base_json = json.dumps(_localise(json.loads(base_json), paths))
        job = json.loads(job_json)
        job["system"] = _localise(job["system"], paths)
        job_json = json.dumps(job)
    should_stop = _stop_check(stop_event) if stop_event is not None else None
    # the run's messages go to the worker's logging (its log, which the cluster keeps)
    with forwarded():
        header, data, summary_json, columns_json, error = _prepared(base_json, label).run_job(job_json, should_stop)
    return {"header": header, "data": data, "summary_json": summary_json, "columns_json": columns_json, "error": error}


def _stop_check(name: str) -> Any:
    """``f()`` -> whether the set's stop event is set (asked of the scheduler; the run polls it
    about once a second, so a short run never asks)."""
    from distributed import Event, get_client

    state: Dict[str, Any] = {}

    def stopped() -> bool:
        if "event" not in state:
            state["event"] = Event(name, client=get_client())
        return bool(state["event"].is_set())

    return stopped


def _read_fmus(base_json: str) -> Dict[str, Tuple[str, str, bytes]]:
    out: Dict[str, Tuple[str, str, bytes]] = {}
    for inst in json.loads(base_json)["instances"]:
        p = inst["fmu"]
        if p in out:
            continue
        try:
            data = Path(p).read_bytes()
        except OSError as e:
            raise _railfmu.FmuError(f"cannot read '{p}': {e}") from None
        out[p] = (hashlib.sha256(data).hexdigest(), Path(p).name, data)
    return out


def _scatter_fmus(client: Any, base_json: str) -> Dict[str, Tuple[str, str, Any]]:
    """The FMUs of the description sent to every worker: path -> (SHA-256, file name, future)."""
    fmus = _read_fmus(base_json)
    # hash=False: keys new to this set. A key derived from the content would be the one an
    # earlier set scattered, which the scheduler may still be releasing (its tasks would
    # then fail with "lost dependencies").
    paths = list(fmus)
    scattered = client.scatter([fmus[p][2] for p in paths], broadcast=True, hash=False)
    return {p: (fmus[p][0], fmus[p][1], f) for p, f in zip(paths, scattered)}


def results_format(client: Any, base_json: str, label: str, jobs_json: List[str], *, ship_fmus: bool, retries: int = 3) -> str:
    """The results format ("csv" or "parquet") a run set of ``jobs_json`` chooses by size, as a
    local run set does: from the FMUs' model descriptions read on this client. Only when the
    workers read the FMUs from their own paths (``ship_fmus=False``) can a worker see what the
    client cannot, and one worker decides; shipped FMUs are the bytes this client could not
    read, so every run fails on its own and the format does not matter ("csv"). A resumed run
    set decides it over every job before it keeps any run."""
    try:
        return _railfmu.results_format_by_size(base_json, label, jobs_json)
    except _railfmu.Error:
        if ship_fmus:
            return "csv"
    return client.submit(format_task, base_json, label, jobs_json, retries=retries, pure=False).result()


def run_jobs_on_cluster(
    client: Any,
    base_json: str,
    label: str,
    jobs_json: List[str],
    outdir: Path,
    on_done: Callable[[str, Optional[str]], Any],
    *,
    ship_fmus: bool = True,
    retries: int = 3,
    format: Optional[str] = None,
    reports: Optional[List[Optional[str]]] = None,
    kept_json: Optional[List[str]] = None,
) -> List[str]:
    """Submits one task per job to ``client``, writes each run's folder as its result arrives
    and returns the reports (JSON) in job order. ``format``: "csv" or "parquet"; None chooses
    by size as a local run set does (from the FMUs' model descriptions, read on this client).
    A task that raises (even after its retries, e.g. every worker running it died) gives a
    failed run carrying the exception's message.

    ``reports``, when given, is a list of one entry per job that receives each report as its
    run's folder is written. A set stopped part way (Ctrl-C, an exception of ``on_done``, a
    client that fails) ends as a local run set does: the remaining tasks are cancelled, each
    run not finished gets its report in ``reports`` as cancelled but no folder (an earlier
    set's folder of its name is removed), and the exception is raised.

    ``kept_json``: the jobs of the set that a resume keeps; their parameters are columns of
    every run's table too (a Parquet folder reads with its first file's columns)."""
    from distributed import as_completed

    from ._runset import remove_sweep_report

    if format is None:
        format = results_format(client, base_json, label, jobs_json, ship_fmus=ship_fmus, retries=retries)
    fmus_arg = _scatter_fmus(client, base_json) if ship_fmus else None
    writer = _railfmu.RunWriter(os.fspath(outdir), jobs_json, format, base_json, label, kept_json)
    if reports is None:
        reports = [None] * len(jobs_json)
    # keys unique per submission: a key resubmitted while the scheduler still releases it from
    # an earlier set would be cancelled
    token = uuid.uuid4().hex[:16]
    stop_event = f"railfmu-stop-{token}"
    futures = {}
    remove_sweep_report(Path(outdir))
    try:
        for i, job_json in enumerate(jobs_json):
            name = json.loads(job_json)["name"]
            fut = client.submit(
                run_task,
                base_json,
                label,
                job_json,
                fmus_arg,
                stop_event,
                key=f"railfmu-{name}-{token}",
                retries=retries,
                pure=False,
            )
            futures[fut] = (i, name, job_json)
        for fut in as_completed(list(futures)):
            i, name, job_json = futures[fut]
            try:
                r = fut.result()
                report = writer.write(job_json, r["header"], r["data"], r["summary_json"], r["columns_json"], r["error"])
                error = r["error"]
            except Exception as e:  # the task failed: the run's error, the set goes on
                if _scheduler_lost(client, e):
                    finished = sum(r is not None for r in reports)
                    raise SchedulerLostError(
                        f"the Dask client lost its scheduler after {finished} of the {len(jobs_json)} "
                        "runs submitted; the others are cancelled: run the set again with resume=True on a "
                        "working cluster"
                    ) from e
                error = f"run '{name}' failed on the cluster: {type(e).__name__}: {e}"
                report = writer.write(job_json, error=error)
            reports[i] = report
            on_done(name, error)
    except BaseException as stop:
        if not isinstance(stop, SchedulerLostError):
            _stop_running_tasks(client, stop_event)
        _cancel(futures)
        if isinstance(stop, KeyboardInterrupt):
            error = "cancelled: the run set was interrupted before this run finished"
        else:
            error = f"cancelled: the run set stopped before this run finished ({type(stop).__name__}: {stop})"
        for i, job_json in enumerate(jobs_json):
            if reports[i] is None:
                reports[i] = writer.not_finished(job_json, error)
        raise
    else:
        _cancel(futures)
    return [r for r in reports if r is not None]


def _scheduler_lost(client: Any, e: BaseException) -> bool:
    """Whether a task's exception says that the client has lost its scheduler (every pending
    future is cancelled then: no result of this set can arrive any more), not that the run
    failed."""
    from distributed.comm import CommClosedError

    # the futures cancelled for it, or a result fetched over the closed connection
    if getattr(e, "reason", None) == "scheduler-connection-lost" or isinstance(e, CommClosedError):
        return True
    # reconnecting, or closed meanwhile
    return getattr(client, "status", "running") != "running"


def _stop_running_tasks(client: Any, name: str) -> None:
    """Sets the set's stop event, which the runs still going poll (a cancelled future stops a
    task only before it starts). Best effort: a client that cannot reach its scheduler has no
    running tasks to stop."""
    from distributed import Event

    try:
        Event(name, client=client).set()
    except Exception:
        pass


def _cancel(futures: Any) -> None:
    """Cancels the tasks of ``futures`` still pending (a client that lost its scheduler
    cannot, and has no tasks left)."""
    for fut in futures:
        try:
            fut.cancel()
        except Exception:
            pass
