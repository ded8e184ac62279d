#!/usr/bin/env python3
"""Drive TissueSim.fmu from Python with fmpy: a spherical probe presses the default organ and
releases it; the contact force is printed as a table.

    fmu/test.sh                       # or: cargo run --release -p tissuesim-fmu --bin build-fmu
    build/venv-fmu/bin/python fmu/examples/fmpy_probe.py [--fmu target/fmu/TissueSim.fmu]

This is the loop of any co-simulation master: set the tool pose (inputs), fmi2DoStep, read the
wrench and volume (outputs). The FMU sub-steps each communication step at `internal_step` and
moves the probe linearly from its previous pose to the new one, so the communication step can
be any size.
"""

import argparse
import math
import os
import pathlib

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = pathlib.Path(__file__).resolve().parents[2]


def default_fmu():
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return str((ROOT / target) / "fmu" / "TissueSim.fmu")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--fmu", default=default_fmu(), help="path of TissueSim.fmu")
    p.add_argument("--step", type=float, default=0.01, help="communication step (s)")
    p.add_argument("--duration", type=float, default=2.0, help="simulated time (s)")
    p.add_argument("--depth", type=float, default=0.045, help="probe travel along -z (m)")
    p.add_argument("--youngs-modulus", type=float, default=5.0e3, help="E of the organ (Pa)")
    p.add_argument("--every", type=int, default=5, help="print every N steps")
    args = p.parse_args()

    md = read_model_description(args.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    start = {v.name: v.start for v in md.modelVariables}
    unzipdir = extract(args.fmu)

    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="probe")
    fmu.instantiate(loggingOn=False)
    fmu.setupExperiment(startTime=0.0, stopTime=args.duration)
    fmu.enterInitializationMode()
    # Fixed parameters are set before the end of initialisation; the world is built then.
    fmu.setReal([vr["youngs_modulus"]], [args.youngs_modulus])
    fmu.exitInitializationMode()

    x0, y0, z0 = (float(start[n]) for n in ("tool_px", "tool_py", "tool_pz"))
    wrench = [vr[n] for n in ("force_x", "force_y", "force_z", "volume_ratio")]

    print(f"{'t [s]':>7} {'probe z [m]':>12} {'Fx [N]':>9} {'Fy [N]':>9} {'Fz [N]':>9} "
          f"{'contacts':>8} {'V/V0':>8}")
    t = 0.0
    n = int(round(args.duration / args.step))
    for i in range(n):
        # Press along -z with a smooth half-sine profile over the middle of the run, then back.
        s = min(max((t + args.step) / args.duration, 0.0), 1.0)
        z = z0 - args.depth * math.sin(math.pi * s) ** 2
        fmu.setReal([vr["tool_px"], vr["tool_py"], vr["tool_pz"]], [x0, y0, z])
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=args.step)
        t += args.step
        fx, fy, fz, ratio = fmu.getReal(wrench)
        (contacts,) = fmu.getInteger([vr["contact_count"]])
        if i % args.every == 0 or i == n - 1:
            print(f"{t:7.3f} {z:12.4f} {fx:9.3f} {fy:9.3f} {fz:9.3f} {contacts:8d} {ratio:8.5f}")

    fmu.terminate()
    fmu.freeInstance()


if __name__ == "__main__":
    main()
