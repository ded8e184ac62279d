#!/usr/bin/env python3
"""Plots and tables of the paper's experiments (Fig. 6, 7, 9) and of the probe force trace.

    build/venv-validation/bin/python validation/paper_experiments.py [--large build/evidence/large]

Reads what `cargo run --release --example evidence -- {volume,runtime,large,press}` wrote:
  docs/data/volume_time.csv        -> docs/img/volume_time.png,   docs/data/volume_summary.csv   (paper Fig. 6)
  docs/data/runtime.csv            -> docs/img/runtime.png                                      (paper Fig. 7)
  build/evidence/large/*.csv,
  docs/data/large_deformation.csv  -> docs/img/large_<scenario>.png, docs/img/large_trace.png   (paper Fig. 9)
  docs/data/press_trace.csv        -> docs/img/press_trace.png
and prints the tables used in docs/VALIDATION.md. Parts whose input is missing are skipped with a note.
"""
import argparse
import csv
import os

import numpy as np
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    return rows


def col(rows, key, cast=float):
    return np.array([cast(r[key]) for r in rows])


def volume(data, img):
    path = os.path.join(data, 'volume_time.csv')
    if not os.path.exists(path):
        print('skip volume: no', path)
        return
    rows = read(path)
    runs = {}
    for r in rows:
        runs.setdefault(r['run'], []).append(r)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=False)
    summary = []
    t_settle, t_press_end = 1.5, 3.5
    for k, kind in enumerate(['gravity', 'probe']):
        ax = axes[k]
        for vol, style in [('vol', 'C0-'), ('novol', 'C3-'), ('hard', 'C2-')]:
            rr = runs.get('%s_%s' % (kind, vol))
            if not rr:
                continue
            t, v = col(rr, 'time'), col(rr, 'volume_ratio')
            lab = {'vol': 'volume constraints, compliance 1/lambda (default)',
                   'novol': 'no volume constraints',
                   'hard': 'hard volume constraints + full stress (paper)'}[vol]
            ax.plot(t, 100 * (v - 1), style, lw=1.2, label=lab)
            phase = (t > t_settle) & (t <= t_press_end)
            if not phase.any():
                continue
            summary.append(dict(run='%s_%s' % (kind, vol),
                                max_abs_dev_pct=100 * np.abs(v - 1).max(),
                                max_abs_dev_press_hold_pct=100 * np.abs(v[phase] - 1).max(),
                                final_dev_pct=100 * (v[-1] - 1),
                                max_disp_mm=1e3 * col(rr, 'max_displacement').max(),
                                substeps=int(col(rr, 'substeps').max())))
        if kind == 'probe':
            ax.axvspan(1.5, 2.5, color='0.9', label='probe in (20% of thickness)')
            ax.axvspan(2.5, 3.5, color='0.8', label='hold')
            ax.axvspan(3.5, 4.5, color='0.9')
        ax.axhline(1, color='k', ls=':', lw=0.8)
        ax.axhline(-1, color='k', ls=':', lw=0.8)
        ax.set_xlabel('time [s]')
        ax.set_ylabel('V / V0 - 1 [%]')
        ax.set_title('liver_4k, top 10% fixed, ' + ('gravity' if kind == 'gravity' else 'gravity + probe'))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(img, 'volume_time.png'), dpi=120)
    plt.close(fig)
    with open(os.path.join(data, 'volume_summary.csv'), 'w', newline='') as fh:
        w = csv.DictWriter(fh, fieldnames=list(summary[0].keys()))
        w.writeheader()
        for s in summary:
            w.writerow({k: ('%.4f' % v if isinstance(v, float) else v) for k, v in s.items()})
    print('\n| run | max abs(V/V0-1) | max during press+hold | at t = 5 s | max displacement | substeps |')
    print('|---|---|---|---|---|---|')
    for s in summary:
        print('| %s | %.3f%% | %.3f%% | %+.3f%% | %.1f mm | %d |' % (
            s['run'], s['max_abs_dev_pct'], s['max_abs_dev_press_hold_pct'], s['final_dev_pct'], s['max_disp_mm'],
            s['substeps']))


