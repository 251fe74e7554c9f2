#!/usr/bin/python3
"""Draws the consistency report of an `ibrdf run` folder (run by `ibrdf report`, docs/report.md).

Usage: report.py RUN_DIR OUT_DIR

Reads RUN_DIR's samples.npy (+ sidecar), consistency.json, truth-comparison.json, reconstruction/,
stamps/*.json, and OUT_DIR/report-data.json (written by `ibrdf report`: the measured photo, rendered
spheres, the reconstruction and the truth along the incidence plane). Writes the PNG figures and a
self-contained OUT_DIR/index.html (figures embedded as data URIs, and the same PNGs beside it).
Plots with matplotlib (Debian's python3-matplotlib), Agg backend: no display needed.
"""
import base64
import glob
import html
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

CHANNELS = (("R", "#d62728"), ("G", "#2ca02c"), ("B", "#1f77b4"))
FIXED_INCIDENCE_COLOUR = "#ff7f0e"
FIXED_EXITANCE_COLOUR = "#9467bd"
COVERAGE_THETAS = (0, 15, 30, 45, 60, 75)
PLANE_TOLERANCE_DEG = 5.0   # |delta_phi| (or |pi - delta_phi|) for "in the incidence plane"
THETA_TOLERANCE_DEG = 2.5   # |theta - theta_0| for "fixed" incidence or exitance
MAX_POINTS = 4000           # per scatter panel, a fixed-seed subset beyond that


