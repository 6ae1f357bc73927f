"""EN 14363 running-stability assessment of results, as ``master assess`` makes it."""

from __future__ import annotations

import json
from collections import abc
import numbers as numbers_abc
import os
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _railfmu
from ._results import PathLike, Results


@dataclass(frozen=True)
class SignalAssessment:
    """The assessment of one signal."""

    name: str
    dominant_frequency_hz: float
    """Peak of the signal's spectrum in 0.5-20 Hz (or the ``f0_hz`` given)."""
    band_hz: Tuple[float, float]
    """The band-pass: the dominant frequency +-2 Hz."""
    max_rms: float
    stable: bool
    window_centre_m: np.ndarray
    """Centre of each 100 m window along the track [m] (10 m apart), counted from the record's
    first sample (the skipped start-up included: ``skip_s`` at the speed moves them along)."""
    rms: np.ndarray
    """rms of the band-passed signal in each window (unit of the assessment)."""


@dataclass(frozen=True)
class StabilityAssessment:
    """The verdict of :func:`assess_stability` over all its signals."""

    quantity: str
    unit: str
    """``m/s2`` (acceleration) or ``kN`` (sum of guiding forces)."""
    speed_kmh: float
    limit: float
    """EN 14363 limit: (12 - m_bogie/5)/2 m/s2, or (10 + 2 Q0/3)/2 kN."""
    max_rms: float
    stable: bool
    """No window of any signal over the limit."""
    notes: List[str]
    """What could not be checked (no record of how the signals were sampled) or was accepted
    (``accept_narrow_band``)."""
    signals: Dict[str, SignalAssessment]

    def to_pandas(self):
        """The rms of every window: one row per signal and window (``signal``,
        ``window_centre_m``, ``rms``), the limit and unit in ``df.attrs``."""
        import pandas as pd

        df = pd.concat(
            [
                pd.DataFrame({"signal": s.name, "window_centre_m": s.window_centre_m, "rms": s.rms})
                for s in self.signals.values()
            ],
            ignore_index=True,
        )
        df.attrs.update(limit=self.limit, unit=self.unit, speed_kmh=self.speed_kmh)
        return df

    def __repr__(self) -> str:
        verdict = "met" if self.stable else "exceeded"
        return (
            f"<StabilityAssessment {self.quantity} at {self.speed_kmh:g} km/h: max rms "
            f"{self.max_rms:.3f} {self.unit}, limit {self.limit:.3f} {self.unit}: {verdict}>"
        )


