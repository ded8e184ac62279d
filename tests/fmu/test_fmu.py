"""Tests of TissueSim.fmu through fmpy: validation, simulation, FMU states, several instances,
argument checks, logging and resource locations."""

import ctypes
import math
import pathlib
import random
import struct
import shutil
import subprocess
import sys
import urllib.parse
from ctypes import byref, c_double, c_int

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CoSimulation, fmi2False, fmi2LastSuccessfulTime, fmi2Terminated

from conftest import Recorder

FORCE = ["force_x", "force_y", "force_z"]
OUTPUTS_REAL = FORCE + ["torque_x", "torque_y", "torque_z", "volume", "volume_ratio",
                        "max_displacement", "max_penetration"]

# Default probe position (start values): ~1.7 cm in front (+z) of the organ's right lobe.
Z_OUT = 0.095
# Pressed position: the probe surface ~2.8 cm (about 20 % of the organ's depth) into the face.
Z_IN = 0.05
H = 0.01  # communication step (s)


def press_z(t):
    """Probe z: rest 0.3 s, press (-z) over 0.5 s, hold 0.1 s, release over 0.3 s, rest."""
    if t < 0.3:
        return Z_OUT
    if t < 0.8:
        return Z_OUT + (Z_IN - Z_OUT) * (t - 0.3) / 0.5
    if t < 0.9:
        return Z_IN
    if t < 1.2:
        return Z_IN + (Z_OUT - Z_IN) * (t - 0.9) / 0.3
    return Z_OUT


def outputs(fmu, vr):
    reals = fmu.getReal([vr[n] for n in OUTPUTS_REAL])
    count = fmu.getInteger([vr["contact_count"]])[0]
    return np.array(list(reals) + [count], dtype=float)


def run(fmu, vr, t0, n, y=press_z):
    """n communication steps from t0 following y(t); returns the outputs after each step."""
    rows = []
    t = t0
    for _ in range(n):
        fmu.setReal([vr["tool_pz"]], [y(t + H)])
        fmu.doStep(t, H)
        t += H
        rows.append(outputs(fmu, vr))
    return np.array(rows), t


# --------------------------------------------------------------------------------------------
# Validation and packaging


def test_validate_fmu(fmu_path):
    assert validate_fmu(fmu_path) == []