def load_json(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def subset(mask, rng, limit=MAX_POINTS):
    index = np.flatnonzero(mask)
    if index.size > limit:
        index = np.sort(rng.choice(index, limit, replace=False))
    return index


def save(fig, out, name):
    fig.savefig(os.path.join(out, name), dpi=100)
    plt.close(fig)
    return name


def coverage_figure(s, out):
    """The paper's coverage plots: for each incidence angle, where the exitant directions fell."""
    ti = np.degrees(s["theta_i"])
    te = np.degrees(s["theta_e"])
    dphi = s["delta_phi"]
    lum = s["brdf"] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
    rng = np.random.default_rng(0)
    fig, axes = plt.subplots(2, 3, figsize=(12, 8), subplot_kw={"projection": "polar"})
    for ax, theta in zip(axes.flat, COVERAGE_THETAS):
        mask = np.abs(ti - theta) <= THETA_TOLERANCE_DEG
        idx = subset(mask, rng, 8000)
        if idx.size:
            ax.scatter(dphi[idx], te[idx], s=2, c=np.log10(np.maximum(lum[idx], 1e-6)), cmap="viridis",
                       linewidths=0)
        ax.set_ylim(0, 90)
        ax.set_yticks([30, 60, 90])
        ax.set_title(f"theta_i = {theta} deg: {int(mask.sum())} samples", fontsize=10)
    fig.suptitle("Sample coverage: exitant direction (radius theta_e, angle delta_phi) for each incidence angle "
                 f"(+-{THETA_TOLERANCE_DEG} deg); colour log10 luminance of f", fontsize=11)
    fig.tight_layout()
    return save(fig, out, "coverage.png")


def incidence_plane_figure(s, data, out):
    """Fixed-incidence and fixed-exitance samples in the incidence plane, per channel, with the
    reconstruction (and the truth) as curves. Abscissa: the other angle, positive on the light's side."""
    curves = data.get("incidence_plane", [])
    ti = np.degrees(s["theta_i"])
    te = np.degrees(s["theta_e"])
    dphi = np.degrees(s["delta_phi"])
    back = np.abs(dphi) <= PLANE_TOLERANCE_DEG
    forward = np.abs(np.abs(dphi) - 180.0) <= PLANE_TOLERANCE_DEG
    rng = np.random.default_rng(1)
    fig, axes = plt.subplots(3, len(curves), figsize=(4 * len(curves), 10), squeeze=False)
    for col, curve in enumerate(curves):
        t0 = curve["theta0_deg"]
        fixed_i = (np.abs(ti - t0) <= THETA_TOLERANCE_DEG) & (back | forward)
        fixed_e = (np.abs(te - t0) <= THETA_TOLERANCE_DEG) & (back | forward)
        xi = np.where(back, te, -te)  # signed exitance angle
        xe = np.where(back, ti, -ti)  # signed incidence angle (by reciprocity, the same curve)
        ii, ie = subset(fixed_i, rng), subset(fixed_e, rng)
        angles = np.array(curve["angle_deg"])
        recon = np.array(curve["reconstruction"]) if curve["reconstruction"] else None
        truth = np.array(curve["truth"]) if curve["truth"] else None
        for row, (name, colour) in enumerate(CHANNELS):
            ax = axes[row][col]
            ax.scatter(xi[ii], s["brdf"][ii, row], s=3, color=FIXED_INCIDENCE_COLOUR, linewidths=0,
                       label=f"fixed incidence, theta_i = {t0:g}")
            ax.scatter(xe[ie], s["brdf"][ie, row], s=3, color=FIXED_EXITANCE_COLOUR, linewidths=0,
                       label=f"fixed exitance, theta_e = {t0:g}")
            if truth is not None:
                ax.plot(angles, truth[:, row], color="0.4", linestyle="--", linewidth=1, label="truth")
            if recon is not None:
                values = np.where(recon[:, row] < 0, np.nan, recon[:, row])
                ax.plot(angles, values, color=colour, linewidth=1.5, label="reconstruction")
            shown = np.concatenate([s["brdf"][ii, row], s["brdf"][ie, row]])
            shown = shown[shown > 0]
            if shown.size and shown.max() > 10 * shown.min():  # a glossy lobe: log scale
                ax.set_yscale("log")
            ax.set_xlim(-90, 90)
            ax.grid(True, alpha=0.3)
            if row == 0:
                ax.set_title(f"theta_0 = {t0:g} deg ({len(ii)} + {len(ie)} samples)", fontsize=10)
            if row == 2:
                ax.set_xlabel("other angle, deg (+ light side, - mirror side)")
            if col == 0:
                ax.set_ylabel(f"{name}: f, 1/sr")
            if row == 0 and col == 0:
                ax.legend(fontsize=7, markerscale=3)
    fig.suptitle(f"Incidence plane (|delta_phi| or |180 - delta_phi| <= {PLANE_TOLERANCE_DEG:g} deg): "
                 "fixed-incidence and fixed-exitance samples, reconstruction", fontsize=11)
    fig.tight_layout()
    return save(fig, out, "incidence-plane.png")


def consistency_figure(c, key, title, out):
    figure = c.get(key) if c else None
    if not figure or not figure.get("bins"):
        return None
    bins = figure["bins"]
    a = np.array([b["value_a"] for b in bins])
    b = np.array([b["value_b"] for b in bins])
    err = np.array([x["rel_error"] for x in bins])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for i, (name, colour) in enumerate(CHANNELS):
        axes[0].scatter(a[:, i], b[:, i], s=6, color=colour, label=name, alpha=0.7)
    positive = np.concatenate([a[a > 0], b[b > 0]])
    if positive.size:
        lo, hi = positive.min(), positive.max()
        axes[0].plot([lo, hi], [lo, hi], color="k", linewidth=0.8)
        axes[0].set_xscale("log")
        axes[0].set_yscale("log")
        for axis in (axes[0].xaxis, axes[0].yaxis):
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes[0].set_xlabel("bin estimate")
    axes[0].set_ylabel("its " + ("reciprocal" if key == "reciprocity" else "mirror") + " bin's estimate")
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"{len(bins)} bin pairs", fontsize=10)
    axes[1].hist(100 * err, bins=40, color="0.5")
    axes[1].set_xlabel("relative difference, % (mean over channels)")
    axes[1].set_ylabel("bin pairs")
    axes[1].set_title(f"weighted mean {100 * figure['overall_rel_error']:.2f} %, "
                      f"median {100 * figure['median_rel_error']:.2f} %, p95 {100 * figure['p95_rel_error']:.2f} %",
                      fontsize=10)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return save(fig, out, f"{key}.png")


def stamps(run_dir):
    result = {}
    for path in sorted(glob.glob(os.path.join(run_dir, "stamps", "*.json"))):
        stamp = load_json(path)
        result[stamp.get("stage", os.path.basename(path)[:-5])] = stamp.get("seconds", 0.0)
    return result


STAGE_ORDER = ("synth", "scan", "align", "derender", "check", "compare", "reconstruct", "report")


def timings_figure(times, counts, out):
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    names = [n for n in STAGE_ORDER if n in times] + [n for n in times if n not in STAGE_ORDER]
    axes[0].barh(names, [times[n] for n in names], color="#4c72b0")
    axes[0].invert_yaxis()
    axes[0].set_xlabel("seconds (wall clock, as recorded when the stage last ran)")
    axes[0].set_title("Stage timings", fontsize=10)
    rejected = {k: v for k, v in (counts or {}).get("rejected", {}).items() if v > 0}
    if rejected:
        axes[1].barh(list(rejected), list(rejected.values()), color="#c44e52")
        axes[1].invert_yaxis()
        axes[1].set_xscale("log")
    axes[1].set_xlabel("pixels")
    axes[1].set_title(f"Rejected pixels by reason ({(counts or {}).get('accepted', 0)} accepted)", fontsize=10)
    fig.tight_layout()
    return save(fig, out, "timings.png")


