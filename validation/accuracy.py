#!/usr/bin/env python3
"""Accuracy of the point-based solver against the scikit-fem references
(the figures of docs/history/VALIDATION_HISTORY.md §1).

    build/venv-validation/bin/python validation/accuracy.py [--runs build/evidence/accuracy]

Reads the static equilibria written by `cargo run --release --example evidence -- accuracy --out DIR`
(DIR/runs.csv and one `node,ux,uy,uz` CSV per run), compares each with the P2 reference of its scene using
validation/compare.py, and writes
  docs/data/accuracy.csv          every run: settings, convergence, relative L2 / max-norm error vs P2
  docs/data/accuracy_tables.md    the tables of docs/VALIDATION.md
  docs/img/accuracy_errors.png    point-based with / without volume constraints vs linear-tet FEM (P1)
  docs/img/accuracy_sweep.png     liver nu 0.3: error vs neighbour count and vs hourglass stiffness
  docs/img/cantilever_deflection.png  beam deflection along x
"""
import argparse
import csv
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from compare import align, max_norm, read_csv, relative_l2  # noqa: E402

import matplotlib  # noqa: E402
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

REF = os.path.join(HERE, 'reference')
REFERENCES = {
    'cantilever': ('cantilever_p2_lattice.csv', 'cantilever_p1_lattice.csv'),
    'liver030': ('liver4k_nu030_p2.csv', 'liver4k_nu030_p1.csv'),
    'liver045': ('liver4k_nu045_p2.csv', 'liver4k_nu045_p1.csv'),
}
SCENE_TITLE = {'cantilever': 'cantilever (nu 0.3)', 'liver030': 'liver_4k sag, nu 0.30',
               'liver045': 'liver_4k sag, nu 0.45'}
GOAL = 0.03


def load(path, ref_path):
    ids, u = read_csv(path)
    ids_r, ur = read_csv(ref_path)
    return align(ids, u, ids_r, ur), ur, ids_r