def test_validate_command_line(fmu_path):
    r = subprocess.run([sys.executable, "-m", "fmpy", "validate", fmu_path],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "No problems found" in r.stdout


def test_archive_layout_and_model_description(md, unzipdir):
    root = pathlib.Path(unzipdir)
    assert (root / "binaries" / "linux64" / "TissueSim.so").is_file()
    assert not (root / "binaries" / "linux64" / "libTissueSim.so").exists()
    assert (root / "resources" / "organ.vtk").is_file()
    scene = (root / "resources" / "scene.txt").read_text()
    assert "youngs_modulus" in scene and "5000.0 [Pa]" in scene
    assert md.fmiVersion == "2.0"
    cs = md.coSimulation
    assert cs.modelIdentifier == "TissueSim"
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert not cs.providesDirectionalDerivative
    units = {u.name for u in md.unitDefinitions}
    assert {"m", "N", "N.m", "m3", "Pa", "kg/m3", "s", "m/s2"} <= units
    by_name = {v.name: v for v in md.modelVariables}
    assert by_name["force_y"].unit == "N" and by_name["force_y"].causality == "output"
    assert by_name["youngs_modulus"].variability == "fixed"
    assert by_name["damping"].variability == "tunable"
    assert by_name["tool_shape"].type == "Enumeration"
    assert by_name["elastic_scheme"].type == "Enumeration"
    assert by_name["volume_scheme"].declaredType.name == "VolumeScheme"
    assert by_name["damping_stiffness"].unit == "s"
    crushed = by_name["crushed_substeps"]
    assert crushed.type == "Integer" and crushed.start == "1"
    assert by_name["contact_count"].type == "Integer"
    assert by_name["mesh"].start == "organ.vtk"


def test_every_fmi2_function_is_exported(unzipdir):
    lib = ctypes.CDLL(str(pathlib.Path(unzipdir) / "binaries" / "linux64" / "TissueSim.so"))
    names = """GetTypesPlatform GetVersion SetDebugLogging Instantiate FreeInstance SetupExperiment
        EnterInitializationMode ExitInitializationMode Terminate Reset GetReal GetInteger
        GetBoolean GetString SetReal SetInteger SetBoolean SetString GetFMUstate SetFMUstate
        FreeFMUstate SerializedFMUstateSize SerializeFMUstate DeSerializeFMUstate
        GetDirectionalDerivative SetRealInputDerivatives GetRealOutputDerivatives DoStep
        CancelStep GetStatus GetRealStatus GetIntegerStatus GetBooleanStatus
        GetStringStatus""".split()
    for name in names:
        assert hasattr(lib, "fmi2" + name), name
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    lib.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    assert lib.fmi2GetVersion() == b"2.0"
    assert lib.fmi2GetTypesPlatform() == b"default"


# --------------------------------------------------------------------------------------------
# Simulation


@pytest.fixture(scope="module")
def press_result(fmu_path):
    times = [0.0, 0.3, 0.8, 0.9, 1.2, 1.6]
    ys = [press_z(t) for t in times]
    signals = np.array(list(zip(times, ys)), dtype=[("time", np.double), ("tool_pz", np.double)])
    return simulate_fmu(fmu_path, start_time=0.0, stop_time=1.6, step_size=H, input=signals,
                        output=OUTPUTS_REAL + ["contact_count", "tool_pz"])


def test_simulation_outputs_are_finite(press_result):
    for name in OUTPUTS_REAL:
        assert np.all(np.isfinite(press_result[name])), name


def test_force_appears_in_contact_and_points_back(press_result):
    r = press_result
    pressed = (r["time"] > 0.75) & (r["time"] < 0.95)
    assert np.all(r["contact_count"][pressed] > 0)
    # The probe presses along -z: the tissue pushes it back along +z.
    assert np.all(r["force_z"][pressed] > 0.5)
    fmag = np.sqrt(r["force_x"] ** 2 + r["force_y"] ** 2 + r["force_z"] ** 2)
    assert fmag[pressed].max() > 1.0
    # Mostly along +z.
    i = np.argmax(fmag)
    assert r["force_z"][i] > 0.7 * fmag[i]


def test_force_vanishes_out_of_contact(press_result):
    r = press_result
    free = (r["time"] < 0.33) | (r["time"] > 1.35)
    assert np.all(r["contact_count"][free] == 0)
    for name in FORCE + ["torque_x", "torque_y", "torque_z"]:
        assert np.all(np.abs(r[name][free]) < 1e-9), name


def test_threads_parameter_gives_bit_identical_outputs(fmu_path, press_result):
    """threads = 2 runs the force pass on two threads; every output is bit for bit the one of
    the default single-threaded run."""
    times = [0.0, 0.3, 0.8, 0.9, 1.2, 1.6]
    ys = [press_z(t) for t in times]
    signals = np.array(list(zip(times, ys)), dtype=[("time", np.double), ("tool_pz", np.double)])
    r = simulate_fmu(fmu_path, start_time=0.0, stop_time=1.6, step_size=H, input=signals,
                     start_values={"threads": 2}, output=OUTPUTS_REAL + ["contact_count", "tool_pz"])
    assert np.any(r["contact_count"] > 0)
    for name in OUTPUTS_REAL + ["contact_count"]:
        assert np.array_equal(r[name], press_result[name]), name


def test_volume_is_conserved_within_one_percent(fmu_path):
    """The volume constraints carry the material's bulk stiffness: nearly incompressible tissue
    (nu = 0.49) keeps its volume within 1% while hanging and being pressed. (At the default
    nu = 0.45 the soft default organ physically changes volume by up to ~1.7% as it sags.)"""
    times = [0.0, 0.3, 0.8, 0.9, 1.2, 1.6]
    ys = [press_z(t) for t in times]
    signals = np.array(list(zip(times, ys)), dtype=[("time", np.double), ("tool_pz", np.double)])
    r = simulate_fmu(fmu_path, start_time=0.0, stop_time=1.6, step_size=H, input=signals,
                     start_values={"poisson_ratio": 0.49}, output=["volume_ratio", "volume",
                                                                    "contact_count"])
    assert np.any(r["contact_count"] > 0)
    assert np.all(np.abs(r["volume_ratio"] - 1.0) < 0.01)
    assert np.all(r["volume"] > 0.0)


def deep_press_z(t):
    """Probe z of a 20 cm press at 0.5 m/s from the default position, and back."""
    return Z_OUT - 0.5 * (t if t <= 0.4 else max(0.0, 0.8 - t))


def deep_press(fmu_path, start_values):
    times = np.arange(0.0, 0.8005, 0.001)
    signals = np.array([(t, deep_press_z(t)) for t in times],
                       dtype=[("time", np.double), ("tool_pz", np.double)])
    return simulate_fmu(fmu_path, start_time=0.0, stop_time=0.8, step_size=0.001,
                        input=signals, start_values=start_values,
                        output=["force_z", "contact_count"])


@pytest.mark.parametrize("settings", [{}, {"crushed_substeps": 2},
                                      {"min_substeps": 2, "damping_stiffness": 3e-4}])
def test_deep_press_settings_keep_a_probe_on_the_tissue_through_a_15_cm_press(fmu_path, settings):
    """With the defaults (where the tissue at the tool is compressed and the probe is narrower
    than the crushed tetrahedra, those steps take twice the substeps), with two substeps wherever
    it is compressed (docs/SETTINGS.md, "Deep presses"), or with two substeps everywhere and
    0.3 ms of stiffness damping, the default scene's probe driven 20 cm along -z at 0.5 m/s stays
    in contact and is pushed back at every step from first contact to 15 cm of travel.
    tests/contact_deep_press.rs measures the geometry on the library."""
    r = deep_press(fmu_path, settings)
    t, count = r["time"], r["contact_count"]
    first = t[np.argmax(count > 0)]
    pressing = (t > first) & (t <= 0.3)
    assert pressing.sum() > 200
    assert np.all(count[pressing] > 0)
    assert np.all(r["force_z"][pressing] > 0.0)


def test_substeps_and_stiffness_damping_reach_the_solver(fmu_path, press_result):
    """min_substeps and damping_stiffness change the run (the same press, other forces), and
    the probe still presses back."""
    times = [0.0, 0.3, 0.8, 0.9, 1.2, 1.6]
    signals = np.array(list(zip(times, [press_z(t) for t in times])),
                       dtype=[("time", np.double), ("tool_pz", np.double)])
    pressed = (press_result["time"] > 0.75) & (press_result["time"] < 0.95)
    default = press_result["force_z"][pressed]
    for start_values in ({"min_substeps": 2}, {"damping_stiffness": 0.0}):
        r = simulate_fmu(fmu_path, start_time=0.0, stop_time=1.6, step_size=H, input=signals,
                         start_values=start_values, output=FORCE + ["contact_count"])
        assert np.all(r["force_z"][pressed] > 0.5), start_values
        assert np.max(np.abs(r["force_z"][pressed] - default)) > 1e-6 * np.max(default), \
            start_values


def test_the_papers_schemes_are_selectable(fmu_path, press_result):
    """elastic_scheme = point_based with volume_scheme = tetrahedra runs the paper's method: the
    same press pushes back with another force than the default's corotated tetrahedra."""
    times = [0.0, 0.3, 0.8, 0.9, 1.2, 1.6]
    signals = np.array(list(zip(times, [press_z(t) for t in times])),
                       dtype=[("time", np.double), ("tool_pz", np.double)])
    r = simulate_fmu(fmu_path, start_time=0.0, stop_time=1.6, step_size=H, input=signals,
                     start_values={"elastic_scheme": 1, "volume_scheme": 1},
                     output=FORCE + ["contact_count", "volume_ratio"])
    pressed = (r["time"] > 0.75) & (r["time"] < 0.95)
    assert np.all(r["contact_count"][pressed] > 0)
    assert np.all(r["force_z"][pressed] > 0.5)
    default = press_result["force_z"][pressed]
    assert np.max(np.abs(r["force_z"][pressed] - default)) > 0.01 * np.max(default)
    assert np.all(np.abs(r["volume_ratio"] - 1.0) < 0.05)


def test_large_communication_step_interpolates_the_tool(slaves, vr):
    """One 0.1 s step moving the probe into the organ ends where ten 0.01 s steps along the same
    straight path end: the pose is interpolated across the internal steps, never teleported."""
    fine = slaves.initialised()
    coarse = slaves.initialised()
    rest = lambda t: Z_OUT
    run(fine, vr, 0.0, 20, rest)
    run(coarse, vr, 0.0, 20, rest)
    target = 0.06
    t = 0.2
    for k in range(1, 11):
        fine.setReal([vr["tool_pz"]], [Z_OUT + (target - Z_OUT) * k / 10])
        fine.doStep(t, H)
        t += H
    coarse.setReal([vr["tool_pz"]], [target])
    coarse.doStep(0.2, 10 * H)
    a, b = outputs(fine, vr), outputs(coarse, vr)
    assert np.all(np.isfinite(b))
    assert b[-1] > 0, "in contact at the end"
    # Same final state up to rounding of the interpolated positions.
    assert abs(a[6] - b[6]) < 1e-6 * a[6]  # volume
    assert abs(a[8] - b[8]) < 1e-3 * a[8] + 1e-9  # max displacement


def test_any_step_size_works(slaves, vr):
    fmu = slaves.initialised()
    t = 0.0
    for h in [1e-4, 3.3e-3, 0.0123, 0.05, 2.5e-3]:
        fmu.doStep(t, h)
        t += h
        assert np.all(np.isfinite(outputs(fmu, vr)))
    assert fmu.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(t, abs=1e-12)
    assert fmu.getBooleanStatus(fmi2Terminated) is False


def test_a_tracking_glitch_is_placed_not_swept(slaves, vr):
    """A tracking glitch: the probe input jumps 9.5 cm into the organ within one 1 ms
    communication step (95 m/s, beyond the solver's tool jump speed), is held there, then jumps
    back out. Every step succeeds (swept at 95 m/s, the tissue pushed along failed the speed
    bound: fmi2Discard on every step until the input moved back), the force output never
    kicks, and the organ keeps its volume."""
    fmu = slaves.initialised()
    h = 1e-3
    t = 0.0
    for z in [Z_OUT] * 10 + [0.0] * 50 + [Z_OUT] * 50:
        fmu.setReal([vr["tool_pz"]], [z])
        fmu.doStep(t, h)  # raises FMICallException on fmi2Discard
        t += h
        y = outputs(fmu, vr)
        assert np.all(np.isfinite(y))
        force = np.linalg.norm(y[0:3])
        assert force < 5.0, f"a {force} N kick at t = {t} s"
        assert abs(y[7] - 1.0) < 0.02, f"volume ratio {y[7]} at t = {t} s"
    assert fmu.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(t, abs=1e-12)


def test_other_tool_shapes(slaves, vr):
    s = math.sqrt(0.5)
    for shape in (1, 2, 3):
        fmu = slaves.initialised(tool_shape=shape, tool_qw=s, tool_qz=s)  # axis along x
        assert fmu.getInteger([vr["tool_shape"]]) == [shape]
        rows, _ = run(fmu, vr, 0.0, 20, lambda t: 0.06)
        assert np.all(np.isfinite(rows))


# --------------------------------------------------------------------------------------------
# FMU states


def test_get_set_state_reproduces_the_run(slaves, vr):
    fmu = slaves.initialised()
    _, t = run(fmu, vr, 0.0, 60)
    state = fmu.getFMUState()
    first, t1 = run(fmu, vr, t, 25)
    fmu.setFMUState(state)
    second, t2 = run(fmu, vr, t, 25)
    fmu.freeFMUState(state)
    assert t1 == t2
    assert first[:, -1].max() > 0, "the replayed window has contact"
    assert np.array_equal(first, second)


def test_serialized_state_continues_in_a_second_instance(slaves, vr):
    a = slaves.initialised()
    _, t = run(a, vr, 0.0, 60)
    state = a.getFMUState()
    data = a.serializeFMUState(state)
    a.freeFMUState(state)
    assert bytes(data[:8]) == b"TSFMUST\0"

    b = slaves.initialised()
    restored = b.deSerializeFMUstate(data)
    b.setFMUState(restored)
    b.freeFMUState(restored)
    assert np.array_equal(outputs(a, vr), outputs(b, vr))
    ra, _ = run(a, vr, t, 25)
    rb, _ = run(b, vr, t, 25)
    assert np.array_equal(ra, rb)


def test_corrupt_serialized_state_is_refused(slaves, vr):
    a = slaves.initialised()
    run(a, vr, 0.0, 3)
    state = a.getFMUState()
    data = bytearray(a.serializeFMUState(state))
    a.freeFMUState(state)
    data[0] ^= 0xFF
    with pytest.raises(FMICallException):
        a.deSerializeFMUstate(bytes(data))


def state_sections(data, md):
    """Byte ranges [start, end) of the sections of a serialised state (format version 2, see
    docs/FMU.md): header, variable values (parameters, inputs, outputs), model (world) state and
    the trailing checksum; and where each variable's value lies."""
    pos = 8 + 4
    (glen,) = struct.unpack_from("<Q", data, pos)
    pos += 8 + glen + 1 + 8 + 8 + 1 + 8 + 1
    (n,) = struct.unpack_from("<I", data, pos)
    pos += 4
    header = (0, pos)
    names = [v.name for v in sorted(md.modelVariables, key=lambda v: v.valueReference)]
    assert n == len(names)
    values = {}
    for name in names:
        tag = data[pos]
        size = {0: 8, 1: 4, 2: 1}.get(tag)
        if size is None:
            (slen,) = struct.unpack_from("<Q", data, pos + 1)
            size = 8 + slen
        values[name] = (pos, pos + 1 + size)
        pos += 1 + size
    sections = {
        "header": header,
        "variables": (header[1], pos),
        "model": (pos, len(data) - 8),
        "checksum": (len(data) - 8, len(data)),
    }
    return sections, values


def test_every_corrupted_bit_is_refused_at_deserialize(slaves, vr, md):
    """Single-bit flips anywhere in a serialised state (every bit of the header, of the variable
    section with the parameters and of the checksum; a seeded sample of the world state) are
    refused by fmi2DeSerializeFMUstate with fmi2Error and a logged message; the instance keeps
    working and the good state still restores."""
    rec = Recorder()
    fmu = slaves.initialised(callbacks=rec.callbacks)
    _, t = run(fmu, vr, 0.0, 40)
    state = fmu.getFMUState()
    data = fmu.serializeFMUState(state)
    fmu.freeFMUState(state)
    assert struct.unpack_from("<I", data, 8)[0] == 2, "format version"
    reference, _ = run(fmu, vr, t, 5)
    good = fmu.deSerializeFMUstate(data)

    sections, values = state_sections(data, md)
    bits = []
    for name in ("header", "variables", "checksum"):
        lo, hi = sections[name]
        bits += range(8 * lo, 8 * hi)
    lo, hi = sections["model"]
    assert hi - lo > 1000, "the world state is in the model section"
    bits += random.Random(20240611).sample(range(8 * lo, 8 * hi), 400)
    # The parameter section is covered, in particular the fixed box (a flip there once
    # restored an organ without its fixed region).
    lo, hi = values["fixed_min_y"]
    assert all(b in bits for b in range(8 * lo, 8 * hi))
    assert len(bits) >= 200

    corrupt = bytearray(data)
    refused = 0
    for k, bit in enumerate(bits):
        corrupt[bit // 8] ^= 1 << (bit % 8)
        before = len(rec.messages)
        with pytest.raises(FMICallException):
            # Every other call reuses the good state: a refused call must leave it intact.
            fmu.deSerializeFMUstate(bytes(corrupt), state=good if k % 2 else None)
        new = rec.messages[before:]
        assert new and new[-1][0] == 3 and "fmi2DeSerializeFMUstate" in new[-1][2], (bit, new)
        if bit >= 8 * 12:  # after magic and version: the checksum catches it
            assert "corrupt" in new[-1][2], (bit, new)
        corrupt[bit // 8] ^= 1 << (bit % 8)
        refused += 1
    assert refused == len(bits) and bytes(corrupt) == data

    # The instance still steps, and the good state (reused above) restores exactly.
    fmu.setReal([vr["tool_pz"]], [press_z(t + 5 * H)])
    fmu.doStep(t + 5 * H, H)
    fmu.setFMUState(good)
    again, _ = run(fmu, vr, t, 5)
    fmu.freeFMUState(good)
    assert np.array_equal(reference, again)


def first_steps(fmu, vr, n):
    """max_displacement and volume at initialisation and after each of n steps (tool at rest,
    out of contact); contact count and force magnitude after each step."""
    names = ["max_displacement", "volume"]
    rows = [list(fmu.getReal([vr[k] for k in names])) + [0, 0.0]]
    t = 0.0
    for _ in range(n):
        fmu.doStep(t, H)
        t += H
        f = np.linalg.norm(fmu.getReal([vr[k] for k in FORCE]))
        rows.append(list(fmu.getReal([vr[k] for k in names]))
                    + [fmu.getInteger([vr["contact_count"]])[0], f])
    return np.array(rows)


def test_settle_starts_the_organ_at_rest(slaves, vr):
    """settle = true: the organ starts in static equilibrium, so over the first 0.1 s it barely
    moves, while without settle it falls into its sag."""
    rec = Recorder()
    settled = first_steps(slaves.initialised(callbacks=rec.callbacks, settle=True), vr, 10)
    swinging = first_steps(slaves.initialised(settle=False), vr, 10)
    drift_settled = np.abs(settled[:, 0] - settled[0, 0]).max()
    drift_swinging = np.abs(swinging[:, 0] - swinging[0, 0]).max()
    dvol_settled = np.abs(settled[:, 1] / settled[0, 1] - 1).max()
    print(f"displacement change over 0.1 s: settled {drift_settled:.3e} m, "
          f"not settled {drift_swinging:.3e} m; initial sag {settled[0, 0]:.4f} m; "
          f"volume change settled {dvol_settled:.2e}")
    assert settled[0, 0] > 0.005, "the settled organ starts sagged, not at its rest shape"
    assert swinging[0, 0] == 0.0
    assert drift_swinging > 0.005
    assert drift_settled < 1e-4
    assert drift_settled < 0.01 * drift_swinging
    assert dvol_settled < 1e-3
    # The tool stays clear: no contact, no force, in both runs.
    assert settled[1:, 2].max() == 0 and settled[1:, 3].max() == 0.0
    assert not any(s == 3 for s, _, _ in rec.messages)


def test_settle_failure_is_an_error_and_can_be_corrected(slaves, vr):
    """A body with no fixed node has no static equilibrium: fmi2ExitInitializationMode fails
    with a logged reason, the instance stays in initialisation mode and can be corrected."""
    rec = Recorder()
    fmu = slaves.new(callbacks=rec.callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    slaves.set(fmu, settle=True, fixed_min_y=1.0)  # empty fixed box
    with pytest.raises(FMICallException):
        fmu.exitInitializationMode()
    errors = [m for s, _, m in rec.messages if s == 3]
    assert any("fmi2ExitInitializationMode" in m and "settle" in m for m in errors), errors
    slaves.set(fmu, fixed_min_y=0.043)
    fmu.exitInitializationMode()
    fmu.doStep(0.0, H)


# --------------------------------------------------------------------------------------------
# Several instances


def test_instances_are_independent(slaves, vr):
    alone = slaves.initialised()
    ref, _ = run(alone, vr, 0.0, 90)

    soft = slaves.initialised()
    stiff = slaves.initialised(youngs_modulus=4.0e4)
    rs, rh = [], []
    t = 0.0
    for _ in range(90):
        for fmu in (soft, stiff):
            fmu.setReal([vr["tool_pz"]], [press_z(t + H)])
            fmu.doStep(t, H)
        t += H
        rs.append(outputs(soft, vr))
        rh.append(outputs(stiff, vr))
    rs, rh = np.array(rs), np.array(rh)
    assert np.array_equal(ref, rs), "an interleaved instance changed another one"
    fy_soft, fy_stiff = rs[:, 2], rh[:, 2]
    assert np.abs(fy_soft).max() > 0.5 and np.abs(fy_stiff).max() > 0.5
    assert np.abs(fy_soft - fy_stiff).max() > 0.1 * np.abs(fy_soft).max()
    assert stiff.getReal([vr["youngs_modulus"]]) == [4.0e4]
    assert soft.getReal([vr["youngs_modulus"]]) == [5.0e3]


# --------------------------------------------------------------------------------------------
# Bad inputs and call sequences


def test_nan_and_inf_inputs_are_refused_and_change_nothing(slaves, vr):
    fmu = slaves.initialised()
    run(fmu, vr, 0.0, 5)
    before = outputs(fmu, vr)
    pose_before = fmu.getReal([vr["tool_px"], vr["tool_pz"]])
    for bad in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(FMICallException) as e:
            fmu.setReal([vr["tool_pz"], vr["tool_px"]], [0.06, bad])
        assert e.value.status == 3
    assert fmu.getReal([vr["tool_px"], vr["tool_pz"]]) == pose_before
    assert np.array_equal(outputs(fmu, vr), before)
    fmu.doStep(5 * H, H)  # still usable, time unchanged by the refused calls


def test_zero_quaternion_fails_the_step_and_changes_nothing(slaves, vr):
    fmu = slaves.initialised()
    run(fmu, vr, 0.0, 5)
    before = outputs(fmu, vr)
    fmu.setReal([vr["tool_qw"], vr["tool_qx"], vr["tool_qy"], vr["tool_qz"]], [0, 0, 0, 0])
    with pytest.raises(FMICallException) as e:
        fmu.doStep(5 * H, H)
    assert e.value.status == 3
    assert np.array_equal(outputs(fmu, vr), before)
    fmu.setReal([vr["tool_qw"]], [2.0])  # normalised on use
    fmu.doStep(5 * H, H)  # the failed step did not advance time


def test_zero_quaternion_at_initialisation(slaves, vr):
    fmu = slaves.new()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([vr["tool_qw"]], [0.0])
    with pytest.raises(FMICallException):
        fmu.exitInitializationMode()
    fmu.setReal([vr["tool_qw"]], [1.0])
    fmu.exitInitializationMode()


def test_illegal_call_sequences(slaves, vr):
    fmu = slaves.new()
    with pytest.raises(FMICallException):
        fmu.doStep(0.0, H)
    with pytest.raises(FMICallException):
        fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        fmu.getReal([vr["force_y"]])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    with pytest.raises(FMICallException):
        fmu.doStep(0.0, H)
    with pytest.raises(FMICallException):
        fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, H)
    with pytest.raises(FMICallException):
        fmu.doStep(0.5, H)  # wrong communication point
    with pytest.raises(FMICallException):
        fmu.doStep(H, -H)
    fmu.terminate()
    with pytest.raises(FMICallException):
        fmu.doStep(H, H)
    fmu.getReal([vr["force_y"]])  # outputs stay readable
    fmu.reset()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, H)


def test_unknown_and_wrong_value_references(slaves, vr):
    fmu = slaves.initialised()
    with pytest.raises(FMICallException):
        fmu.getReal([12345])
    with pytest.raises(FMICallException):
        fmu.setReal([12345], [1.0])
    with pytest.raises(FMICallException):
        fmu.getReal([vr["contact_count"]])  # an Integer through fmi2GetReal
    with pytest.raises(FMICallException):
        fmu.getInteger([vr["force_x"]])
    with pytest.raises(FMICallException):
        fmu.setReal([vr["force_x"]], [1.0])  # an output
    with pytest.raises(FMICallException):
        fmu.setReal([vr["youngs_modulus"]], [1.0e4])  # fixed, after initialisation
    with pytest.raises(FMICallException):
        fmu.setInteger([vr["tool_shape"]], [7])  # not an item of the enumeration
    with pytest.raises(FMICallException):
        fmu.setReal([vr["poisson_ratio"]], [0.7])  # outside [min, max]
    fmu.setReal([vr["damping"]], [5.0])  # tunable
    fmu.doStep(0.0, H)


def test_unsupported_functions_fail_cleanly(slaves, vr):
    fmu = slaves.initialised()
    value = (c_double * 1)()
    refs = (ctypes.c_uint * 1)(vr["force_y"])
    known = (ctypes.c_uint * 1)(vr["tool_pz"])
    dv = (c_double * 1)(1.0)
    with pytest.raises(FMICallException):
        fmu.fmi2GetDirectionalDerivative(fmu.component, refs, 1, known, 1, dv, value)
    with pytest.raises(FMICallException):
        fmu.fmi2CancelStep(fmu.component)
    order = (c_int * 1)(1)
    with pytest.raises(FMICallException):
        fmu.fmi2GetRealOutputDerivatives(fmu.component, refs, 1, order, value)


# --------------------------------------------------------------------------------------------
# Logging


def test_error_messages_reach_the_logger_with_percent_intact(slaves, vr):
    for proxy, expected in ((True, "100%.vtk"), (False, "100%%.vtk")):
        rec = Recorder(proxy=proxy)
        fmu = slaves.new(callbacks=rec.callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setString([vr["mesh"]], ["missing_100%.vtk"])
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        errors = [m for s, c, m in rec.messages if s == 3]
        assert errors and all(c == "logStatusError" for s, c, m in rec.messages if s == 3)
        assert any(expected in m for m in errors), rec.messages
        # Correct the parameter and retry: initialisation mode was kept.
        fmu.setString([vr["mesh"]], ["organ.vtk"])
        fmu.exitInitializationMode()


def test_debug_logging_categories(slaves, vr):
    rec = Recorder()
    fmu = slaves.new(callbacks=rec.callbacks, logging_on=False)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    assert not any(c == "logModel" for _, c, _ in rec.messages)
    fmu.setDebugLogging(True, ["logCalls"])
    fmu.doStep(0.0, H)
    assert any(c == "logCalls" and "fmi2DoStep" in m for _, c, m in rec.messages)
    with pytest.raises(FMICallException):
        fmu.setDebugLogging(True, ["noSuchCategory"])
    n = len(rec.messages)
    fmu.setDebugLogging(False, [])
    fmu.doStep(H, H)
    assert len(rec.messages) == n


# --------------------------------------------------------------------------------------------
# Resource locations


def instantiate_at(md, unzipdir, uri, name, rec):
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="TissueSim",
                    instanceName=name)
    fmu.callbacks = rec.callbacks
    fmu.component = fmu.fmi2Instantiate(name.encode(), fmi2CoSimulation, md.guid.encode(),
                                        None if uri is None else uri.encode(),
                                        byref(rec.callbacks), fmi2False, fmi2False)
    assert fmu.component, rec.messages
    return fmu


def test_resource_location_variants(md, unzipdir, vr, tmp_path):
    # A copy of the resources under a path that needs percent-encoding.
    odd = tmp_path / "dir with space 100% é" / "resources"
    shutil.copytree(pathlib.Path(unzipdir) / "resources", odd)
    plain = str(odd)
    quoted = urllib.parse.quote(plain)
    variants = [
        odd.as_uri(),
        odd.as_uri() + "/",
        "file:" + quoted,
        "file:" + quoted + "/",
        "file://localhost" + quoted,
        "file://LOCALHOST" + quoted + "/",
    ]
    volumes = []
    for i, uri in enumerate(variants):
        rec = Recorder()
        fmu = instantiate_at(md, unzipdir, uri, f"res{i}", rec)
        try:
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            volumes.append(fmu.getReal([vr["volume"]])[0])
        finally:
            fmu.fmi2FreeInstance(fmu.component)
    assert all(v > 0 for v in volumes)
    assert len(set(volumes)) == 1


def test_missing_or_bad_resource_location(md, unzipdir, vr):
    for uri in (None, "http://example.com/resources", "file://server/share/resources"):
        rec = Recorder()
        fmu = instantiate_at(md, unzipdir, uri, "nores", rec)
        try:
            assert any(s == 1 for s, _, _ in rec.messages), "a warning explains the problem"
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            with pytest.raises(FMICallException):
                fmu.exitInitializationMode()  # organ.vtk cannot be resolved
            assert "resource location" in rec.text()
            # The embedded default organ and absolute paths need no resources.
            absolute = str(pathlib.Path(unzipdir) / "resources" / "organ.vtk")
            fmu.setString([vr["mesh"]], [absolute])
            fmu.exitInitializationMode()
            fmu.doStep(0.0, H)
        finally:
            fmu.fmi2FreeInstance(fmu.component)


def test_wrong_guid_is_refused(md, unzipdir):
    rec = Recorder()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="TissueSim",
                    instanceName="g")
    c = fmu.fmi2Instantiate(b"g", fmi2CoSimulation, b"{00000000-0000-0000-0000-000000000000}",
                            pathlib.Path(unzipdir, "resources").as_uri().encode(),
                            byref(rec.callbacks), fmi2False, fmi2False)
    assert not c
    assert "GUID" in rec.text()


def test_grasp_holds_the_tissue_and_release_lets_go(slaves, vr):
    """grasp = true after pressing into the organ: pulling the tool back out drags the tissue,
    whose pull on the tool (force_z < 0, towards the organ) a free probe does not feel; grasp =
    false lets go."""
    def pull(grasp):
        fmu = slaves.initialised(settle=True)
        t, z = 0.0, Z_OUT
        while fmu.getInteger([vr["contact_count"]])[0] == 0 or z > Z_OUT - 0.035:
            z -= 0.0005
            fmu.setReal([vr["tool_pz"]], [z])
            fmu.doStep(t, H)
            t += H
            assert z > Z_IN, "the probe never touched the organ"
        fmu.setBoolean([vr["grasp"]], [grasp])
        for _ in range(40):  # back out 2 cm at 5 cm/s
            z += 0.0005
            fmu.setReal([vr["tool_pz"]], [z])
            fmu.doStep(t, H)
            t += H
        force_z = fmu.getReal([vr["force_z"]])[0]
        held = fmu.getInteger([vr["grasped_count"]])[0]
        return fmu, t, force_z, held

    free_fmu, _, free_force, free_held = pull(False)
    fmu, t, force, held = pull(True)
    print(f"2 cm pulled back: grasped {held} particles, force_z {force:.3f} N "
          f"(free probe: {free_force:.3f} N, {free_held} held)")
    assert free_held == 0 and held > 0
    assert force < -0.05, "the held tissue pulls the tool back towards the organ"
    assert abs(free_force) < 0.1 * abs(force)
    fmu.setBoolean([vr["grasp"]], [False])
    for _ in range(20):
        fmu.doStep(t, H)
        t += H
    assert fmu.getInteger([vr["grasped_count"]])[0] == 0
    assert abs(fmu.getReal([vr["force_z"]])[0]) < 0.1 * abs(force)


def test_a_needle_punctures_at_its_force_and_reports_its_depth(slaves, vr):
    """A 1 mm capsule needle pointing -z (local +y turned onto -z), puncture force 0.3 N,
    pushed into the settled organ at 5 cm/s: before puncture the tissue pushes back on it
    (force_z > 0) and needle_depth is 0; it punctures, and its depth then follows the travel
    past the entry point; a plain probe never reports a depth."""
    half, radius = 0.03, 0.001
    c, s = math.cos(-math.pi / 4), math.sin(-math.pi / 4)
    fmu = slaves.initialised(settle=True, tool_shape=1, tool_radius=radius,
                             tool_half_length=half, needle_puncture_force=0.3,
                             needle_friction=10.0, tool_qw=c, tool_qx=s,
                             tool_pz=Z_OUT + half + radius)
    t, z = 0.0, Z_OUT + half + radius
    pushed_back, entry = 0.0, None
    while z > Z_IN - 0.04:
        z -= 0.0005
        fmu.setReal([vr["tool_pz"]], [z])
        fmu.doStep(t, H)
        t += H
        depth = fmu.getReal([vr["needle_depth"]])[0]
        if entry is None:
            if depth > 0.0:
                entry = z
            else:
                pushed_back = max(pushed_back, fmu.getReal([vr["force_z"]])[0])
        elif entry - z > 0.01:
            break
    assert entry is not None, "the needle never punctured"
    print(f"needle: largest push-back before puncture {pushed_back:.3f} N; "
          f"{depth * 1e3:.1f} mm deep after {(entry - z) * 1e3:.1f} mm more travel")
    assert 0.2 < pushed_back < 0.45, "the tissue pushes back up to about the puncture force"
    assert abs(depth - (entry - z)) < 0.003, "the depth follows the travel past the entry"
    probe = slaves.initialised(settle=True)
    probe.setReal([vr["tool_pz"]], [Z_IN])
    probe.doStep(0.0, H)
    assert probe.getReal([vr["needle_depth"]])[0] == 0.0

