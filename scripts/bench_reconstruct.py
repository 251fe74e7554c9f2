#!/usr/bin/python3
"""Time against error of `ibrdf reconstruct` and R's locfit on the same samples (scripts/bench-reconstruct).

For every sample count x kernel scale x degree: `ibrdf reconstruct` tabulates the full MERL grid and
evaluates a fixed random set of MERL cell centres (--eval); locfit (scripts/locfit_reconstruct.R) fits
the same samples, in the same folded and radius-scaled (u, v, w) coordinates with the mirror images
ibrdf's estimator uses, in log space, with the same degree and tricube kernel, at the same cell
centres. Errors are relative RMS against the true BRDF at those points (both methods, same points);
locfit's time for the full grid is extrapolated from its time per point. Writes results.csv,
results.md and time_vs_error.png into --out.
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

MERL_EVALUATIONS = 548108  # distinct evaluations of a full MERL table with bilateral sharing (ibrdf summary)


def regression_coordinates(wi, wo):
    """(u, v, w) = (theta_h cos phi_d, theta_h sin phi_d, theta_d), as core/brdf_coords.cc."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    theta_h = np.arccos(np.clip(h[:, 2], -1, 1))
    phi_h = np.arctan2(h[:, 1], h[:, 0])
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    x = c * wi[:, 0] - s * wi[:, 1]
    y = s * wi[:, 0] + c * wi[:, 1]
    z = wi[:, 2]
    c, s = np.cos(-theta_h), np.sin(-theta_h)
    dx, dy, dz = c * x + s * z, y, -s * x + c * z
    theta_d = np.arccos(np.clip(dz, -1, 1))
    phi_d = np.arctan2(dy, dx)
    return np.stack([theta_h * np.cos(phi_d), theta_h * np.sin(phi_d), theta_d], axis=1)


def merl_points(count, seed):
    """Random MERL cell centres with theta_i, theta_e <= 80 degrees: (theta_i, theta_e, delta_phi) and (u, v, w)."""
    rng = np.random.default_rng(seed)
    i = rng.integers(0, 90, 8 * count)
    j = rng.integers(0, 90, 8 * count)
    k = rng.integers(0, 180, 8 * count)
    theta_h = ((i + 0.5) / 90) ** 2 * np.pi / 2
    theta_d = (j + 0.5) / 90 * np.pi / 2
    phi_d = (k + 0.5) / 180 * np.pi
    d = np.stack([np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d), np.cos(theta_d)], axis=1)
    c, s = np.cos(theta_h), np.sin(theta_h)
    wi = np.stack([c * d[:, 0] + s * d[:, 2], d[:, 1], -s * d[:, 0] + c * d[:, 2]], axis=1)
    hv = np.stack([s, np.zeros_like(s), c], axis=1)
    wo = 2 * np.sum(wi * hv, axis=1, keepdims=True) * hv - wi
    limit = math.cos(math.radians(80))
    keep = np.nonzero((wi[:, 2] >= limit) & (wo[:, 2] >= limit))[0][:count]
    wi, wo = wi[keep], wo[keep]
    theta_i = np.arccos(wi[:, 2])
    theta_e = np.arccos(wo[:, 2])
    delta_phi = np.angle(np.exp(1j * (np.arctan2(wo[:, 1], wo[:, 0]) - np.arctan2(wi[:, 1], wi[:, 0]))))
    uvw = np.stack([theta_h[keep] * np.cos(phi_d[keep]), theta_h[keep] * np.sin(phi_d[keep]), theta_d[keep]], axis=1)
    return np.stack([theta_i, theta_e, delta_phi], axis=1), uvw


def scaled_folded(uvw, radius_h_deg, radius_d_deg):
    scale = np.array([1 / math.radians(radius_h_deg)] * 2 + [1 / math.radians(radius_d_deg)])
    p = np.abs(uvw) * scale
    p[:, 2] = uvw[:, 2] * scale[2]
    return p


def with_mirrors(p, values):
    """The folded points plus their mirror images within one kernel radius of the fold lines."""
    parts, vals = [p], [values]
    for su, sv, keep in ((-1, 1, p[:, 0] < 1), (1, -1, p[:, 1] < 1), (-1, -1, (p[:, 0] < 1) & (p[:, 1] < 1))):
        m = p[keep].copy()
        m[:, 0] *= su
        m[:, 1] *= sv
        parts.append(m)
        vals.append(values[keep])
    return np.concatenate(parts), np.concatenate(vals)