def runtime(data, img):
    path = os.path.join(data, 'runtime.csv')
    if not os.path.exists(path):
        print('skip runtime: no', path)
        return
    rows = read(path)
    meshes = list(dict.fromkeys(r['mesh'] for r in rows))
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    x = np.arange(len(meshes))
    for k, (vol, lab) in enumerate([('true', 'with volume constraints'), ('false', 'without volume constraints')]):
        rr = [next(r for r in rows if r['mesh'] == m and r['volume_constraints'] == vol) for m in meshes]
        mean, p99 = [float(r['mean_ms']) for r in rr], [float(r['p99_ms']) for r in rr]
        bars = ax.bar(x + (k - 0.5) * 0.38, mean, 0.38, label=lab + ' (mean)')
        ax.bar_label(bars, fmt='%.2f', fontsize=7)
        ax.plot(x + (k - 0.5) * 0.38, p99, 'k_', ms=14, mew=2, label='p99' if k == 0 else None)
    ax.axhline(1.0, color='k', ls='--', lw=1, label='1 ms (1 kHz)')
    ax.set_xticks(x, ['%s\n%s nodes' % (m, next(r['nodes'] for r in rows if r['mesh'] == m)) for m in meshes])
    ax.set_ylabel('ms per step (dt = 1 ms)')
    ax.set_title('Runtime, DESIGN section 7 scene, probe pressing')
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(img, 'runtime.png'), dpi=120)
    plt.close(fig)
    print('\n| mesh | nodes | tets | volume constraints | substeps | mean ms | p50 | p99 | max |')
    print('|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        print('| %s | %s | %s | %s | %s | %.3f | %.3f | %.3f | %.3f |' % (
            r['mesh'], r['nodes'], r['tets'], r['volume_constraints'], r['substeps'], float(r['mean_ms']),
            float(r['p50_ms']), float(r['p99_ms']), float(r['max_ms'])))


def render(ax, x, tris, title, lim, disp, vmax):
    polys = x[tris]
    n = np.cross(polys[:, 1] - polys[:, 0], polys[:, 2] - polys[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-30
    light = np.array([0.2, 0.6, 0.8])  # from above and from the front (+z), where the viewer is
    shade = 0.45 + 0.55 * np.clip(n @ (light / np.linalg.norm(light)), 0, 1)
    colors = plt.get_cmap('viridis')(np.clip(disp[tris].mean(1) / vmax, 0, 1))[:, :3] * shade[:, None]
    # Plot x -> x, z -> depth, y -> up.
    pc = Poly3DCollection(polys[:, :, [0, 2, 1]], facecolors=colors, edgecolors='none')
    ax.add_collection3d(pc)
    (lo, hi) = lim
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[2], hi[2])
    ax.set_zlim(lo[1], hi[1])
    ax.set_box_aspect((hi[0] - lo[0], hi[2] - lo[2], hi[1] - lo[1]))
    ax.view_init(elev=20, azim=65)
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)


def large(data, img, large_dir):
    summ = os.path.join(data, 'large_deformation.csv')
    tri_path = os.path.join(large_dir, 'boundary_triangles.csv')
    if not (os.path.exists(summ) and os.path.exists(tri_path)):
        print('skip large: no', summ, 'or', tri_path)
        return
    tris = np.loadtxt(tri_path, delimiter=',', skiprows=1, dtype=int)
    rows = read(summ)
    titles = {'press': 'probe pressing 45% of the thickness', 'sweep': 'capsule sweeping 40% of the width',
              'pull': 'grasped patch pulled 5.8 cm, then released'}
    for r in rows:
        name = r['scenario']
        snaps = []
        for tag in ['settled', 'peak', 'released']:
            p = os.path.join(large_dir, '%s_%s.csv' % (name, tag))
            if os.path.exists(p):
                snaps.append((tag, np.loadtxt(p, delimiter=',', skiprows=1)))
        allx = np.vstack([s[1] for s in snaps])
        lim = (allx.min(0) - 0.005, allx.max(0) + 0.005)
        fig = plt.figure(figsize=(11, 3.8))
        x0 = snaps[0][1]
        vmax = max(np.linalg.norm(x - x0, axis=1).max() for _, x in snaps)
        for k, (tag, x) in enumerate(snaps):
            ax = fig.add_subplot(1, len(snaps), k + 1, projection='3d')
            label = {'settled': 'settled under gravity', 'peak': 'largest deformation',
                     'released': 'after release + 2 s'}[tag]
            render(ax, x, tris, label, lim, np.linalg.norm(x - x0, axis=1), vmax)
        fig.suptitle('%s: %s (colour: displacement from settled, 0 to %.0f mm; inverted tets after release: %s, '
                     'recovered %s%%)' % (name, titles.get(name, ''), 1e3 * vmax, r['inverted_tets_after_release'],
                                          r['recovered_pct']), fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(img, 'large_%s.png' % name), dpi=110)
        plt.close(fig)
    trace_path = os.path.join(large_dir, 'large_trace.csv')
    if os.path.exists(trace_path):
        tr = read(trace_path)
        fig, axes = plt.subplots(1, 3, figsize=(12, 3.5))
        for name in dict.fromkeys(r['scenario'] for r in tr):
            rr = [r for r in tr if r['scenario'] == name]
            t = col(rr, 'time')
            axes[0].plot(t, 1e3 * col(rr, 'max_disp_from_settled'), label=name)
            axes[1].plot(t, 100 * (col(rr, 'volume_ratio') - 1), label=name)
            axes[2].plot(t, col(rr, 'min_tet_volume_ratio'), label=name)
        axes[0].set_ylabel('max displacement from settled [mm]')
        axes[1].set_ylabel('V / V0 - 1 [%]')
        axes[2].set_ylabel('smallest tet V / V0')
        for ax in axes:
            ax.set_xlabel('time [s]')
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(img, 'large_trace.png'), dpi=110)
        plt.close(fig)
    print('\n| scenario | peak displacement | left after release | recovered | worst inverted tets | '
          'smallest tet V/V0 | worst abs(V/V0-1) | inverted after release | V/V0 after | diverged steps | NaN |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        print('| %s | %.1f mm | %.2f mm | %s%% | %s | %s | %s%% | %s | %s | %s | %s |' % (
            r['scenario'], 1e3 * float(r['peak_disp_m']), 1e3 * float(r['end_disp_m']), r['recovered_pct'],
            r['worst_inverted_tets'], r['worst_min_tet_ratio'], r['worst_volume_error_pct'],
            r['inverted_tets_after_release'], r['volume_ratio_after_release'], r['diverged_steps'], r['non_finite']))