def truth_bands_figure(t, out):
    if not t:
        return None
    bands = [b for b in t["bands"] if b["count"] > 0]
    if not bands:
        return None
    labels = [f"{b['theta_low_deg']:.0f}-{b['theta_high_deg']:.0f}" for b in bands]
    x = np.arange(len(bands))
    fig, ax = plt.subplots(figsize=(8, 3.8))
    for i, (name, colour) in enumerate(CHANNELS):
        ax.bar(x + (i - 1) * 0.27, [100 * b["median_rel_error"][i] for b in bands], 0.27, color=colour, label=name)
    ax.set_xticks(x)
    ax.set_xticklabels(labels)
    ax.set_xlabel("max(theta_i, theta_e), deg")
    ax.set_ylabel("median |relative error|, %")
    ax.set_title("Samples against the true BRDF, by band", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save(fig, out, "truth-bands.png")


def pct(values):
    if values is None:
        return "n/a"
    if isinstance(values, (int, float)):
        return f"{100 * values:.2f} %"
    return " / ".join(f"{100 * v:.2f} %" for v in values)


def embed(out, name):
    with open(os.path.join(out, name), "rb") as f:
        return "data:image/png;base64," + base64.b64encode(f.read()).decode("ascii")


def figure_html(out, name, caption, width=None):
    if not name:
        return ""
    style = f' style="max-width:{width}px"' if width else ""
    return (f'<figure><img src="{embed(out, name)}" alt="{html.escape(name)}"{style}>'
            f'<figcaption>{html.escape(caption)} ({html.escape(name)})</figcaption></figure>\n')


# ---- Multi-light sessions (issue 12, real rigs): kept apart from the rest of the page.
def lights_section(out, data):
    """The session's lights (a dome, a turntable: a light per photo), what each gave and a photo under
    each; empty for a one-light session. `data["lights"]` is written by report/light_photos.cc."""
    lights = data.get("lights")
    if not lights:
        return ""
    rows = []
    for light in lights:
        where = light.get("position", light.get("direction", []))
        phase = light.get("phase_deg")
        thumb = (f'<img src="{embed(out, light["file"])}" alt="{html.escape(light["file"])}">'
                 if light.get("file") else html.escape(light.get("note", "no samples")))
        rows.append(f"<tr><td>{html.escape(light['id'])}</td><td>{light['kind']} "
                    f"[{', '.join(f'{v:.3f}' for v in where)}]</td><td>{light['photos']}</td>"
                    f"<td>{light['samples']}</td><td>{'n/a' if phase is None else f'{phase:.0f}'}</td>"
                    f"<td>{light['photo']}</td><td>{thumb}</td></tr>")
    used = sum(1 for light in lights if light["samples"] > 0)
    return (f"<h2>Lights</h2><p>{len(lights)} lights, {used} of them gave samples. Phase: the median angle "
            f"between light and view over the light's samples. Each photo is linearized, cropped to its samples "
            f"and tone-mapped on its own.</p><table><tr><th>light</th><th>kind, position or direction (m)</th>"
            f"<th>photos</th><th>samples</th><th>phase, deg</th><th>photo shown</th><th>photo</th></tr>"
            + "\n".join(rows) + "</table>\n")


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: report.py RUN_DIR OUT_DIR")
    run_dir, out = sys.argv[1], sys.argv[2]
    s = np.load(os.path.join(run_dir, "samples.npy"))
    side = load_json(os.path.join(run_dir, "samples.npy.json")) or {}
    counts = side.get("counts", {})
    c = load_json(os.path.join(run_dir, "consistency.json"))
    t = load_json(os.path.join(run_dir, "truth-comparison.json"))
    r = load_json(os.path.join(run_dir, "reconstruction", "summary.json"))
    data = load_json(os.path.join(out, "report-data.json")) or {}
    times = stamps(run_dir)

    figures = {
        "coverage": coverage_figure(s, out),
        "plane": incidence_plane_figure(s, data, out),
        "reciprocity": consistency_figure(c, "reciprocity", "Reciprocity: f(ti, te, dphi) against f(te, ti, -dphi), "
                                          "binned (local linear fit at each bin centre)", out),
        "isotropy": consistency_figure(c, "isotropy", "Bilateral symmetry: f(ti, te, dphi) against f(ti, te, -dphi)", out),
        "timings": timings_figure(times, counts, out),
        "bands": truth_bands_figure(t, out),
    }

    name = side.get("session_name", os.path.basename(os.path.abspath(run_dir)))
    rows = [("samples accepted", f"{counts.get('accepted', s.size)} of {counts.get('pixels_examined', 'n/a')} pixels "
             f"in {counts.get('photos', 'n/a')} photos")]
    for reason, n in counts.get("rejected", {}).items():
        rows.append((f"rejected: {reason}", str(n)))
    if c:
        rows.append(("reciprocity error (R / G / B)", pct(c["reciprocity"].get("per_channel_rel_error"))))
        rows.append(("bilateral-symmetry error (R / G / B)", pct(c["isotropy"].get("per_channel_rel_error"))))
    if t:
        rows.append(("samples vs truth: median |rel. error| (R / G / B)", pct(t["overall"]["median_rel_error"])))
        rows.append(("samples vs truth: p95 |rel. error| (R / G / B)", pct(t["overall"]["p95_rel_error"])))
    if r and "error_against_truth" in r:
        e = r["error_against_truth"]
        rows.append(("reconstruction vs truth: relative RMS (R / G / B)",
                     f"{pct(e['rel_rms_error'])} over {e['cells_scored']} MERL cells (coverage {pct(e['coverage'])})"))
    if r and "fits" in r:
        for model, fit in r["fits"].items():
            rows.append((f"{model} fit: relative RMS against the samples", pct(fit["rel_rms_vs_samples"])))
    for stage in [n for n in STAGE_ORDER if n in times]:
        rows.append((f"time: {stage}", f"{times[stage]:.2f} s"))
    table = "\n".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in rows)

    appearance = ""
    for key, caption in (("photo", "measured photo (linearized, cropped)"),
                         ("render", "reconstructed material on a sphere"),
                         ("render_truth", "true material on a sphere")):
        if key in data:
            extra = f", light {data[key].get('phase_deg', 0):.0f} deg from the view"
            if key == "photo":
                extra = f", photo {data[key]['index']}" + extra
            appearance += figure_html(out, data[key]["file"], caption + extra, 320)
    if "photo_note" in data:
        appearance += f"<p>No measured photo: {html.escape(data['photo_note'])}</p>"

    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>ibrdf report: {html.escape(name)}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; max-width: 1300px; }}
