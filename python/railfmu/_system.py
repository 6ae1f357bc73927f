"""A system of coupled FMUs, prepared once, run many times."""

from __future__ import annotations

import json
import numbers
import os
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

from . import _railfmu
from ._json import description_json
from ._log import forwarded
from ._results import Results

PathLike = Union[str, "os.PathLike[str]"]
Value = Union[bool, int, float, str]
ProgressArg = Union[None, bool, Callable[[int, int], Any]]


def _plain(value: Any) -> Any:
    """NumPy scalars as the Python bool/int/float they stand for."""
    try:
        import numpy as np
    except ImportError:  # pragma: no cover
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def _plain_dict(parameters: Optional[Mapping[str, Any]]) -> Dict[str, Any]:
    if parameters is not None and not isinstance(parameters, Mapping):
        raise TypeError(
            "parameters must be a mapping of 'instance.variable' to a value, "
            f"not {type(parameters).__name__}"
        )
    return {k: _plain(v) for k, v in (parameters or {}).items()}


def _seconds(name: str, value: Any) -> Optional[float]:
    """A time option [s]: None, or a real number (NumPy's too); True or '2' is refused rather
    than read as 1 s or 2 s."""
    if value is None:
        return None
    value = _plain(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number of seconds, not {type(value).__name__} {value!r}")
    return float(value)


class System:
    """A system description (JSON: FMU instances, parameters, connections, timing, coupling,
    recording) with its FMUs opened, checked, unpacked and loaded once.

    Start values set here (:meth:`set_parameter`) and the stop time apply to every later
    :meth:`run`; each run instantiates its own FMU instances, so runs never see each other's
    state. Invalid names or values raise :class:`SystemDescriptionError` at once, with the
    master's message.

    >>> sys = System.load("systems/passive.json")
    >>> sys.set_parameter("bogie.vehicle.speed", 70.0)
    >>> df = sys.run(stop_time=2.0).to_pandas()
    """

    def __init__(self, prepared: "_railfmu.PreparedSystem"):
        self._prepared = prepared
        self._parameters: Dict[str, Value] = {}
        self._stop_time: Optional[float] = None

    @classmethod
    def load(
        cls,
        path: PathLike,
        *,
        step: Optional[float] = None,
        stop_time: Optional[float] = None,
        algorithm: Optional[str] = None,
        record: Optional[Sequence[str]] = None,
    ) -> "System":
        """Loads a system description file: JSON (FMU paths relative to its folder), or an SSP
        (a ``.ssp`` archive, or a bare ``.ssd`` next to its FMUs) as ``master run`` reads it.
        An ``.fmu`` is not a system description (:class:`SystemDescriptionError`): describe
        a system of its instances with :meth:`from_dict`.

        ``step``, the communication step [s]; ``stop_time`` [s]; ``algorithm``, the coupling
        algorithm, ``"jacobi"`` or ``"gauss-seidel"``: each replaces the description's (as
        ``master run --step --stop --algorithm``). An SSP's defaults: its libcosim or
        OMSimulator step annotation, its DefaultExperiment's stop time, and the coupling
        ``master export-ssp`` kept in it (else Jacobi). ``record``: the ``instance.variable``
        names to record, replacing the description's list (``master run --record``; an SSP
        records every output unless given)."""
        step_s, stop_s = _seconds("step", step), _seconds("stop_time", stop_time)
        if record is not None:
            if isinstance(record, (str, bytes)):
                raise TypeError(f"record must be a list of instance.variable names, got {record!r}")
            record = list(record)
            if not all(isinstance(r, str) for r in record):
                raise TypeError(f"record must be a list of instance.variable names, got {record!r}")
            if not record:
                raise ValueError("record: an empty list records nothing; give names, or None for the description's list")
        with forwarded():
            return cls(_railfmu.PreparedSystem.load(os.fspath(path), step_s, stop_s, algorithm, record))

    @classmethod
    def from_dict(cls, description: Mapping[str, Any], base_dir: PathLike = ".", label: str = "<dict>") -> "System":
        """A system from a description given as a dict (FMU paths relative to ``base_dir``)."""
        text = description_json(description, label)
        with forwarded():
            return cls(_railfmu.PreparedSystem.from_json(text, os.fspath(base_dir), label))

    @property
    def file(self) -> str:
        """The description's file (or label), as named in messages."""
        return self._prepared.file

    @property
    def description(self) -> Dict[str, Any]:
        """The description as loaded, FMU paths absolute (without this object's changes)."""
        return json.loads(self._prepared.description_json())

    @property
    def instances(self) -> List[str]:
        """Instance names in declaration order."""
        return [i["name"] for i in self.description["instances"]]

    @property
    def columns(self) -> List[str]:
        """The header of a run's results: ``time [s]``, then ``instance.variable [unit]``."""
        return self._prepared.header()

    def variables(self, instance: str) -> List[Dict[str, Any]]:
        """The variables of one instance's FMU, from its modelDescription.xml: one dict per
        variable with ``name``, ``value_reference``, ``causality`` and ``variability`` (as
        ``'Parameter'``, ``'Output'``, ``'Fixed'``, ...), ``initial``, ``var_type`` (``'Real'``,
        ``'Integer'``, ``'Enumeration'``, ``'Boolean'``, ``'String'``), ``unit``, ``start``
        (the text of the XML attribute, or None), ``description`` and ``declared_type``."""
        names = self.instances
        if instance not in names:
            raise KeyError(f"no instance '{instance}' (instances: {', '.join(names)})")
        models = json.loads(self._prepared.models_json())
        return list(models[names.index(instance)]["variables"])

    @property
    def parameters(self) -> Dict[str, Value]:
        """The start values set on this object (``instance.variable`` -> value), a copy."""
        return dict(self._parameters)

    def set_parameter(self, name: str, value: Value) -> None:
        """Sets the start value of ``instance.variable`` for later runs; checked against the
        FMU's model description at once (name, type, range as the master checks them)."""
        self.set_parameters({name: value})

    def set_parameters(self, parameters: Mapping[str, Value]) -> None:
        """Sets several start values (see :meth:`set_parameter`); all or none."""
        merged = {**self._parameters, **_plain_dict(parameters)}
        self._prepared.check(merged, self._stop_time)
        self._parameters = merged

    @property
    def stop_time(self) -> float:
        """Stop time [s] of later runs (the description's unless set)."""
        return self._stop_time if self._stop_time is not None else float(self.description["stop_time"])

    @stop_time.setter
    def stop_time(self, value: Optional[float]) -> None:
        seconds = _seconds("stop_time", value)
        if seconds is not None:
            self._prepared.check(self._parameters, seconds)
        self._stop_time = seconds

    def run(
        self,
        parameters: Optional[Mapping[str, Value]] = None,
        stop_time: Optional[float] = None,
        progress: ProgressArg = None,
    ) -> Results:
        """Runs the system once and returns its :class:`Results`.

        ``parameters`` and ``stop_time`` apply to this run only, on top of those set on the
        object. The GIL is released while the FMUs run, so other Python threads go on.
        ``progress``: True for a progress bar (tqdm when installed), or a callable
        ``f(steps_done, steps_total)``. Ctrl-C stops the run at its next communication point
        and raises KeyboardInterrupt.

        Raises :class:`SystemDescriptionError` for an invalid name or value,
        :class:`FmuError` when an FMU cannot be instantiated, :class:`SimulationError` when
        the simulation fails; its ``history`` holds the :class:`Results` up to the last
        communication point every instance completed (``summary["failed"]`` gives the time
        and the error), or None when the run failed before its first row.
        """
        merged = {**self._parameters, **_plain_dict(parameters)}
        seconds = _seconds("stop_time", stop_time)
        stop = seconds if seconds is not None else self._stop_time
        from ._progress import bar

        try:
            with bar(progress, "steps") as cb, forwarded():
                header, data, texts, summary, meta = self._prepared.run(merged, stop, cb)
        except _railfmu.SimulationError as e:
            history = None
            if len(e.args) == 2 and isinstance(e.args[1], tuple):
                h_header, h_data, h_texts, h_summary, h_meta = e.args[1]
                history = Results._from_bytes(
                    h_header, h_data, json.loads(h_summary), True, h_texts, json.loads(h_meta)
                )
                e.args = (e.args[0],)
            e.history = history
            raise
        return Results._from_bytes(header, data, json.loads(summary), True, texts, json.loads(meta))

    def __repr__(self) -> str:
        return f"<System {self.file}: {', '.join(self.instances)}>"

    def __copy__(self) -> "System":
        # the loaded FMUs shared (runs never see each other's state), the settings its own
        other = System(self._prepared)
        other._parameters = dict(self._parameters)
        other._stop_time = self._stop_time
        return other

    def __deepcopy__(self, memo: Dict[int, Any]) -> "System":
        return self.__copy__()

    def __reduce__(self):
        # the loaded FMUs live in this process; say what to send instead of pickle's own
        # "cannot pickle 'PreparedSystem'"
        raise TypeError(
            "a railfmu.System holds FMUs loaded in this process and does not pickle: send its "
            "description (System.description, a dict) or its file and load it where it runs "
            "(System.from_dict, System.load), or run a set on a Dask cluster with "
            "railfmu.run_set(..., client=...)"
        )