def press(data, img):
    path = os.path.join(data, 'press_trace.csv')
    if not os.path.exists(path):
        print('skip press: no', path)
        return
    rows = read(path)
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    print('\n| contact mode | peak abs(f) | mean abs(f) over the hold | mean f_z over the hold | '
          'step-to-step RMS change over the hold | contacts at full depth |')
    print('|---|---|---|---|---|---|')
    for mode, st in [('exact', 'C0'), ('sampled', 'C3')]:
        rr = [r for r in rows if r['mode'] == mode]
        if not rr:
            continue
        t = col(rr, 'time')
        f, fz = col(rr, 'f'), col(rr, 'fz')
        axes[0].plot(t, f, color=st, lw=1, label='|f| ' + mode)
        axes[0].plot(t, fz, color=st, lw=0.8, ls='--', label='f_z ' + mode)
        axes[1].plot(t, col(rr, 'contact_count'), color=st, lw=1, label=mode)
        axes[2].plot(t, 100 * (col(rr, 'volume_ratio') - 1), color=st, lw=1, label=mode)
        hold = (t > 1.0) & (t < 1.5)
        print('| %s | %.3f N | %.3f N | %.3f N | %.4f N | %d |' % (
            mode, f.max(), f[hold].mean(), fz[hold].mean(), np.sqrt(np.mean(np.diff(f[hold]) ** 2)),
            int(col(rr, 'contact_count')[hold].max())))
    depth = col([r for r in rows if r['mode'] == 'exact'], 'depth')
    ax2 = axes[0].twinx()
    ax2.plot(col([r for r in rows if r['mode'] == 'exact'], 'time'), 1e3 * depth, 'k:', lw=1)
    ax2.set_ylabel('probe depth [mm] (dotted)')
    axes[0].set_ylabel('force on the probe [N]')
    axes[0].set_title('1 cm sphere probe pressed 2 cm into liver_4k (DESIGN section 7 scene), dt 1 ms')
    axes[1].set_ylabel('contact count')
    axes[2].set_ylabel('V / V0 - 1 [%]')
    axes[2].set_xlabel('time since the probe starts [s]')
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc='upper right')
    fig.tight_layout()
    fig.savefig(os.path.join(img, 'press_trace.png'), dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--docs', default=os.path.join(ROOT, 'docs'))
    ap.add_argument('--large', default=os.path.join(ROOT, 'build', 'evidence', 'large'))
    args = ap.parse_args()
    data, img = os.path.join(args.docs, 'data'), os.path.join(args.docs, 'img')
    os.makedirs(img, exist_ok=True)
    volume(data, img)
    runtime(data, img)
    large(data, img, args.large)
    press(data, img)


if __name__ == '__main__':
    main()