table {{ border-collapse: collapse; }} th, td {{ border: 1px solid #ccc; padding: 3px 8px; text-align: left; }}
th {{ font-weight: normal; color: #444; }} figure {{ display: inline-block; margin: 0.5em; vertical-align: top; }}
figure img {{ max-width: 100%; }} figcaption {{ font-size: 0.85em; color: #555; }}
</style></head><body>
<h1>ibrdf consistency report: {html.escape(name)}</h1>
<p>Run folder: <code>{html.escape(os.path.abspath(run_dir))}</code>. Figures after Marschner et al. 1999, Image-Based
BRDF Measurement. Every figure is embedded in this file; the same PNGs lie beside it.</p>
<h2>Headline figures</h2>
<table>{table}</table>
<h2>Appearance</h2>
<p>The sphere is lit by a distant light at the measured photo's median angle between light and view; each image is
scaled so its 99th-percentile luminance is 0.8 (sRGB). Magenta: no reconstructed value there.</p>
{appearance}
{lights_section(out, data)}
<h2>Sample coverage</h2>
{figure_html(out, figures['coverage'], 'exitant directions sampled at each incidence angle')}
<h2>Incidence plane, three colour channels</h2>
{figure_html(out, figures['plane'], 'fixed-incidence (orange) and fixed-exitance (purple) samples; reconstruction as the channel-coloured curve, truth dashed')}
<h2>Reciprocity and bilateral symmetry</h2>
{figure_html(out, figures['reciprocity'], 'reciprocal bin pairs')}
{figure_html(out, figures['isotropy'], 'mirrored bin pairs')}
{('<h2>Against the truth</h2>' + figure_html(out, figures['bands'], 'median relative error by band')) if figures['bands'] else ''}
<h2>Timings and rejected samples</h2>
{figure_html(out, figures['timings'], 'stage wall-clock times and pixels rejected by reason')}
</body></html>
"""
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write(page)


if __name__ == "__main__":
    main()
