#!/usr/bin/env python3
"""Force plots of the surgical interactions (pressing, grasping, needle insertion) on the
default organ.

    cargo run --release --example interaction_traces    # writes docs/data/*_trace*.csv
    build/venv-validation/bin/python validation/plot_interaction.py

Reads docs/data/grasp_trace.csv, needle_trace.csv and press_trace_r{10,2.5,1}mm.csv (a missing
one is skipped with a note), writes docs/img/grasp_trace.png, needle_trace.png and
surface_press_trace.png and prints the figures quoted in docs/VALIDATION.md.
"""
import csv
import os

import numpy as np
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, 'docs', 'data')
IMG = os.path.join(ROOT, 'docs', 'img')


def read(name):
    path = os.path.join(DATA, name)
    if not os.path.exists(path):
        print('skip: no', path)
        return None
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def grasp(d):
    t, f, held = d['time_s'], d['force_along_n'], d['grasped']
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(t, f, lw=1.2, label='force along the press (N)')
    ax.set_xlabel('time (s)')
    ax.set_ylabel('force on the tool along the press (N)')
    ax2 = ax.twinx()
    ax2.plot(t, d['travel_m'] * 1e3, 'k--', lw=0.8, label='tool travel (mm)')
    ax2.set_ylabel('tool travel into the organ (mm)')
    on = held > 0
    if on.any():
        ax.axvspan(t[on][0], t[on][-1], color='tab:green', alpha=0.12, label='grasping')
    ax.legend(loc='lower left', fontsize=8)
    ax.set_title('Grasp: press 4 mm, grasp, pull 30 mm out, hold, release')
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, 'grasp_trace.png'), dpi=120)
    deepest = d['travel_m'][held > 0].min()
    pulled = (held > 0) & (d['travel_m'] <= deepest + 1e-9)
    print(f"grasp: {int(held.max())} particles held; pull at full retraction "
          f"{-f[pulled].mean():.3f} N; after release {np.abs(f[t > t[on][-1] + 0.01]).max():.2e} N")


def needle(d):
    t, f = d['time_s'], d['force_along_n']
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(d['travel_m'] * 1e3, f, lw=1.0)
    ax.set_xlabel('needle travel (mm)')
    ax.set_ylabel('axial force on the needle (N)')
    punct = d['punctured'] > 0
    if punct.any():
        k = int(np.argmax(punct))
        ax.axvline(d['travel_m'][k] * 1e3, color='tab:red', lw=0.8, ls=':',
                   label=f'puncture at {f[k]:.3f} N')
        ax.legend(fontsize=8)
        deepest = int(np.argmax(d['inserted_length_m']))
        print(f"needle: puncture at {d['travel_m'][k] * 1e3:.1f} mm of travel, {f[k]:.3f} N; "
              f"{f[k + 20]:.3f} N 20 ms later; {f[deepest]:.3f} N at "
              f"{d['inserted_length_m'][deepest] * 1e3:.1f} mm inserted "
              f"({int(d['held'][deepest])} particles held)")
    else:
        print('needle: no puncture in the trace')
    ax.set_title('Needle: insertion at 2 cm/s, hold, withdrawal')
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, 'needle_trace.png'), dpi=120)


def press(traces):
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for label, d in traces:
        ax.plot(d['depth_m'] * 1e3, d['force_along_n'], lw=1.0, label=label)
        inside = int(d['inside'].sum())
        print(f"press {label}: centre inside on {inside} of {len(d['inside'])} steps; "
              f"{d['force_along_n'][-1]:.3f} N at {d['depth_m'][-1] * 1e3:.1f} mm")
    ax.set_xlabel("sphere front past first contact (mm)")
    ax.set_ylabel('force on the sphere, against the press (N)')
    ax.set_title('Spheres pressed horizontally into the hanging organ at 5 cm/s')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, 'surface_press_trace.png'), dpi=120)


def main():
    os.makedirs(IMG, exist_ok=True)
    traces = []
    for r in ('10', '2.5', '1'):
        d = read(f'press_trace_r{r}mm.csv')
        if d is not None:
            traces.append((f'r = {r} mm', d))
    if traces:
        press(traces)
    d = read('grasp_trace.csv')
    if d is not None:
        grasp(d)
    d = read('needle_trace.csv')
    if d is not None:
        needle(d)


if __name__ == '__main__':
    main()
