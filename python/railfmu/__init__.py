"""railfmu: the co-simulation master from Python.

Load a system of FMI 2.0 co-simulation FMUs (the master's JSON system description, or an
SSP), set start values, run it, and get the results as NumPy or pandas with their units; run a
run set (a base system plus parameter variations) on local threads or on a Dask cluster; read
result folders back; assess recorded signals by the EN 14363 stability criterion (:func:`assess_stability`).
Every run is the master's own (the same Rust code as the ``master`` command, bit for bit);
the GIL is released while FMUs run. Errors are exceptions carrying the master's messages.

>>> import railfmu
>>> sys = railfmu.System.load("systems/passive.json")
>>> df = sys.run({"bogie.vehicle.speed": 70.0}, stop_time=2.0).to_pandas()
>>> df.attrs["units"]["bogie.wheelset_front.lateral_displacement_relative"]
'm'
"""

from ._assess import SignalAssessment, StabilityAssessment, assess_stability
from ._railfmu import AssessmentError, Error, FmuError, OutputError, SimulationError, SystemDescriptionError
from ._results import Results, RunSetResults, read_results, split_label
from ._runset import RunSet, run_set
from ._system import System
from .dask import SchedulerLostError

# System.run sets it to the run's Results up to the failure; any other SimulationError has none
SimulationError.history = None

__all__ = [
    "AssessmentError",
    "Error",
    "FmuError",
    "OutputError",
    "Results",
    "RunSet",
    "SchedulerLostError",
    "RunSetResults",
    "SignalAssessment",
    "SimulationError",
    "StabilityAssessment",
    "System",
    "SystemDescriptionError",
    "assess_stability",
    "read_results",
    "run_set",
    "split_label",
]