def tip_deflection(ids, u):
    """Area average (trapezoid weights) of u_y over the lattice nodes of the end face x = L (i = 20)."""
    i, rest = ids % 21, ids // 21
    j, k = rest % 5, rest // 5
    face = i == 20
    w = np.where((j[face] == 0) | (j[face] == 4), 0.5, 1.0) * np.where((k[face] == 0) | (k[face] == 4), 0.5, 1.0)
    return float((u[face, 1] * w).sum() / w.sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--runs', default=os.path.join(ROOT, 'build', 'evidence', 'accuracy'))
    ap.add_argument('--docs', default=os.path.join(ROOT, 'docs'))
    args = ap.parse_args()
    data_dir, img_dir = os.path.join(args.docs, 'data'), os.path.join(args.docs, 'img')
    os.makedirs(data_dir, exist_ok=True)
    os.makedirs(img_dir, exist_ok=True)

    with open(os.path.join(args.runs, 'runs.csv')) as fh:
        runs = list(csv.DictReader(fh))
    p1_err = {}
    for scene, (p2, p1) in REFERENCES.items():
        u1, u2, _ = load(os.path.join(REF, p1), os.path.join(REF, p2))
        p1_err[scene] = (relative_l2(u1, u2), max_norm(u1, u2)[1])
    cant = json.load(open(os.path.join(REF, 'cantilever.json')))['tip_deflection']

    rows = []
    for r in runs:
        p2 = os.path.join(REF, REFERENCES[r['scene']][0])
        u, ur, ids = load(os.path.join(args.runs, r['csv']), p2)
        a = float((u * ur).sum() / (ur * ur).sum())  # best scalar fit u ~ a u_ref
        row = dict(r)
        row.update(rel_l2=relative_l2(u, ur), max_rel=max_norm(u, ur)[1],
                   max_u_ref=float(np.linalg.norm(ur, axis=1).max()),
                   stiffness_scale=1.0 / a, shape_error=relative_l2(u / a, ur))
        if r['scene'] == 'cantilever':
            row['tip_uy'] = tip_deflection(ids, u)
        rows.append(row)
    keys = list(runs[0].keys()) + ['rel_l2', 'max_rel', 'max_u_ref', 'stiffness_scale', 'shape_error', 'tip_uy']
    with open(os.path.join(data_dir, 'accuracy.csv'), 'w', newline='') as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction='ignore')
        w.writeheader()
        for row in rows:
            w.writerow({k: (('%.6g' % v) if isinstance(v, float) else v) for k, v in row.items()})
    by = {r['name']: r for r in rows}

    # Tables.
    md = []
    md.append('### Point-based (with / without volume constraints) vs linear-tet FEM, relative L2 vs P2\n')
    md.append('| scene | with volume constraints | without | P1 (linear tets) | goal |')
    md.append('|---|---|---|---|---|')
    for scene in REFERENCES:
        v, nv = by.get(scene + '_vol'), by.get(scene + '_novol')
        md.append('| %s | %.1f%% (max %.1f%%) | %.1f%% (max %.1f%%) | %.1f%% (max %.1f%%) | %s |' % (
            SCENE_TITLE[scene], 100 * v['rel_l2'], 100 * v['max_rel'], 100 * nv['rel_l2'], 100 * nv['max_rel'],
            100 * p1_err[scene][0], 100 * p1_err[scene][1], '3%' if scene != 'cantilever' else '-'))
    md.append('\n(max = largest nodal error relative to the largest reference displacement)\n')
    md.append('### Convergence and global stiffness of those runs\n')
    md.append('| run | substeps/step | steps | residual v/(alpha max|u|) | max|u| / max|u_ref| | stiffness ratio 1/a | shape error after scaling |')
    md.append('|---|---|---|---|---|---|---|')
    for scene in REFERENCES:
        for tag in ('_vol', '_novol'):
            r = by[scene + tag]
            md.append('| %s | %s | %s | %s | %.3f | %.3f | %.1f%% |' % (
                r['name'], r['substeps'], r['steps'], r['residual'], float(r['max_u']) / r['max_u_ref'],
                r['stiffness_scale'], 100 * r['shape_error']))
    md.append('\n### Cantilever tip deflection (area-average u_y at x = L)\n')
    md.append('| solution | tip u_y [m] | / Euler-Bernoulli | / P2 |')
    md.append('|---|---|---|---|')
    eb, p2t = cant['analytic_euler_bernoulli'], cant['p2']
    tips = [('Euler-Bernoulli', eb), ('Timoshenko', cant['analytic_timoshenko']), ('P2 40x8x8 (reference)', p2t),
            ('P1 20x4x4', cant['p1'])]
    for r in rows:
        if r['scene'] == 'cantilever':
            tips.append(('point-based ' + r['name'].replace('cantilever_', ''), r['tip_uy']))
    for name, t in tips:
        md.append('| %s | %.5f | %.3f | %.3f |' % (name, t, t / eb, t / p2t))
    md.append('\n### Liver nu 0.3 (with volume constraints): neighbours and hourglass stiffness\n')
    md.append('| target_neighbours | hourglass_stiffness | relative L2 vs P2 | max nodal | max|u|/ref | steps |')
    md.append('|---|---|---|---|---|---|')
    sweep = [(int(r['neighbours']), float(r['hourglass']), r) for r in rows
             if r['scene'] == 'liver030' and r['volume_constraints'] == 'true' and r['iterations'] == '1'
             and 'scale' not in r['name']]
    for nb, hg, r in sorted(sweep, key=lambda s: (s[0], s[1])):
        md.append('| %d | %g | %.1f%% | %.1f%% | %.3f | %s |' % (nb, hg, 100 * r['rel_l2'], 100 * r['max_rel'],
                                                               float(r['max_u']) / r['max_u_ref'], r['steps']))
    md.append('\n### Other runs (hourglass on nu 0.45, without constraints, checks of the method)\n')
    md.append('| run | relative L2 vs P2 | max nodal | max|u|/ref | tip u_y / P2 |')
    md.append('|---|---|---|---|---|')
    listed = {s[2]['name'] for s in sweep} | {s + t for s in REFERENCES for t in ('_vol', '_novol')}
    for r in rows:
        if r['name'] in listed:
            continue
        tip = '%.3f' % (r['tip_uy'] / p2t) if 'tip_uy' in r else '-'
        md.append('| %s | %.1f%% | %.1f%% | %.3f | %s |' % (r['name'], 100 * r['rel_l2'], 100 * r['max_rel'],
                                                           float(r['max_u']) / r['max_u_ref'], tip))
    text = '\n'.join(md) + '\n'
    with open(os.path.join(data_dir, 'accuracy_tables.md'), 'w') as fh:
        fh.write(text)
    print(text)

    # Plot: with / without / P1.
    scenes = list(REFERENCES)
    x = np.arange(len(scenes))
    fig, ax = plt.subplots(figsize=(7.5, 4))
    vals = [[100 * by[s + '_vol']['rel_l2'] for s in scenes], [100 * by[s + '_novol']['rel_l2'] for s in scenes],
            [100 * p1_err[s][0] for s in scenes]]
    labels = ['point-based + XPBD volume constraints (default)', 'point-based, no volume constraints',
              'linear-tet FEM (P1)']
    for k, (v, lab) in enumerate(zip(vals, labels)):
        bars = ax.bar(x + (k - 1) * 0.27, v, 0.27, label=lab)
        ax.bar_label(bars, fmt='%.1f', fontsize=7)
    ax.axhline(100 * GOAL, color='k', ls='--', lw=1, label='3% goal (liver)')
    ax.set_xticks(x, [SCENE_TITLE[s] for s in scenes])
    ax.set_ylabel('relative L2 error vs P2 FEM [%]')
    ax.set_title('Static accuracy against quadratic-tet FEM (scikit-fem)')
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(img_dir, 'accuracy_errors.png'), dpi=120)
    plt.close(fig)

    # Plot: sweeps.
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    nbs = sorted((nb, r) for nb, hg, r in sweep if hg == 0.05)
    axes[0].plot([n for n, _ in nbs], [100 * r['rel_l2'] for _, r in nbs], 'o-', label='point-based (hourglass 0.05)')
    axes[0].set_xlabel('BodyOptions::target_neighbours')
    hgs = sorted((hg, r) for nb, hg, r in sweep if nb == 20)
    axes[1].plot([h for h, _ in hgs], [100 * r['rel_l2'] for _, r in hgs], 'o-', label='point-based (20 neighbours)')
    axes[1].set_xscale('symlog', linthresh=0.05)
    axes[1].set_xlabel('Settings::hourglass_stiffness')
    for ax in axes:
        ax.axhline(100 * p1_err['liver030'][0], color='C1', ls=':', label='P1 FEM (%.1f%%)' % (100 * p1_err['liver030'][0]))
        ax.axhline(100 * GOAL, color='k', ls='--', lw=1, label='3% goal')
        ax.set_ylabel('relative L2 vs P2 [%]')
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle('liver_4k sag, nu 0.3, with volume constraints')
    fig.tight_layout()
    fig.savefig(os.path.join(img_dir, 'accuracy_sweep.png'), dpi=120)
    plt.close(fig)

    # Plot: cantilever centreline deflection.
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    xs = np.linspace(0, 0.1, 21)
    L, q = 0.1, 1000 * 9.81 * 4e-4
    EI = 5e4 * 0.02 ** 4 / 12
    ax.plot(xs, -q * xs ** 2 * (6 * L ** 2 - 4 * L * xs + xs ** 2) / (24 * EI), 'k--', lw=1, label='Euler-Bernoulli')

    def centreline(path):
        ids, u = read_csv(path)
        i, rest = ids % 21, ids // 21
        sel = rest == 2 + 5 * 2  # j = 2, k = 2: the beam axis
        order = np.argsort(i[sel])
        return i[sel][order] * 0.005, u[sel, 1][order]
    for path, lab, st in [(os.path.join(REF, 'cantilever_p2_lattice.csv'), 'P2 FEM (reference)', 'k-'),
                          (os.path.join(REF, 'cantilever_p1_lattice.csv'), 'P1 FEM 20x4x4', 'C1:'),
                          (os.path.join(args.runs, 'cantilever_vol.csv'), 'point-based + volume constraints', 'C0o-'),
                          (os.path.join(args.runs, 'cantilever_novol.csv'), 'point-based, no constraints', 'C2s-')]:
        if os.path.exists(path):
            xx, uy = centreline(path)
            ax.plot(xx, uy, st, ms=3, label=lab)
    ax.set_xlabel('x [m]')
    ax.set_ylabel('u_y on the beam axis [m]')
    ax.set_title('Cantilever under gravity (E 50 kPa, 20x4x4 lattice)')
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(img_dir, 'cantilever_deflection.png'), dpi=120)
    plt.close(fig)


if __name__ == '__main__':
    main()
