"""Builds an fmpy container FMU (binary: fmpy's container_fmu, not written by this project) that
wraps our MassSpring and SpringDamperMass connected inside it, and simulates it with fmpy.

Usage: python make_container.py DIST_DIR OUT_DIR
Writes OUT_DIR/Container.fmu, Container.system.json, Container.fmpy.csv (see foreign_common.py).

Inside the container (fmpy's implementation): every component steps over the container's fixed
step from the same inputs, then all connections are copied (Jacobi). Its FMI 2.0 interface:
value reference 0 is the time; parameters are forwarded to the components.
"""
import os
import shutil
import sys
import tempfile
import uuid
from pathlib import Path

import attrs

from fmpy import read_model_description
from fmpy.container_fmu import Configuration
from fmpy.container_fmu.cli import create_container_fmu
from fmpy.container_fmu.config import Component, Connection
from fmpy.model_description import CoSimulation, DefaultExperiment, ModelDescription, ModelVariable, Unknown

from foreign_common import write_experiment

STEP = 1e-3
STOP = 2.0


def main(dist, out):
    os.makedirs(out, exist_ok=True)
    ms_path = Path(dist) / "MassSpring.fmu"
    sdm_path = Path(dist) / "SpringDamperMass.fmu"
    ms_md = read_model_description(ms_path)
    sdm_md = read_model_description(sdm_path)
    ms = Component(name="ms", filename=ms_path, modelDescription=ms_md)
    sdm = Component(name="sdm", filename=sdm_path, modelDescription=sdm_md)

    def var(md, name):
        return next(v for v in md.modelVariables if v.name == name)

    md = ModelDescription(
        fmiVersion="2.0",
        modelName="Container",
        instantiationToken="{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "rail-fmu/Container")) + "}",
        description="fmpy container FMU: MassSpring + SpringDamperMass coupled inside",
        coSimulation=CoSimulation(modelIdentifier="container_fmu", fixedInternalStepSize=STEP),
        defaultExperiment=DefaultExperiment(startTime="0.0", stopTime=str(STOP), stepSize=str(STEP)),
    )
    # the units the exposed variables use, as the components define them
    for u in ms_md.unitDefinitions + sdm_md.unitDefinitions:
        if all(d.name != u.name for d in md.unitDefinitions):
            md.unitDefinitions.append(u)
    time = ModelVariable(name="time", type="Real", causality="independent", variability="continuous")
    time.canHandleMultipleSetPerTimeInstant = False
    md.modelVariables.append(time)
    mappings = {}
    # (container name, causality, component, component variable)
    exposed = [
        ("ms_mass", "parameter", ms, "mass"),
        ("coupling_stiffness", "parameter", sdm, "coupling_stiffness"),
        ("ms_position", "output", ms, "position"),
        ("ms_velocity", "output", ms, "velocity"),
        ("sdm_position", "output", sdm, "position"),
        ("coupling_force", "output", sdm, "coupling_force"),
    ]
    for name, causality, comp, cname in exposed:
        inner = var(comp.modelDescription, cname)
        v = ModelVariable(name=name, type="Real", causality=causality, unit=inner.unit)
        # fmpy writes canHandleMultipleSetPerTimeInstant="true" unless False (FMI 2.0 allows it on
        # any variable; it means something only for model exchange). The `fmi` crate the master
        # loads FMUs with (fmi-schema 0.8) rejects it as an unknown field, so leave it out here;
        # tests/tests/foreign_fmus.rs keeps an ignored test that shows the master's limitation.
        v.canHandleMultipleSetPerTimeInstant = False
        if causality == "parameter":
            v.variability = "fixed"
            v.initial = "exact"
            v.start = inner.start
        else:
            v.variability = "continuous"
        md.modelVariables.append(v)
        mappings[v] = [(comp, inner)]
        if causality == "output":
            md.outputs.append(Unknown(variable=v, dependencies=[]))
            md.initialUnknowns.append(Unknown(variable=v, dependencies=[]))

    def conn(a, an, b, bn):
        # fmpy 0.3.32 writes a connection's type as the connector's FMI 2.0 type name ("Real"),
        # which its own container binary rejects ("unknown variant `Real`, expected ...
        # `Float64`"); it converts the name only for exposed variables. Pass connectors typed
        # as the binary expects (only .type and .valueReference are used).
        return Connection(
            startElement=a,
            startConnectors=[attrs.evolve(var(a.modelDescription, an), type="Float64")],
            endElement=b,
            endConnectors=[attrs.evolve(var(b.modelDescription, bn), type="Float64")],
        )

    config = Configuration(
        parallelDoStep=False,
        modelDescription=md,
        components=[ms, sdm],
        connections=[
            conn(ms, "position", sdm, "input_position"),
            conn(ms, "velocity", sdm, "input_velocity"),
            conn(sdm, "coupling_force", ms, "force"),
        ],
        variableMappings=mappings,
    )
    fmu = Path(out) / "Container.fmu"
    if fmu.exists():
        fmu.unlink()
    unzipdir = Path(tempfile.mkdtemp(prefix="container_"))
    try:
        create_container_fmu(config, unzipdir, fmu)
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)

    write_experiment(
        out,
        "Container",
        str(fmu),
        "box",
        {"ms_mass": 2.0, "coupling_stiffness": 300.0},
        0.0,
        STOP,
        STEP,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
