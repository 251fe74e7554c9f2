"""Error by theta_d and theta_h band of the round-trip tables (scripts/bench-merl-roundtrip): each
variant's reconstructed table against the demo's table (its truth), and the demo's table against the
bluepaint truth (evaluated by `ibrdf reconstruct --material ... --eval` at the cell centres), over the
MERL cells every table scores (theta_i, theta_e <= 80 degrees at the cell centre, data in every table).
Relative RMS (R, G, B pooled) and, in brackets, the mean signed relative error, in percent.
Usage: merl_roundtrip_bands.py --ibrdf IBRDF --material BLUEPAINT.json --demo TABLE --out OUT VARIANT...
(VARIANT: OUT/VARIANT-rec/brdf.binary is its table)."""
import argparse, subprocess
import numpy as np

SCALE = np.array([1 / 1500, 1.15 / 1500, 1.66 / 1500]).reshape(3, 1, 1, 1)


def read(path):
    return np.fromfile(path, np.float64, offset=12).reshape(3, 90, 90, 180) * SCALE


def cells():
    """Cell-centre angles (degrees) and directions (phi_h = 0), as core/merl_format.cc's MerlCellCentre."""
    th = np.radians(((np.arange(90) + 0.5) / 90) ** 2 * 90)
    td = np.radians(np.arange(90) + 0.5)
    pd = np.radians(np.arange(180) + 0.5)
    TH, TD, PD = np.meshgrid(th, td, pd, indexing='ij')
    dx, dy, dz = np.sin(TD) * np.cos(PD), np.sin(TD) * np.sin(PD), np.cos(TD)
    c, s = np.cos(TH), np.sin(TH)
    wi = np.stack([c * dx + s * dz, dy, -s * dx + c * dz])
    h = np.stack([s, np.zeros_like(s), c])
    wo = 2 * (wi * h).sum(0) * h - wi
    return np.degrees(TH), np.degrees(TD), wi, wo


def main():
    p = argparse.ArgumentParser()
    p.add_argument('--ibrdf', required=True)
    p.add_argument('--material', required=True)
    p.add_argument('--demo', required=True)
    p.add_argument('--out', required=True)
    p.add_argument('variants', nargs='+')
    a = p.parse_args()
    TH, TD, wi, wo = cells()
    inlim = (wi[2] >= np.cos(np.radians(80))) & (wo[2] >= np.cos(np.radians(80)))
    points = np.stack([np.arccos(np.clip(wi[2][inlim], -1, 1)), np.arccos(np.clip(wo[2][inlim], -1, 1)),
                       np.arctan2(wo[1], wo[0])[inlim] - np.arctan2(wi[1], wi[0])[inlim]], 1)
    np.save(f'{a.out}/cells.npy', points)
    subprocess.run([a.ibrdf, '-q', 'reconstruct', '--material', a.material, '--eval', f'{a.out}/cells.npy', '--out',
                    f'{a.out}/truth-eval', '--overwrite'], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    truth = np.full((3, 90, 90, 180), -1.0)
    ev = np.load(f'{a.out}/truth-eval/eval.npy')
    for c in range(3):
        truth[c][inlim] = ev[:, c]
    demo = read(a.demo)
    pairs = [('demo vs bluepaint', demo, truth)] + [(f'{v} vs table', read(f'{a.out}/{v}-rec/brdf.binary'), demo)
                                                    for v in a.variants]
    valid = inlim.copy()
    for _, r, t in pairs:
        valid &= (r > 0).all(0) & (t > 0).all(0)
    errs = [(label, (((r - t) / t) ** 2).mean(0), ((r - t) / t).mean(0)) for label, r, t in pairs]
    print(f'Relative RMS % (mean signed %), R G B pooled, over the {valid.sum()} cells every table scores')
    for name, A, edges in [('theta_d', TD, [0, 10, 20, 40, 60, 65, 70, 75, 78, 80]),
                           ('theta_h', TH, [0, 1, 5, 10, 20, 30, 50, 70, 80])]:
        print()
        print(f'| {name}, deg | cells | ' + ' | '.join(label for label, _, _ in errs) + ' |')
        print('| --- | ---: |' + ' ---: |' * len(errs))
        for lo, hi in list(zip(edges[:-1], edges[1:])) + [(None, None)]:
            m = valid & (A >= lo) & (A < hi) if lo is not None else valid
            if not m.any():
                continue
            band = f'{lo}-{hi}' if lo is not None else 'all'
            print(f'| {band} | {m.sum()} | ' + ' | '.join(f'{100 * np.sqrt(e[m].mean()):.2f} ({100 * mu[m].mean():+.2f})'
                                                          for _, e, mu in errs) + ' |')


if __name__ == '__main__':
    main()