def assess_stability(
    source: Union[Results, PathLike],
    signals: Union[str, Sequence[str]],
    speed_kmh: float,
    *,
    quantity: str = "acceleration",
    bogie_mass_t: float = 6.1,
    wheel_load_kn: Optional[float] = None,
    skip_s: float = 0.0,
    f0_hz: Optional[float] = None,
    accept_narrow_band: bool = False,
) -> StabilityAssessment:
    """The EN 14363 rms stability criterion on recorded signals, as the seed's section 4.2 and
    ``master assess`` apply it (the same Rust code): each signal band-passed +-2 Hz around its
    dominant frequency, rms over 100 m of track in 10 m steps at the constant ``speed_kmh``,
    the largest compared with the limit.

    ``source``: the :class:`Results` of a run, or a results file (CSV or Parquet: ours, whose
    metadata record how they were sampled, or a host's export with the time in the first
    column). ``signals``: column names, with or without their `` [unit]``. ``quantity``:
    ``"acceleration"`` (lateral, m/s2; limit from ``bogie_mass_t``, 5.39 m/s2 for the seed's
    6.1 t) or ``"guiding_force"`` (also ``"guiding-force"``: sum of guiding forces of a
    wheelset, N or kN; limit from the static wheel load ``wheel_load_kn``, which it needs: the
    coach's is 54.2 kN, the 2-dof bogie's 70 kN). ``skip_s``: start-up excluded. A signal recorded with
    a narrower band than the one assessed (decimated too far) is refused unless
    ``accept_narrow_band``. A dominant frequency below 2.1 Hz is assessed in a band whose lower
    edge is clamped to 0.1 Hz, with a note.

    The band check needs the record of how the signals were sampled: a file of ours carries it
    (assess the file itself), a run's own :class:`Results` are full rate; a table read back
    into :class:`Results` has lost it, so it is assessed with a note instead of the check.

    Raises :class:`AssessmentError` when the signals cannot be assessed (unknown column, record
    shorter than one window, bad option, narrow band) and :class:`OutputError` when the file
    cannot be read.
    """
    if isinstance(signals, str):
        names = [signals]
    else:
        # any iterable of names: a list, a tuple, a NumPy array or pandas Index of str
        names = list(signals) if isinstance(signals, abc.Iterable) and not isinstance(signals, bytes) else None
        if names is None or not all(isinstance(s, str) for s in names):
            raise TypeError(f"signals must be a column name or a list of column names, got {signals!r}")
    if not isinstance(accept_narrow_band, (bool, np.bool_)):
        raise TypeError(f"accept_narrow_band must be True or False, got {accept_narrow_band!r}")
    if not isinstance(source, (Results, str, bytes, os.PathLike)):
        raise TypeError(
            f"source must be railfmu.Results or the path of a results file, got {type(source).__name__}"
            + (" (a DataFrame: assess the Results it came from, or write it to a CSV file)" if hasattr(source, "columns") else "")
        )
    numbers = {"speed_kmh": speed_kmh, "bogie_mass_t": bogie_mass_t, "skip_s": skip_s}
    if f0_hz is not None:
        numbers["f0_hz"] = f0_hz
    if wheel_load_kn is not None:
        numbers["wheel_load_kn"] = wheel_load_kn
    for key, value in numbers.items():
        # a number, not a text that reads as one (as System.run takes its times)
        if isinstance(value, (str, bytes, bool, np.bool_)) or not isinstance(value, (numbers_abc.Real, np.number)):
            raise TypeError(f"{key} must be a number, got {value!r}")
        if not np.isfinite(float(value)):
            raise _railfmu.AssessmentError(f"{key} = {value}: not a finite number")
    options = json.dumps(
        {
            "signals": names,
            "speed_kmh": float(speed_kmh),
            "quantity": quantity,
            "bogie_mass_t": float(bogie_mass_t),
            "wheel_load_kn": None if wheel_load_kn is None else float(wheel_load_kn),
            "skip_s": float(skip_s),
            "f0_hz": None if f0_hz is None else float(f0_hz),
            "accept_narrow_band": bool(accept_narrow_band),
        },
        allow_nan=False,
    )
    if isinstance(source, Results):
        data = np.ascontiguousarray(source.values, dtype=np.float64).tobytes()
        # the sampling and running speed its metadata records, as for the file it came from
        meta = None if source.metadata is None else json.dumps(source.metadata, default=str)
        answer = _railfmu.assess_columns(source.header, data, source.full_rate, options, meta)
    else:
        answer = _railfmu.assess_file(os.fspath(source), options)
    a = json.loads(answer)
    return StabilityAssessment(
        quantity=a["quantity"],
        unit=a["unit"],
        speed_kmh=a["speed_kmh"],
        limit=a["limit"],
        max_rms=a["max_rms"],
        stable=a["stable"],
        notes=list(a["notes"]),
        signals={
            s["name"]: SignalAssessment(
                name=s["name"],
                dominant_frequency_hz=s["dominant_frequency_hz"],
                band_hz=tuple(s["band_hz"]),
                max_rms=s["max_rms"],
                stable=s["stable"],
                window_centre_m=np.asarray(s["window_centre_m"], dtype=np.float64),
                rms=np.asarray(s["rms"], dtype=np.float64),
            )
            for s in a["signals"]
        },
    )