def rel_rms(f, truth, valid):
    rel = (f[valid] - truth[valid]) / truth[valid]
    return float(np.sqrt(np.mean(rel ** 2))) if rel.size else float("nan")


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(cmd, log):
    """Runs cmd; returns (wall seconds, CPU seconds of the child, user + system, all threads)."""
    t, c = time.time(), children_cpu()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    with open(log, "w") as f:
        f.write(" ".join(cmd) + "\n" + r.stdout)
    if r.returncode != 0:
        sys.exit("failed (%s): %s\n%s" % (log, " ".join(cmd), r.stdout[-2000:]))
    return time.time() - t, children_cpu() - c


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ibrdf", required=True)
    ap.add_argument("--samples", required=True)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--counts", default="100000,300000,0", help="sample counts (0: all)")
    ap.add_argument("--scales", default="0.7,1,1.4", help="factors on the default radii 2.5 x 9 degrees")
    ap.add_argument("--degrees", default="0,1,2")
    ap.add_argument("--points", type=int, default=80, help="MERL cell centres both methods are scored at")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--no-locfit", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    work = os.path.join(a.out, "work")
    os.makedirs(work, exist_ok=True)

    samples = np.load(a.samples)
    uvw_all = regression_coordinates(samples["wi"].astype(np.float64), samples["wo"].astype(np.float64))
    log_all = np.log(np.maximum(samples["brdf"].astype(np.float64), 1e-6))
    angles, ev_uvw = merl_points(a.points, seed=7)
    ev_path = os.path.join(work, "ev.npy")
    np.save(ev_path, angles)
    rng = np.random.default_rng(3)
    rows = []
    counts = [int(c) or len(samples) for c in a.counts.split(",")]
    for count in counts:
        index = np.sort(rng.permutation(len(samples))[:count])
        subset = os.path.join(work, "samples_%d.npy" % count)
        np.save(subset, samples[index])
        for scale in [float(s) for s in a.scales.split(",")]:
            rh, rd = 2.5 * scale, 9.0 * scale
            x, y = with_mirrors(scaled_folded(uvw_all[index], rh, rd), log_all[index])
            ev = scaled_folded(ev_uvw, rh, rd)
            lf_dir = os.path.join(work, "locfit_%d_%g" % (count, scale))
            os.makedirs(lf_dir, exist_ok=True)
            x.astype("<f8").tofile(os.path.join(lf_dir, "x.f64"))
            y.astype("<f8").tofile(os.path.join(lf_dir, "y.f64"))
            ev.astype("<f8").tofile(os.path.join(lf_dir, "ev.f64"))
            for degree in [int(d) for d in a.degrees.split(",")]:
                configs = [("ibrdf", ["--bin-h", "0.2", "--bin-d", "0.1"])]
                if scale == 1.0 and degree == 2:
                    configs.append(("ibrdf, no binning", ["--bin-h", "0", "--bin-d", "0"]))
                truth = None
                for method, extra in configs:
                    rec = os.path.join(work, "rec")
                    cmd = [a.ibrdf, "--threads", str(a.threads), "reconstruct", subset, "--out", rec, "--overwrite",
                           "--no-fits", "--truth", a.truth, "--eval", ev_path, "--degree", str(degree),
                           "--radius-h-deg", str(rh), "--radius-d-deg", str(rd)] + extra
                    wall, cpu = run(cmd, os.path.join(work, "ibrdf_%d_%g_%d%s.log" % (count, scale, degree, "" if method == "ibrdf" else "_nobin")))
                    summary = json.load(open(os.path.join(rec, "summary.json")))
                    f = np.load(os.path.join(rec, "eval.npy"))
                    truth = np.load(os.path.join(rec, "eval_truth.npy"))
                    ibrdf_f = f
                    valid = (f >= 0).all(axis=1) & (truth > 0).all(axis=1)
                    t = summary["timings_s"]
                    rows.append(dict(method=method, samples=count, scale=scale, radius_h_deg=rh, radius_d_deg=rd,
                                     degree=degree, grid_s=t["build_s"] + t["tabulate_s"], command_s=wall,
                                     cpu_s=cpu,
                                     points_scored=int(valid.sum()), rel_rms_points=rel_rms(f, truth, valid),
                                     rel_rms_grid=summary["error_against_truth"]["rel_rms_error_all"],
                                     extrapolated=False))
                    print(rows[-1], flush=True)
                if a.no_locfit:
                    continue
                wall, _ = run(["Rscript", os.path.join(os.path.dirname(os.path.abspath(__file__)), "locfit_reconstruct.R"),
                            lf_dir, str(degree)], os.path.join(work, "locfit_%d_%g_%d.log" % (count, scale, degree)))
                timing = json.load(open(os.path.join(lf_dir, "timing.json")))
                fit = np.exp(np.fromfile(os.path.join(lf_dir, "fit.f64"), "<f8").reshape(-1, 3))
                valid = np.isfinite(fit).all(axis=1) & (truth > 0).all(axis=1) & (ibrdf_f >= 0).all(axis=1)
                cpu = 3 * timing["setup_cpu_s_per_channel"] + timing["per_point_cpu_s_rgb"] * MERL_EVALUATIONS
                rows.append(dict(method="locfit", samples=count, scale=scale, radius_h_deg=rh, radius_d_deg=rd,
                                 degree=degree, grid_s=float("nan"), command_s=wall, cpu_s=cpu,
                                 points_scored=int(valid.sum()),
                                 rel_rms_points=rel_rms(fit, truth, valid), rel_rms_grid=float("nan"),
                                 extrapolated=True, locfit_points_cpu_s=timing["cpu_s"],
                                 locfit_nonfinite=int((~np.isfinite(fit).all(axis=1)).sum()),
                                 locfit_rows=timing["samples"],
                                 # agreement with the last ibrdf run of this configuration (unbinned where it ran)
                                 median_rel_diff_to_ibrdf=float(np.median(np.abs(fit[valid] - ibrdf_f[valid]) / ibrdf_f[valid]))
                                 if valid.any() else float("nan")))
                print(rows[-1], flush=True)
    write_outputs(rows, a)


