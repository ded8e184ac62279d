"""Fixtures for the TissueSim FMU tests (run through fmu/test.sh, which builds the FMU).

The FMU is taken from $TISSUESIM_FMU, else from <target dir>/fmu/TissueSim.fmu with the target
directory $CARGO_TARGET_DIR or target/.
"""

import os
import pathlib
from ctypes import byref

import pytest
from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

ROOT = pathlib.Path(__file__).resolve().parents[2]


def fmu_file() -> pathlib.Path:
    if os.environ.get("TISSUESIM_FMU"):
        return pathlib.Path(os.environ["TISSUESIM_FMU"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    return target / "fmu" / "TissueSim.fmu"


@pytest.fixture(scope="session")
def fmu_path() -> str:
    path = fmu_file()
    if not path.is_file():
        pytest.fail(f"{path} not found: build it with fmu/test.sh or "
                    "`cargo run --release -p tissuesim-fmu --bin build-fmu`")
    return str(path)


@pytest.fixture(scope="session")
def md(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory):
    return extract(fmu_path, unzipdir=str(tmp_path_factory.mktemp("fmu")))


@pytest.fixture(scope="session")
def vr(md):
    """Variable name -> value reference."""
    return {v.name: v.valueReference for v in md.modelVariables}


# Every Recorder ever made, kept alive for the whole session: fmpy's native logger proxy keeps
# the Python logger of the last `addLoggerProxy` call in a global and calls it for every
# proxied callback struct (fmpy's default callbacks included), so a recorder's ctypes callback
# freed by the garbage collector would later be called from C (a segmentation fault whose
# timing depends on when the collector runs).
_RECORDERS = []


class Recorder:
    """fmi2CallbackFunctions whose logger records (status, category, message).

    With proxy=True, fmpy's native proxy formats the message with vsnprintf first, as a C
    master does; with proxy=False the raw format string arrives.
    """

    def __init__(self, proxy=True):
        _RECORDERS.append(self)
        self.messages = []

        def logger(env, name, status, category, message):
            self.messages.append((status, category.decode(), message.decode()))

        self._logger = fmi2CallbackLoggerTYPE(logger)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._logger
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        if proxy:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(byref(self.callbacks))

    def text(self):
        return "\n".join(m for _, _, m in self.messages)


@pytest.fixture
def recorder():
    return Recorder()


class Slaves:
    """Creates FMU2Slave instances and frees them at the end of the test."""

    def __init__(self, md, unzipdir):
        self.md = md
        self.unzipdir = unzipdir
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.live = []
        self.count = 0

    def new(self, callbacks=None, logging_on=False):
        self.count += 1
        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                        modelIdentifier="TissueSim", instanceName=f"inst{self.count}")
        fmu.instantiate(callbacks=callbacks, loggingOn=logging_on)
        self.live.append(fmu)
        return fmu

    def set(self, fmu, **values):
        for name, value in values.items():
            ref = [self.vr[name]]
            if isinstance(value, bool):
                fmu.setBoolean(ref, [value])
            elif isinstance(value, int):
                fmu.setInteger(ref, [value])
            elif isinstance(value, str):
                fmu.setString(ref, [value])
            else:
                fmu.setReal(ref, [float(value)])

    def initialised(self, callbacks=None, **params):
        fmu = self.new(callbacks=callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        self.set(fmu, **params)
        fmu.exitInitializationMode()
        return fmu

    def close(self):
        for fmu in self.live:
            try:
                fmu.fmi2FreeInstance(fmu.component)
            except Exception:
                pass
        self.live.clear()


@pytest.fixture
def slaves(md, unzipdir):
    s = Slaves(md, unzipdir)
    yield s
    s.close()