def write_outputs(rows, a):
    keys = ["method", "samples", "scale", "radius_h_deg", "radius_d_deg", "degree", "cpu_s", "grid_s", "command_s",
            "points_scored", "rel_rms_points", "rel_rms_grid", "extrapolated", "median_rel_diff_to_ibrdf"]
    with open(os.path.join(a.out, "results.csv"), "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(str(r.get(k, "")) for k in keys) + "\n")
    lines = ["| samples | radii (deg) | degree | ibrdf CPU s (whole command) | ibrdf wall s (build + grid) "
             "| ibrdf rel. RMS at points | ibrdf rel. RMS full grid | locfit CPU s (extrapolated) "
             "| locfit rel. RMS at points | CPU ratio locfit / ibrdf |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        if r["method"] != "ibrdf":
            continue
        lf = [q for q in rows if q["method"] == "locfit" and q["samples"] == r["samples"] and q["scale"] == r["scale"]
              and q["degree"] == r["degree"]]
        lf_cells = ["", "", ""]
        if lf:
            q = lf[0]
            lf_cells = ["%.0f" % q["cpu_s"], "%.2f %%" % (100 * q["rel_rms_points"]), "%.0f" % (q["cpu_s"] / r["cpu_s"])]
        lines.append("| %d | %.2f x %.2f | %d | %.1f | %.1f | %.2f %% | %.2f %% | %s | %s | %s |" % (
            r["samples"], r["radius_h_deg"], r["radius_d_deg"], r["degree"], r["cpu_s"], r["grid_s"],
            100 * r["rel_rms_points"], 100 * r["rel_rms_grid"], *lf_cells))
    for r in rows:
        if r["method"] == "ibrdf, no binning":
            lines.append("| %d | %.2f x %.2f | %d | %.1f (no binning) | %.1f | %.2f %% | %.2f %% | | | |" % (
                r["samples"], r["radius_h_deg"], r["radius_d_deg"], r["degree"], r["cpu_s"], r["grid_s"],
                100 * r["rel_rms_points"], 100 * r["rel_rms_grid"]))
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    fig, ax = plt.subplots(figsize=(8, 5.5))
    colours = {0: "tab:blue", 1: "tab:orange", 2: "tab:green"}
    markers = {"ibrdf": "o", "ibrdf, no binning": "s", "locfit": "^"}
    counts = sorted({r["samples"] for r in rows})
    for r in rows:
        size = 20 + 80 * counts.index(r["samples"])
        ax.scatter(r["cpu_s"], 100 * r["rel_rms_points"], s=size, c=colours[r["degree"]], marker=markers[r["method"]],
                   alpha=0.75, edgecolors="k", linewidths=0.4)
    handles = [Line2D([], [], marker=m, ls="", color="grey", label=k + (" (extrapolated)" if k == "locfit" else ""))
               for k, m in markers.items()]
    handles += [Line2D([], [], marker="o", ls="", color=c, label="degree %d" % d) for d, c in colours.items()]
    ax.legend(handles=handles, fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("CPU seconds to tabulate the full MERL grid (548108 evaluations)")
    ax.set_ylabel("relative RMS error vs truth at %d MERL cells (%%)" % a.points)
    ax.set_title("bluepaint sphere: ibrdf vs locfit\n(marker size: samples %s; kernel scales %s)"
                 % (", ".join(str(c) for c in counts), a.scales), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "time_vs_error.png"), dpi=110)


if __name__ == "__main__":
    main()
