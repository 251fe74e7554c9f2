#!/usr/bin/python3
"""Draws the consistency report of an `ibrdf run` folder (run by `ibrdf report`, docs/report.md).

Usage: report.py RUN_DIR OUT_DIR [--data-later]

With --data-later (how `ibrdf report` runs it), the figures of the run folder alone are drawn first, then
the script waits for OUT_DIR/report-data.json (or stops quietly at OUT_DIR/report-abort).

Reads RUN_DIR's samples.npy (+ sidecar), consistency.json, truth-comparison.json, reconstruction/,
stamps/*.json, and what `ibrdf report` wrote into OUT_DIR: report-data.json (title, models, the photo and
its renders, spheres, incidence-plane bands with every model at the samples' own positions, the
explorer's grids) and its .npy files. Writes the PNG figures, a self-contained OUT_DIR/index.html
(figures embedded as data URIs, the same PNGs beside it) and OUT_DIR/explorer.html (the interactive
explorer, its data embedded, no network at view time). Plots with matplotlib (Debian's
python3-matplotlib), Agg backend: no display needed.

Structure: one function per figure, each taking what it needs and returning the PNG's name (or None);
main() gathers them into sections. A multi-light session adds one photo section per light the same way.
"""
import base64
import glob
import html
import json
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

CHANNELS = (("R", "#d62728"), ("G", "#2ca02c"), ("B", "#1f77b4"))
MODEL_STYLE = {  # colour, line style
    "reconstruction": ("k", "-"),
    "lafortune": ("#ff7f0e", "-."),
    "ggx": ("#9467bd", "--"),
    "truth": ("0.5", ":"),
}
FIXED_INCIDENCE_COLOUR = "#e377c2"
FIXED_EXITANCE_COLOUR = "#17becf"
COVERAGE_THETAS = (0, 15, 30, 45, 60, 75)
THETA_TOLERANCE_DEG = 2.5   # |theta - theta_0| for the coverage plots
MAX_POINTS = 4000           # per scatter panel, a fixed-seed subset beyond that
ZOOM_TARGET_PX = 260        # small photo crops are shown enlarged (integer factor, up to 4) to about this width
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


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
    fig.savefig(os.path.join(out, name), dpi=90)
    plt.close(fig)
    return name


def log_axis(ax, axis="y"):
    """One scale convention: BRDF values on a log axis with a label at every decade and minor ticks."""
    target = ax.yaxis if axis == "y" else ax.xaxis
    (ax.set_yscale if axis == "y" else ax.set_xscale)("log")
    target.set_major_locator(matplotlib.ticker.LogLocator(base=10, numticks=12))
    target.set_minor_locator(matplotlib.ticker.LogLocator(base=10, subs=(2, 5), numticks=12))
    # Plain "%g" labels (no mathtext, which is slow): every decade, and 2 and 5 within it.
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    target.set_major_formatter(plain)
    target.set_minor_formatter(plain)


def coverage_figure(s, out):
    """The paper's coverage plots: for each incidence angle, where the exitant directions fell."""
    ti = np.degrees(s["theta_i"])
    te = np.degrees(s["theta_e"])
    dphi = s["delta_phi"]
    lum = s["brdf"] @ LUMINANCE.astype(np.float32)
    rng = np.random.default_rng(0)
    fig, axes = plt.subplots(2, 3, figsize=(12, 8), subplot_kw={"projection": "polar"})
    positive = lum[lum > 0]
    norm = matplotlib.colors.LogNorm(vmin=max(np.percentile(positive, 1), 1e-6) if positive.size else 1e-3,
                                     vmax=np.percentile(positive, 99.5) if positive.size else 1)
    mappable = None
    for ax, theta in zip(axes.flat, COVERAGE_THETAS):
        mask = np.abs(ti - theta) <= THETA_TOLERANCE_DEG
        idx = subset(mask, rng, 8000)
        if idx.size:
            mappable = ax.scatter(dphi[idx], te[idx], s=2, c=np.maximum(lum[idx], 1e-6), cmap="viridis", norm=norm,
                                  linewidths=0)
        ax.set_ylim(0, 90)
        ax.set_yticks([30, 60, 90])
        ax.set_title(f"theta_i = {theta} deg: {int(mask.sum())} samples", fontsize=10)
    fig.suptitle("Sample coverage: exitant direction (radius theta_e, angle delta_phi) for each incidence angle "
                 f"(+-{THETA_TOLERANCE_DEG} deg)", fontsize=11)
    # Fixed margins rather than tight_layout (which lays every polar tick label out once more before
    # the real draw: a quarter of this figure's time); plain tick labels on the colour bar (mathtext is slow).
    fig.subplots_adjust(left=0.03, right=0.86, bottom=0.04, top=0.9, wspace=0.3, hspace=0.3)
    if mappable is not None:
        bar = fig.colorbar(mappable, ax=list(axes.flat), fraction=0.025, pad=0.04, label="luminance of f, 1/sr (log)")
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
        bar.ax.yaxis.set_major_formatter(plain)
        bar.ax.yaxis.set_minor_formatter(plain)
    return save(fig, out, "coverage.png")


def binned_median(x, y, width=1.0):
    """Medians of y in bins of x `width` wide: the curve drawn through a band's samples."""
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size == 0:
        return np.array([]), np.array([])
    keys = np.floor(x / width).astype(int)
    # One sort by bin, then by value within it, and each bin's middle value (odd count) or the mean of its
    # two middle values (even count), as np.median gives them, without a median call per bin.
    order = np.lexsort((y, keys))
    keys, y = keys[order], y[order]
    unique, starts, counts = np.unique(keys, return_index=True, return_counts=True)
    low, high = y[starts + (counts - 1) // 2], y[starts + counts // 2]
    values = np.where(counts % 2 == 1, low, (low + high) / 2)
    return (unique + 0.5) * width, values


def load_plane(out, plane):
    rows = np.load(os.path.join(out, plane["file"]))
    return {name: rows[:, i] for i, name in enumerate(plane["columns"])}


def incidence_plane_figure(data, models, out):
    """Fixed-incidence and fixed-exitance samples in the incidence plane, per channel, with every model
    evaluated at the samples' own directions (solid: median per degree of those values, so the curve is
    where the samples are) and in the exact plane (thin dotted: the band's centre)."""
    planes = data.get("incidence_plane", [])
    if not planes:
        return None
    rng = np.random.default_rng(1)
    fig, axes = plt.subplots(3, len(planes), figsize=(4.2 * len(planes), 10), squeeze=False)
    for col, plane in enumerate(planes):
        t0 = plane["theta0_deg"]
        cols = load_plane(out, plane)
        kind = cols["kind"]
        x = cols["abscissa_deg"]
        centre_x = np.array(plane["centre_abscissa_deg"])
        for row, (name, colour) in enumerate(CHANNELS):
            ax = axes[row][col]
            key = "_" + name.lower()
            y = cols["sample" + key]
            for k, label, c in ((0, f"fixed incidence, theta_i = {t0:g}", FIXED_INCIDENCE_COLOUR),
                                (1, f"fixed exitance, theta_e = {t0:g}", FIXED_EXITANCE_COLOUR)):
                idx = subset(kind == k, rng)
                ax.scatter(x[idx], y[idx], s=3, color=c, linewidths=0, label=label)
            for model in models:
                mc, ls = MODEL_STYLE.get(model, ("k", "-"))
                bx, by = binned_median(x, cols[model + key])
                if bx.size:
                    ax.plot(bx, by, color=mc, linestyle=ls, linewidth=1.4, label=f"{model} at the samples")
                centre = np.array(plane["centre"][model], dtype=float)[:, row]
                centre = np.where(centre < 0, np.nan, centre)
                ax.plot(centre_x, centre, color=mc, linestyle=":", linewidth=0.7, alpha=0.6)
            positive = y[y > 0]
            if positive.size:
                log_axis(ax)
                ax.set_ylim(np.percentile(positive, 0.5) / 2, positive.max() * 2)
            ax.set_xlim(-90, 90)
            ax.xaxis.set_major_locator(matplotlib.ticker.MultipleLocator(30))
            ax.grid(True, which="major", alpha=0.3)
            if row == 0:
                agree = plane["agreement"].get("reconstruction")
                ratio = ""
                if agree and all(v is not None for v in agree["median_sample_over_model"]):
                    ratio = "\nsamples/reconstruction " + " ".join(f"{v:.3f}" for v in agree["median_sample_over_model"])
                ax.set_title(f"theta_0 = {t0:g} deg ({plane['fixed_incidence_samples']} + "
                             f"{plane['fixed_exitance_samples']} samples){ratio}", fontsize=9)
            if row == 2:
                ax.set_xlabel("other angle, deg (+ light side, - mirror side)")
            if col == 0:
                ax.set_ylabel(f"{name}: f, 1/sr")
            if row == 0 and col == 0:
                ax.legend(fontsize=6, markerscale=3, loc="lower left")
    b = planes[0]
    fig.suptitle(f"Incidence plane (band: |theta - theta_0| <= {b['band_theta_deg']:g} deg, within "
                 f"{b['band_phi_deg']:g} deg of the plane). Curves: each model at the samples' own directions "
                 "(median per degree); dotted: the same model in the exact plane", fontsize=10)
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.06, top=0.9, wspace=0.22, hspace=0.18)  # fixed grid
    return save(fig, out, "incidence-plane.png")


def reciprocity_curves_figure(data, out):
    """The paper's reciprocity figure: the fixed-incidence curve f(theta_0, x) against the fixed-exitance
    curve f(x, theta_0), from the samples alone (medians per degree), and their ratio."""
    planes = data.get("incidence_plane", [])
    if not planes:
        return None
    fig, axes = plt.subplots(2, len(planes), figsize=(4.2 * len(planes), 6), squeeze=False,
                             gridspec_kw={"height_ratios": (3, 1.3)})
    for col, plane in enumerate(planes):
        cols = load_plane(out, plane)
        lum = np.stack([cols["sample_r"], cols["sample_g"], cols["sample_b"]], 1) @ LUMINANCE
        curves = []
        for k, label, c in ((0, "fixed incidence", FIXED_INCIDENCE_COLOUR),
                            (1, "fixed exitance", FIXED_EXITANCE_COLOUR)):
            sel = cols["kind"] == k
            bx, by = binned_median(cols["abscissa_deg"][sel], lum[sel], 2.0)
            curves.append(dict(zip(bx, by)))
            axes[0][col].plot(bx, by, color=c, marker=".", markersize=3, linewidth=1, label=label)
        common = sorted(set(curves[0]) & set(curves[1]))
        if common:
            ratio = np.array([curves[0][x] / curves[1][x] for x in common if curves[1][x] > 0])
            xs = [x for x in common if curves[1][x] > 0]
            axes[1][col].plot(xs, 100 * (ratio - 1), color="k", marker=".", markersize=3, linewidth=0.8)
            med = np.median(np.abs(ratio - 1)) * 100 if ratio.size else float("nan")
            axes[1][col].set_title(f"median |difference| {med:.2f} % over {len(xs)} degrees", fontsize=8)
        axes[1][col].axhline(0, color="0.6", linewidth=0.8)
        axes[1][col].set_ylabel("incidence / exitance - 1, %", fontsize=8)
        axes[1][col].set_xlabel("other angle, deg")
        if lum[lum > 0].size:
            log_axis(axes[0][col])
        axes[0][col].set_title(f"theta_0 = {plane['theta0_deg']:g} deg", fontsize=10)
        for ax in axes[:, col]:
            ax.set_xlim(-90, 90)
            ax.grid(True, alpha=0.3)
        if col == 0:
            axes[0][col].set_ylabel("luminance of f, 1/sr")
            axes[0][col].legend(fontsize=7)
    fig.suptitle("Reciprocity as in the paper: the fixed-incidence curve against the fixed-exitance curve "
                 "(sample medians per 2 deg, no model)", fontsize=10)
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.09, top=0.88, wspace=0.25, hspace=0.35)  # fixed grid
    return save(fig, out, "reciprocity-curves.png")


def figure_of(c, key):
    if not c:
        return None
    if key == "bilateral_symmetry" and key not in c:
        key = "isotropy"  # a consistency.json of the previous release
    return c.get(key)


def consistency_figure(c, key, title, out):
    figure = figure_of(c, key)
    if not figure or not figure.get("bins"):
        return None
    bins = figure["bins"]
    a = np.array([b["value_a"] for b in bins])
    b = np.array([b["value_b"] for b in bins])
    err = np.array([x["rel_error"] for x in bins])
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for i, (name, colour) in enumerate(CHANNELS):
        axes[0].scatter(a[:, i], b[:, i], s=6, color=colour, label=name, alpha=0.7)
    positive = np.concatenate([a[a > 0], b[b > 0]])
    if positive.size:
        lo, hi = positive.min(), positive.max()
        axes[0].plot([lo, hi], [lo, hi], color="k", linewidth=0.8)
        log_axis(axes[0], "x")
        log_axis(axes[0], "y")
    axes[0].set_xlabel("median of the bin's samples, 1/sr")
    axes[0].set_ylabel("median of their " + ("reciprocal" if key == "reciprocity" else "mirrored") + " partners")
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"{len(bins)} bins, {figure.get('pairs', 0)} sample pairs", fontsize=10)
    axes[1].hist(100 * err, bins=40, color="0.5")
    median = figure.get("median_rel_error") or 0.0
    p95 = figure.get("p95_rel_error") or 0.0
    axes[1].axvline(100 * median, color="k", label=f"median {100 * median:.2f} %")
    axes[1].axvline(100 * p95, color="r", label=f"p95 {100 * p95:.2f} %")
    axes[1].legend(fontsize=8)
    axes[1].set_xlabel("|median signed difference| of a bin's pairs, %")
    axes[1].set_ylabel("bins")
    # Where: the worst bin over delta_phi at each (theta_i, theta_e).
    ti = np.array([x["theta_i_deg"] for x in bins])
    te = np.array([x["theta_e_deg"] for x in bins])
    cells = {}
    for i in range(len(bins)):
        cells[(ti[i], te[i])] = max(cells.get((ti[i], te[i]), 0.0), err[i])
    xs = np.array([k[0] for k in cells])
    ys = np.array([k[1] for k in cells])
    vs = np.array(list(cells.values())) * 100
    sc = axes[2].scatter(xs, ys, c=vs, cmap="magma_r", s=120, marker="s",
                         norm=matplotlib.colors.Normalize(0, max(vs.max(), 1.0)))
    fig.colorbar(sc, ax=axes[2], label="worst bin over delta_phi, %")
    for w in figure.get("worst_bins", [])[:3]:
        axes[2].annotate(f"{100 * w['rel_error']:.1f} % at dphi {w['delta_phi_deg']:.0f}",
                         (w["theta_i_deg"], w["theta_e_deg"]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    axes[2].set_xlabel("theta_i, deg")
    axes[2].set_ylabel("theta_e, deg")
    axes[2].set_xlim(0, 90)
    axes[2].set_ylim(0, 90)
    axes[2].set_title("where: the worst bins located", fontsize=10)
    fig.suptitle(title, fontsize=11)
    fig.subplots_adjust(left=0.06, right=0.97, bottom=0.12, top=0.86, wspace=0.28)  # fixed grid
    return save(fig, out, f"{key}.png")


def photo_difference_figure(data, out):
    """The signed difference (render - photo) / photo of each model, one shared diverging scale."""
    photo = data.get("photo")
    if not photo or not photo.get("renders"):
        return None
    renders = photo["renders"]
    fig, axes = plt.subplots(1, len(renders), figsize=(4 * len(renders) + 1, 4.2), squeeze=False)
    limit = 0.1
    image = None
    for ax, r in zip(axes[0], renders):
        d = np.load(os.path.join(out, r["difference"]))
        image = ax.imshow(100 * d, cmap="RdBu_r", vmin=-100 * limit, vmax=100 * limit, interpolation="nearest")
        med = r.get("median_abs_difference")
        ax.set_title(f"{r['model']}: median |difference| {100 * med:.2f} %" if med is not None else r["model"],
                     fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.colorbar(image, ax=list(axes[0]), fraction=0.03, label="(render - photo) / photo, % (clipped at +-10)")
    return save(fig, out, "photo-difference.png")


def held_out_difference_figure(data, out, photo):
    """A held-out photo's signed differences: the regression without it, the reconstruction with it."""
    renders = photo.get("renders", [])
    if not renders:
        return None
    fig, axes = plt.subplots(1, len(renders), figsize=(4 * len(renders) + 1, 4.2), squeeze=False)
    image = None
    for ax, r in zip(axes[0], renders):
        d = np.load(os.path.join(out, r["difference"]))
        image = ax.imshow(100 * d, cmap="RdBu_r", vmin=-10, vmax=10, interpolation="nearest")
        med = r.get("median_abs_difference")
        who = "fitted without this photo" if r["model"] == "held-out" else "reconstruction (saw this photo)"
        ax.set_title(f"{who}:\nmedian |difference| {100 * med:.2f} %" if med is not None else who, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.colorbar(image, ax=list(axes[0]), fraction=0.03, label="(render - photo) / photo, % (clipped at +-10)")
    return save(fig, out, f"held-out-{photo['index']}-difference.png")


def held_out_html(data, out, figures):
    """Held-out photos, shown as the main photo is: measured beside rendered, and the signed difference."""
    held = data.get("held_out") or []
    if not held:
        return ""
    parts = ["<h3>Held-out photos</h3><p>Each photo below beside the sample rendered from its camera by the local "
             "regression fitted <em>without</em> that photo's samples (the reconstruction's degree and radii, "
             "evaluated at the photo's own directions), and by the reconstruction that saw it: the gap between "
             "the two differences is how well the kernel bridges the missing sheet (the photos "
             "<code>ibrdf check --regression --held-out N</code> holds out).</p>"]
    for photo in held:
        if "note" in photo:
            parts.append(f"<p>Held-out photo {photo['index']} not shown: {html.escape(photo['note'])}</p>")
            continue
        x0, y0, x1, y1 = photo["crop"]
        zoom = max(1, min(4, ZOOM_TARGET_PX // (x1 - x0 + 1)))
        shown = (x1 - x0 + 1) * zoom if zoom > 1 else None
        enlarged = f", shown {zoom}x enlarged" if zoom > 1 else ""
        parts.append(figure_html(out, photo["file"], f"held-out photo {photo['index']} (linearized, full resolution"
                                 f"{enlarged}, pixels {x0}-{x1} x {y0}-{y1}, light {photo['phase_deg']:.0f} deg from "
                                 f"the view)", zoom_width=shown))
        for r in photo.get("renders", []):
            who = (f"regression fitted without photo {photo['index']} ({photo['fit_samples']} samples of the other "
                   f"photos; {photo['unsupported']} pixels without support, magenta)") \
                if r["model"] == "held-out" else "the reconstruction (its table; saw this photo)"
            parts.append(figure_html(out, r["file"], f"{who}, rendered from the photo's camera{enlarged}",
                                     zoom_width=shown))
        parts.append("<br>" + figure_html(out, figures.get(f"held_out_{photo['index']}"),
                                          f"signed difference from held-out photo {photo['index']}"))
    return "\n".join(parts)


def stamps(run_dir):
    result = {}
    for path in sorted(glob.glob(os.path.join(run_dir, "stamps", "*.json"))):
        stamp = load_json(path)
        result[stamp.get("stage", os.path.basename(path)[:-5])] = stamp.get("seconds", 0.0)
    return result


STAGE_ORDER = ("synth", "scan", "align", "derender", "check", "compare", "reconstruct", "uniformity", "materials",
               "report")


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
        log_axis(axes[1], "x")
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
    return " / ".join("n/a" if v is None else f"{100 * v:.2f} %" for v in values)


def embed(out, name):
    with open(os.path.join(out, name), "rb") as f:
        return "data:image/png;base64," + base64.b64encode(f.read()).decode("ascii")


def figure_html(out, name, caption, width=None, zoom_width=None):
    """An embedded figure; `zoom_width`: show a small image that many pixels wide, pixels kept sharp."""
    if not name:
        return ""
    style = f' style="max-width:{width}px"' if width else ""
    if zoom_width:
        style = f' style="width:{zoom_width}px; image-rendering: pixelated"'
    return (f'<figure><img src="{embed(out, name)}" alt="{html.escape(name)}"{style}>'
            f'<figcaption>{html.escape(caption)} ({html.escape(name)})</figcaption></figure>\n')


def appearance_html(data, out, figures):
    parts = []
    photo = data.get("photo")
    if photo:
        x0, y0, x1, y1 = photo["crop"]
        zoom = max(1, min(4, ZOOM_TARGET_PX // (x1 - x0 + 1)))
        shown = (x1 - x0 + 1) * zoom if zoom > 1 else None
        enlarged = f", shown {zoom}x enlarged" if zoom > 1 else ""
        parts.append(figure_html(out, photo["file"], f"measured photo {photo['index']} (linearized, full resolution{enlarged}, "
                                 f"pixels {x0}-{x1} x {y0}-{y1}, light {photo['phase_deg']:.0f} deg from the view)",
                                 zoom_width=shown))
        for r in photo.get("renders", []):
            every = "every pixel" if photo["stride"] == 1 else \
                f"every {photo['stride']}th pixel (the derender stride) shown as a block"
            parts.append(figure_html(out, r["file"], f"{r['model']} rendered from the photo's camera ({every}; "
                                     f"black: no sample; magenta: no model value; the photo's tone scale{enlarged})",
                                     zoom_width=shown))
        parts.append("<br>" + figure_html(out, figures.get("difference"), "signed difference of each render from "
                                          "the photo at the samples' pixels"))
    if "photo_note" in data:
        parts.append(f"<p>No measured photo: {html.escape(data['photo_note'])}</p>")
    spheres = data.get("spheres", [])
    if spheres:
        parts.append("<h3>On a sphere</h3>")
        for sp in spheres:
            parts.append(figure_html(out, sp["file"], f"{sp['model']} on a sphere, light {sp['phase_deg']:.0f} deg "
                                     "from the view", 260))
    return "\n".join(parts)


# ---- Multi-light sessions (domes, turntables): kept apart from the rest of the page.
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


def headline_rows(s, side, c, t, r, data, times):
    counts = side.get("counts", {})
    rows = [("samples accepted", f"{counts.get('accepted', s.size)} of {counts.get('pixels_examined', 'n/a')} pixels "
             f"in {counts.get('photos', 'n/a')} photos")]
    zero = [reason for reason, n in counts.get("rejected", {}).items() if n == 0]
    for reason, n in counts.get("rejected", {}).items():
        if n > 0:
            rows.append((f"rejected: {reason}", str(n)))
    if zero:
        rows.append(("rejected: none for", ", ".join(zero)))
    for key, name in (("reciprocity", "reciprocity"), ("bilateral_symmetry", "bilateral symmetry")):
        figure = figure_of(c, key)
        if figure is None:
            continue
        if "headline" in figure:
            rows.append((f"{name}: |median pair difference| per bin, median and p95 over bins", figure["headline"]))
        else:
            rows.append((f"{name} error (R / G / B)", pct(figure.get("per_channel_rel_error"))))
        for w in figure.get("worst_bins", [])[:3]:
            rows.append((f"{name}: a worst bin", f"{100 * w['rel_error']:.2f} % at theta_i {w['theta_i_deg']:.0f}, "
                         f"theta_e {w['theta_e_deg']:.0f}, delta_phi {w['delta_phi_deg']:.0f} deg "
                         f"({w['pairs']} pairs)"))
    if c and "regression" in c:
        reg = c["regression"]
        for key, name in (("reciprocity_near_incidence_plane", "reciprocity near the incidence plane"),
                          ("bilateral_symmetry", "bilateral symmetry")):
            f = reg.get(key, {})
            value = "invalid (no pair had two estimates)" if not f.get("valid") else \
                f"median {pct(f.get('median_rel_error'))}, p95 {pct(f.get('p95_rel_error'))} over {f.get('pairs')} pairs"
            rows.append((f"regression check: {name}", value))
        if reg.get("held_out_photos"):
            value = ("nothing predicted (no held-out sample below the check's max_theta_deg)"
                     if not reg.get("held_out_valid", True) else
                     f"RMS prediction error (R / G / B) {pct(reg.get('held_out_rms_rel_error'))}")
            rows.append((f"regression check: {len(reg['held_out_photos'])} held-out photos", value))
    for plane in data.get("incidence_plane", []):
        agree = plane["agreement"].get("reconstruction")
        if agree:
            rows.append((f"incidence plane {plane['theta0_deg']:g} deg: median sample / reconstruction (R / G / B)",
                         " / ".join("n/a" if v is None else f"{v:.3f}" for v in agree["median_sample_over_model"]) +
                         f" over {agree['samples']} samples"))
    if t:
        rows.append(("samples vs truth: median |rel. error| (R / G / B)", pct(t["overall"]["median_rel_error"])))
        rows.append(("samples vs truth: p95 |rel. error| (R / G / B)", pct(t["overall"]["p95_rel_error"])))
    if r and "error_against_truth" in r:
        e = r["error_against_truth"]
        rows.append(("reconstruction vs truth: relative RMS (R / G / B)",
                     f"{pct(e['rel_rms_error'])} over {e['cells_scored']} MERL cells (coverage {pct(e['coverage'])})"))
    if r and "uncertainty" in r.get("table", {}):
        u = r["table"]["uncertainty"]
        for cls in ("measured", "interpolated"):
            if u.get(cls, {}).get("cells"):
                rows.append((f"reconstruction: stated standard error, {cls} cells (largest channel; uncertainty.npy)",
                             f"median {pct(u[cls]['median'])}, p95 {pct(u[cls]['p95'])} over {u[cls]['cells']} cells"
                             + (f" (measured requires <= {pct(u['max_measured_standard_error'])})"
                                if cls == "measured" else "")))
        rows.append(("reconstruction .bsdf: uncertainty", "not in the format; stated in its description"))
    for cls in ("measured", "interpolated"):
        e = (r or {}).get(f"error_against_truth_{cls}")
        if e and e.get("cells_scored"):
            rows.append((f"reconstruction vs truth, {cls} cells: relative RMS (R / G / B)",
                         f"{pct(e['rel_rms_error'])} over {e['cells_scored']} cells"))
        cov = (r or {}).get("uncertainty_coverage", {}).get(cls)
        if cov and cov.get("cell_channels"):
            rows.append((f"reconstruction vs truth, {cls} cells: true error within 2 standard errors",
                         f"{pct(cov['within_2sigma'])} of {cov['cell_channels']} cell channels"))
    if r and "fits" in r:
        for model, fit in r["fits"].items():
            # Besides one block per model the summary holds "chosen", "snippet_kind", "renderer_snippets".
            if not isinstance(fit, dict) or "rel_rms_vs_samples" not in fit:
                continue
            chosen = " (chosen)" if r["fits"].get("chosen") == model else ""
            rows.append((f"{model} fit{chosen}: relative RMS against the samples", pct(fit["rel_rms_vs_samples"])))
    photo = data.get("photo")
    if photo:
        for rd in photo.get("renders", []):
            if rd.get("median_abs_difference") is not None:
                rows.append((f"photo {photo['index']}: median |render - photo| / photo, {rd['model']}",
                             pct(rd["median_abs_difference"])))
    for h in data.get("held_out") or []:
        for rd in h.get("renders", []):
            if rd.get("median_abs_difference") is not None:
                who = "regression fitted without it" if rd["model"] == "held-out" else rd["model"]
                rows.append((f"held-out photo {h['index']}: median |render - photo| / photo, {who}",
                             pct(rd["median_abs_difference"])))
    for stage in [n for n in STAGE_ORDER if n in times]:
        rows.append((f"time: {stage}", f"{times[stage]:.2f} s"))
    return rows


def b64_array(path):
    return base64.b64encode(np.load(path).astype("<f4").tobytes()).decode("ascii")


def write_explorer(data, out, title):
    grids = data.get("explorer")
    if not grids:
        return None
    payload = {"title": title, "theta_i": grids["theta_i_deg"], "phi": grids["phi_deg"],
               "theta_e": grids["theta_e_deg"], "table_cells": grids["table_cells"], "models": {}}
    for model in grids["models"]:
        payload["models"][model] = {
            "curves": b64_array(os.path.join(out, f"explorer-curves-{model}.npy")),
            "halfdiff": b64_array(os.path.join(out, f"explorer-halfdiff-{model}.npy")),
            "table": b64_array(os.path.join(out, f"explorer-table-{model}.npy")),
        }
    payload["samples"] = b64_array(os.path.join(out, "explorer-samples.npy"))
    page = EXPLORER_HTML.replace("__TITLE__", html.escape(title)).replace("__DATA__", json.dumps(payload))
    with open(os.path.join(out, "explorer.html"), "w") as f:
        f.write(page)
    for path in glob.glob(os.path.join(out, "explorer-*.npy")):
        os.remove(path)  # embedded in explorer.html
    return "explorer.html"


EXPLORER_HTML = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>ibrdf explorer: __TITLE__</title>
<style>
body { font-family: sans-serif; margin: 1em; } .row { display: flex; flex-wrap: wrap; gap: 1em; }
fieldset { border: 1px solid #ccc; } label { margin-right: 0.8em; white-space: nowrap; }
canvas { border: 1px solid #ddd; } .note { color: #555; font-size: 0.85em; max-width: 60em; }
</style></head><body>
<h1>BRDF explorer: __TITLE__</h1>
<p class="note">Everything is embedded in this file: it works offline. Curves: f(theta_i, phi_i = 0; theta_e, phi_e)
in the slice at azimuth phi (the right half of the plot; the left half is the opposite azimuth phi + 180, so phi = 0
is the incidence plane with the light's side on the right). Samples: those within 2.5 deg of theta_i and 5 deg of the
slice. Table: the reconstruction, interpolated smoothly; fits and truth as the run has them.</p>
<div class="row"><fieldset><legend>Incidence and slice</legend>
<label>theta_i <input id="theta" type="range"> <span id="theta-value"></span> deg</label>
<label>slice azimuth phi <input id="phi" type="range"> <span id="phi-value"></span> deg</label><br>
<label><input id="log" type="checkbox" checked> log scale</label>
<label><input id="polar" type="checkbox"> polar plot</label>
<label>channel <select id="channel"><option value="3">luminance</option><option value="0">R</option>
<option value="1">G</option><option value="2">B</option></select></label>
<label><input id="show-samples" type="checkbox" checked> samples</label>
<span id="model-boxes"></span></fieldset>
<fieldset><legend>Compare with a second BRDF</legend>
<input id="compare-file" type="file" accept=".binary"> <span id="compare-name" class="note">a MERL .binary
(e.g. another run's reconstruction/brdf.binary)</span></fieldset></div>
<div class="row"><canvas id="plot" width="580" height="400"></canvas>
<div style="width:240px"><canvas id="sphere" width="224" height="224"></canvas><br>
<label>light elevation <input id="light-theta" type="range" min="0" max="85" value="30" style="width:110px"></label><br>
<label>light azimuth <input id="light-phi" type="range" min="0" max="359" value="180" style="width:110px"></label><br>
<label>sphere model <select id="sphere-model"></select></label></div>
<div style="width:230px"><canvas id="halfdiff" width="224" height="224"></canvas><br><span class="note">theta_h (right) x theta_d (up),
phi_d = 90 deg, log colour: <select id="halfdiff-model"></select></span></div></div>
<pre id="ibrdf-test" style="display:none"></pre>
<script>
const DATA = __DATA__;
const COLOURS = {reconstruction: "#000000", lafortune: "#ff7f0e", ggx: "#9467bd", truth: "#888888", compare: "#17becf"};
function f32(b64) { const s = atob(b64); const b = new Uint8Array(s.length);
  for (let i = 0; i < s.length; ++i) b[i] = s.charCodeAt(i); return new Float32Array(b.buffer); }
const MODELS = {};
for (const name in DATA.models) { const m = DATA.models[name];
  MODELS[name] = {curves: f32(m.curves), halfdiff: f32(m.halfdiff), table: f32(m.table)}; }
const SAMPLES = f32(DATA.samples);
const TI = DATA.theta_i, PH = DATA.phi, TE = DATA.theta_e, NC = DATA.table_cells;
const nTI = Math.round((TI[1] - TI[0]) / TI[2]) + 1, nPH = Math.round((PH[1] - PH[0]) / PH[2]) + 1,
      nTE = Math.round((TE[1] - TE[0]) / TE[2]) + 1;
const $ = id => document.getElementById(id);
$("theta").min = TI[0]; $("theta").max = TI[1]; $("theta").step = TI[2]; $("theta").value = 30;
$("phi").min = PH[0]; $("phi").max = PH[1]; $("phi").step = PH[2]; $("phi").value = 0;
const shown = {};
for (const name in MODELS) { shown[name] = true;
  $("model-boxes").insertAdjacentHTML("beforeend", `<label style="color:${COLOURS[name] || "#000"}">` +
    `<input type="checkbox" id="show-${name}" checked> ${name}</label>`);
  for (const sel of ["sphere-model", "halfdiff-model"]) $(sel).insertAdjacentHTML("beforeend",
    `<option value="${name}">${name}</option>`); }
let compare = null;  // {name, lookup(wi, wo)}
function value(rgb, ch) { if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) return NaN;
  return ch == 3 ? 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2] : rgb[ch]; }
function dir(theta, phi) { const t = theta * Math.PI / 180, p = phi * Math.PI / 180;
  return [Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t)]; }
// The curve of a model at the slider's grid point: values at theta_e = TE[0] .. TE[1].
function curve(name, theta, phi, ch) {
  const it = Math.round((theta - TI[0]) / TI[2]), ip = Math.round((phi - PH[0]) / PH[2]);
  const out = [];
  if (name == "compare") { for (let k = 0; k < nTE; ++k) { const x = TE[0] + k * TE[2];
      out.push(value(compare.lookup(dir(theta, 0), dir(Math.abs(x), x >= 0 ? phi : phi + 180)), ch)); }
    return out; }
  const c = MODELS[name].curves;
  for (let k = 0; k < nTE; ++k) { const at = ((it * nPH + ip) * nTE + k) * 3;
    out.push(value([c[at], c[at + 1], c[at + 2]], ch)); }
  return out;
}
function slabSamples(theta, phi, ch) {
  const pts = [];
  for (let i = 0; i + 5 < SAMPLES.length; i += 6) {
    if (Math.abs(SAMPLES[i] - theta) > 2.5) continue;
    const dp = SAMPLES[i + 2], te = SAMPLES[i + 1];
    const d1 = Math.abs(((dp - phi) % 360 + 540) % 360 - 180), d2 = Math.abs(((dp - phi - 180) % 360 + 540) % 360 - 180);
    let x = null;
    if (Math.min(d1, Math.abs(((-dp - phi) % 360 + 540) % 360 - 180)) <= 5) x = te;
    else if (Math.min(d2, Math.abs(((-dp - phi - 180) % 360 + 540) % 360 - 180)) <= 5) x = -te;
    if (x === null) continue;
    const v = value([SAMPLES[i + 3], SAMPLES[i + 4], SAMPLES[i + 5]], ch);
    if (v > 0) pts.push([x, v]);
  }
  return pts;
}
function draw() {
  const theta = +$("theta").value, phi = +$("phi").value, ch = +$("channel").value;
  const log = $("log").checked, polar = $("polar").checked;
  $("theta-value").textContent = theta; $("phi-value").textContent = phi;
  const cv = $("plot"), g = cv.getContext("2d"); g.clearRect(0, 0, cv.width, cv.height);
  const series = {};
  for (const name in MODELS) if ($("show-" + name).checked) series[name] = curve(name, theta, phi, ch);
  if (compare) series.compare = curve("compare", theta, phi, ch);
  const pts = $("show-samples").checked ? slabSamples(theta, phi, ch) : [];
  let vals = pts.map(p => p[1]);
  for (const n in series) vals = vals.concat(series[n].filter(v => v > 0));
  vals = vals.filter(v => isFinite(v) && v > 0).sort((a, b) => a - b);
  const hi = vals.length ? vals[vals.length - 1] * 1.2 : 1, lo = log ? (vals.length ? Math.max(vals[0] / 1.5, hi * 1e-4) : 1e-3) : 0;
  const W = cv.width, H = cv.height, L = 70, R = 20, T = 20, B = 40;
  const fy = v => log ? (Math.log10(Math.max(v, lo)) - Math.log10(lo)) / (Math.log10(hi) - Math.log10(lo)) : v / hi;
  let px, py;
  if (!polar) { px = (x, v) => L + (x + 90) / 180 * (W - L - R); py = (x, v) => H - B - fy(v) * (H - T - B); }
  else { const cx = W / 2, cy = H - B, r = Math.min(W / 2 - R, H - T - B);
    px = (x, v) => cx + Math.sin(x * Math.PI / 180) * fy(v) * r; py = (x, v) => cy - Math.cos(x * Math.PI / 180) * fy(v) * r; }
  // Axes and ticks.
  g.strokeStyle = "#bbb"; g.fillStyle = "#333"; g.font = "11px sans-serif"; g.lineWidth = 1;
  if (!polar) { g.strokeRect(L, T, W - L - R, H - T - B);
    for (let x = -90; x <= 90; x += 30) { g.fillText(x, px(x, lo) - 8, H - B + 14); }
    g.fillText("theta_e, deg (right: azimuth phi, left: phi + 180)", L + 150, H - 8);
    const ticks = [];
    if (log) { for (let e = Math.floor(Math.log10(lo)); e <= Math.ceil(Math.log10(hi)); ++e)
        for (const m of [1, 2, 5]) { const v = m * Math.pow(10, e); if (v >= lo && v <= hi) ticks.push(v); } }
    else { const step = Math.pow(10, Math.floor(Math.log10(hi / 5))); for (let v = 0; v <= hi; v += step * (hi / step > 20 ? 5 : hi / step > 10 ? 2 : 1)) ticks.push(v); }
    for (const v of ticks) { const y = py(0, v); g.beginPath(); g.moveTo(L, y); g.lineTo(W - R, y); g.stroke();
      g.fillText(v.toPrecision(2), 5, y + 4); }
  } else { for (const v of [0.25, 0.5, 0.75, 1]) { g.beginPath();
      g.arc(W / 2, H - B, v * Math.min(W / 2 - R, H - T - B), Math.PI, 2 * Math.PI); g.stroke(); }
    g.fillText(log ? "radius: log f" : "radius: f", 5, 14); }
  for (const p of pts) { g.fillStyle = "rgba(220,60,160,0.5)"; g.fillRect(px(p[0], p[1]) - 1, py(p[0], p[1]) - 1, 2.5, 2.5); }
  const drawn = {};
  for (const name in series) { g.strokeStyle = COLOURS[name] || "#000"; g.lineWidth = 1.6; g.beginPath();
    let pen = false; const ys = [];
    series[name].forEach((v, k) => { const x = TE[0] + k * TE[2];
      if (!(v > 0) && !(v == 0 && !log)) { pen = false; ys.push(null); return; }
      const X = px(x, v), Y = py(x, v); ys.push(Y);
      if (pen) g.lineTo(X, Y); else g.moveTo(X, Y); pen = true; });
    g.stroke(); drawn[name] = {values: series[name].map(v => isFinite(v) ? v : null), y_px: ys}; }
  $("ibrdf-test").textContent = JSON.stringify({theta_i: theta, phi: phi, channel: ch, log: log, polar: polar,
    theta_e: TE, samples: pts.length, curves: drawn});
  drawSphere(); drawHalfDiff();
}
// Trilinear lookup in a model's 32^3 table (MERL's axes, phi_d over [0, 180)).
function halfDiff(wi, wo) {
  const h = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]; const n = Math.hypot(h[0], h[1], h[2]);
  if (n < 1e-9) return null; h[0] /= n; h[1] /= n; h[2] /= n;
  const th = Math.acos(Math.min(1, h[2])), ph = Math.atan2(h[1], h[0]);
  const rot = (v, axis, a) => { const c = Math.cos(a), s = Math.sin(a);
    if (axis == "z") return [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]];
    return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]; };
  const d = rot(rot(wi, "z", -ph), "y", -th);
  let pd = Math.atan2(d[1], d[0]); if (pd < 0) pd += Math.PI;
  return [th, Math.acos(Math.max(-1, Math.min(1, d[2]))), pd];
}
function tableLookup(name, wi, wo) {
  const a = halfDiff(wi, wo); if (!a) return [-1, -1, -1];
  const t = MODELS[name].table;
  const u = Math.sqrt(a[0] / (Math.PI / 2)) * NC - 0.5, v = a[1] / (Math.PI / 2) * NC - 0.5, w = a[2] / Math.PI * NC - 0.5;
  const fu = Math.floor(u), fv = Math.floor(v), fw = Math.floor(w); const out = [0, 0, 0]; let ws = 0;
  for (let du = 0; du < 2; ++du) for (let dv = 0; dv < 2; ++dv) for (let dw = 0; dw < 2; ++dw) {
    const i = Math.min(NC - 1, Math.max(0, fu + du)), j = Math.min(NC - 1, Math.max(0, fv + dv)), k = ((fw + dw) % NC + NC) % NC;
    const wt = (du ? u - fu : 1 - u + fu) * (dv ? v - fv : 1 - v + fv) * (dw ? w - fw : 1 - w + fw);
    const at = ((i * NC + j) * NC + k) * 3; if (wt <= 0 || t[at] < 0) continue;
    for (let c = 0; c < 3; ++c) out[c] += wt * t[at + c]; ws += wt; }
  return ws > 1e-9 ? out.map(x => x / ws) : [-1, -1, -1];
}
function drawSphere() {
  const cv = $("sphere"), g = cv.getContext("2d"), S = cv.width, img = g.createImageData(S, S);
  const name = $("sphere-model").value; const L = dir(+$("light-theta").value, +$("light-phi").value);
  const lookup = name == "compare" && compare ? compare.lookup : (wi, wo) => tableLookup(name, wi, wo);
  const vals = new Float32Array(S * S * 3).fill(-1); const lum = [];
  for (let y = 0; y < S; y += 2) for (let x = 0; x < S; x += 2) {
    const u = 2 * (x + 1) / S - 1, v = 1 - 2 * (y + 1) / S, r2 = u * u + v * v; if (r2 >= 1) continue;
    const n = [u, v, Math.sqrt(1 - r2)]; const ci = n[0] * L[0] + n[1] * L[1] + n[2] * L[2]; if (ci <= 0) continue;
    // Local frame around n: t1, t2, n.
    const a = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
    let t1 = [a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0]];
    const tn = Math.hypot(...t1); t1 = t1.map(c => c / tn);
    const t2 = [n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]];
    const loc = w => [w[0] * t1[0] + w[1] * t1[1] + w[2] * t1[2], w[0] * t2[0] + w[1] * t2[1] + w[2] * t2[2],
                      w[0] * n[0] + w[1] * n[1] + w[2] * n[2]];
    const f = lookup(loc(L), loc([0, 0, 1]));
    if (f[0] < 0 || f[1] < 0 || f[2] < 0) { vals[(y * S + x) * 3] = -2; continue; }  // no value: magenta
    for (let c = 0; c < 3; ++c) vals[(y * S + x) * 3 + c] = f[c] * ci;
    lum.push(0.2126 * vals[(y * S + x) * 3] + 0.7152 * vals[(y * S + x) * 3 + 1] + 0.0722 * vals[(y * S + x) * 3 + 2]);
  }
  lum.sort((a, b) => a - b); const scale = lum.length ? 0.8 / Math.max(lum[Math.floor(0.99 * (lum.length - 1))], 1e-12) : 1;
  const srgb = v => 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
  for (let y = 0; y < S; ++y) for (let x = 0; x < S; ++x) { const at = ((y & ~1) * S + (x & ~1)) * 3, o = (y * S + x) * 4;
    img.data[o + 3] = 255; if (vals[at] == -2) { img.data[o] = 255; img.data[o + 2] = 255; continue; }
    if (vals[at] < 0) continue;
    for (let c = 0; c < 3; ++c) img.data[o + c] = srgb(Math.min(1, vals[at + c] * scale)); }
  g.putImageData(img, 0, 0);
}
function drawHalfDiff() {
  const cv = $("halfdiff"), g = cv.getContext("2d"), name = $("halfdiff-model").value;
  if (!MODELS[name]) return; const t = MODELS[name].halfdiff, ch = +$("channel").value;
  const img = g.createImageData(90, 90); const vs = [];
  for (let i = 0; i < 90 * 90; ++i) { const v = value([t[3 * i], t[3 * i + 1], t[3 * i + 2]], ch); if (v > 0) vs.push(Math.log10(v)); }
  vs.sort((a, b) => a - b); const lo = vs.length ? vs[0] : 0, hi = vs.length ? vs[vs.length - 1] : 1;
  for (let h = 0; h < 90; ++h) for (let d = 0; d < 90; ++d) { const i = h * 90 + d, o = ((89 - d) * 90 + h) * 4;
    const v = value([t[3 * i], t[3 * i + 1], t[3 * i + 2]], ch); img.data[o + 3] = 255;
    if (!(v > 0)) { img.data[o] = 255; img.data[o + 2] = 255; continue; }
    const s = (Math.log10(v) - lo) / Math.max(hi - lo, 1e-9);
    img.data[o] = 255 * Math.min(1, 1.5 * s); img.data[o + 1] = 255 * Math.max(0, Math.min(1, 1.5 * s - 0.5)); img.data[o + 2] = 255 * Math.max(0, s - 0.66) * 3; }
  const tmp = document.createElement("canvas"); tmp.width = 90; tmp.height = 90; tmp.getContext("2d").putImageData(img, 0, 0);
  g.imageSmoothingEnabled = false; g.drawImage(tmp, 0, 0, cv.width, cv.height);
}
// A second BRDF: a MERL .binary read in the browser (FileReader; nothing leaves the machine).
$("compare-file").addEventListener("change", ev => { const file = ev.target.files[0]; if (!file) return;
  const reader = new FileReader();
  reader.onload = () => { const buf = reader.result, dims = new Int32Array(buf, 0, 3);
    if (dims[0] != 90 || dims[1] != 90 || dims[2] != 180) { $("compare-name").textContent = file.name + ": not a MERL table"; return; }
    const d = new Float64Array(buf.slice(12)), N = 90 * 90 * 180, scale = [1 / 1500, 1.15 / 1500, 1.66 / 1500];
    compare = {name: file.name, lookup: (wi, wo) => { const a = halfDiff(wi, wo); if (!a) return [-1, -1, -1];
      const i = Math.min(89, Math.max(0, Math.floor(Math.sqrt(a[0] / (Math.PI / 2) * 90 * 90)))),
            j = Math.min(89, Math.max(0, Math.floor(a[1] / (Math.PI / 2) * 90))),
            k = Math.min(179, Math.max(0, Math.floor(a[2] / Math.PI * 180))), at = k + 180 * (j + 90 * i);
      return [0, 1, 2].map(c => d[at + c * N] < 0 ? -1 : d[at + c * N] * scale[c]); }};
    $("compare-name").textContent = "compared: " + file.name;
    if (!$("sphere-model").querySelector('option[value="compare"]'))
      $("sphere-model").insertAdjacentHTML("beforeend", '<option value="compare">compare</option>');
    draw(); };
  reader.readAsArrayBuffer(file); });
for (const id of ["theta", "phi", "log", "polar", "channel", "show-samples", "light-theta", "light-phi", "sphere-model", "halfdiff-model"])
  $(id).addEventListener("input", draw);
for (const name in MODELS) $("show-" + name).addEventListener("input", draw);
// Test hook: #theta_i=30&phi=0&channel=1&log=0&polar=1 sets the controls before the first drawing.
for (const kv of location.hash.replace(/^#/, "").split("&")) { const [k, v] = kv.split("=");
  if (k == "theta_i") $("theta").value = v; else if (k == "phi") $("phi").value = v;
  else if (k == "channel") $("channel").value = v; else if (k == "log") $("log").checked = v == "1";
  else if (k == "polar") $("polar").checked = v == "1"; }
draw();
</script></body></html>
"""


_JOBS = []  # the early figure functions, inherited by the forked workers of run_figures
_DATA = {}  # report-data.json, read once per process (late_figure)


def _run_job(index):
    return _JOBS[index]()


def report_data(out):
    """OUT_DIR/report-data.json (what `ibrdf report` computed), read once per process; {} without it."""
    if "data" not in _DATA:
        _DATA["data"] = load_json(os.path.join(out, "report-data.json")) or {}
    return _DATA["data"]


def late_figure_names(data):
    """The figures drawn from report-data.json, the slowest first."""
    return ["plane", "reciprocity_curves", "difference"] + \
        [f"held_out_{p['index']}" for p in data.get("held_out") or [] if "note" not in p]


def late_figure(name, out):
    """Draws one of late_figure_names (in whichever process runs it); returns the PNG's name or None."""
    data = report_data(out)
    if name == "plane":
        return incidence_plane_figure(data, data.get("models", []), out)
    if name == "reciprocity_curves":
        return reciprocity_curves_figure(data, out)
    if name == "difference":
        return photo_difference_figure(data, out)
    index = int(name[len("held_out_"):])
    photo = next(p for p in data.get("held_out") or [] if p.get("index") == index and "note" not in p)
    return held_out_difference_figure(data, out, photo)


def wait_for_data(out):
    """With --data-later, `ibrdf report` starts this script before it has written report-data.json (so the
    figures of the run folder alone are drawn beside its work): True once the file is there (written
    atomically), False when OUT_DIR/report-abort appears instead (the C++ part failed; nothing to draw)."""
    data_path, abort = os.path.join(out, "report-data.json"), os.path.join(out, "report-abort")
    while not os.path.exists(data_path):
        if os.path.exists(abort):
            return False
        time.sleep(0.01)
    return True


def run_figures(early, out, ready, explorer_job):
    """Runs the early figure functions (name -> function returning the figure's file name; they need only
    the run folder) and, once ready() says report-data.json is there, the late ones (late_figure), in
    forked worker processes, one per CPU this process may use, in the order given (the slowest first
    balances them), while this process writes the explorer; returns ({name: file name}, the explorer's
    result), or None when ready() gave up. The figures are the same as run one after another (each
    function draws and saves its own figure with its own random generator); only the wall time changes.
    One CPU: no workers."""
    workers = min(len(early), len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1)
    if workers <= 1:
        figures = {name: job() for name, job in early.items()}
        if not ready():
            return None
        figures.update({name: late_figure(name, out) for name in late_figure_names(report_data(out))})
        return figures, explorer_job()
    import concurrent.futures
    import multiprocessing
    _JOBS[:] = list(early.values())
    context = multiprocessing.get_context("fork")
    with concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        futures = {name: pool.submit(_run_job, i) for i, name in enumerate(early)}
        if not ready():
            pool.shutdown(wait=True, cancel_futures=True)
            return None
        for name in late_figure_names(report_data(out)):
            futures[name] = pool.submit(late_figure, name, out)
        explorer = explorer_job()
        figures = {name: future.result() for name, future in futures.items()}
    return figures, explorer


def _cells(values):
    return "".join(f"<td>{html.escape(str(v))}</td>" for v in values)


def _table(header, rows):
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    return f"<table><tr>{head}</tr>" + "\n".join(f"<tr>{_cells(r)}</tr>" for r in rows) + "</table>\n"


def _fmt(value, scale=1.0, digits=3):
    return "n/a" if not isinstance(value, (int, float)) else f"{value * scale:.{digits}g}"


def acquisition_thumbnails_html(out, data, align):
    """Each measurement photo (an even subset) with the sample's outline as the poses put it, in a grid captioned
    with the photo's index and whether it was used (align's verdict where it posed the photos, else whether it
    gave samples). `data["acquisition_thumbnails"]` is written by report/acquisition_thumbnails.cc."""
    thumbs = (data or {}).get("acquisition_thumbnails")
    if not thumbs or not thumbs.get("photos"):
        return ""
    posed = {image.get("photo"): image for image in (align or {}).get("images", [])}
    cells = []
    for photo in thumbs["photos"]:
        index = photo["index"]
        image = posed.get(index)
        if image is not None and not image.get("used"):
            state = "dropped: " + str(image.get("dropped", ""))
        elif photo.get("samples", 0) > 0:
            state = f"used, {photo['samples']} samples"
        else:
            state = "used" if image is not None else "no samples"
        if not photo.get("outline", True):
            state += "; no outline (no pose, or the sample is not in view)"
        if photo.get("file"):
            cells.append(f'<figure><img src="{embed(out, photo["file"])}" alt="{html.escape(photo["file"])}">'
                         f'<figcaption>photo {index}: {html.escape(state)}</figcaption></figure>')
        else:
            cells.append(f'<figure><figcaption>photo {index}: {html.escape(photo.get("note", "not read"))}'
                         f'</figcaption></figure>')
    shown, total = thumbs.get("shown", len(cells)), thumbs.get("measurement_photos", len(cells))
    subset = (f"{shown} of the {total} measurement photos (chosen evenly)" if shown < total
              else f"All {total} measurement photos")
    note = f" {html.escape(thumbs['note'])}." if thumbs.get("note") else ""
    return (f"<h3>The sample in each photo</h3><p>{subset}, each linearized, cropped to the sample and tone-mapped on one "
            f"scale for all (a dark photo reads dark), with the sample's outline (the sphere's limb, the cylinder's rims and limb lines, or the mesh's "
            f"silhouette edges) projected through the camera model, distortion included, from the photo's pose in "
            f"green: an outline beside the object is a pose or sample geometry that is off.{note}</p>"
            f'<div class="thumbs">' + "".join(cells) + "</div>\n")


def acquisition_html(run_dir, side, data=None, out=None):
    """What the calibration stages found (response/response.json, align/alignment.json,
    lights/white-reference.json, colour/colour.json): the verdicts as a pass/fail table, each photo's markers and residual, the
    sample's fit, the light, the white reference, the colour fit per patch, and the clipped pixels; and each photo with
    the sample's outline drawn over it (report data from `out`)."""
    align = load_json(os.path.join(run_dir, "align", "alignment.json"))
    white = load_json(os.path.join(run_dir, "lights", "white-reference.json"))
    colour = load_json(os.path.join(run_dir, "colour", "colour.json"))
    response = load_json(os.path.join(run_dir, "response", "response.json"))
    parts = []
    verdicts = []
    for stage_json in (response, align, white, colour):
        verdicts += (stage_json or {}).get("verdicts", [])
    if verdicts:
        names = {"ok": "pass", "warn": "warn", "fail": "FAIL"}
        parts.append("<h3>Checks</h3>" + _table(
            ["check", "verdict", "measured", "bound"],
            [[v.get("check"), names.get(v.get("verdict"), v.get("verdict")) + (" (accepted)" if v.get("accepted") else ""),
              v.get("measured"), v.get("bound")] for v in verdicts]))
    if align:
        rows = []
        for image in align.get("images", []):
            rows.append([image.get("photo"), "used" if image.get("used") else "dropped: " + str(image.get("dropped", "")),
                         image.get("markers"), image.get("light_markers"), image.get("outlier_corners"),
                         _fmt(image.get("rms_px")), _fmt(image.get("position_sigma_m"), 1e3),
                         _fmt(image.get("rotation_sigma_deg"))])
        parts.append(f"<h3>Photos posed</h3><p>Bundle adjustment: marker corner RMS {_fmt(align.get('rms_px'))} px over "
                     f"the used photos.</p>" + _table(
                         ["photo", "pose", "markers", "light markers", "outlier corners", "RMS px", "position sigma mm",
                          "rotation sigma deg"], rows))
    thumbnails = acquisition_thumbnails_html(out, data, align) if out else ""
    if thumbnails:
        parts.append(thumbnails)
    if align:
        sphere = align.get("sphere")
        if sphere:
            sigma = sphere.get("center_sigma_m", [None, None, None])
            parts.append("<h3>Sample</h3>" + _table(
                ["sphere centre (m)", "centre sigma (mm)", "radius (m)", "radius sigma (mm)", "silhouette points",
                 "limb balance", "radius known"],
                [[", ".join(_fmt(v, 1, 5) for v in sphere.get("center", [])), ", ".join(_fmt(v, 1e3) for v in sigma),
                  _fmt(sphere.get("radius"), 1, 5), _fmt(sphere.get("radius_sigma_m"), 1e3),
                  sphere.get("silhouette_points"), _fmt(sphere.get("limb_balance")), sphere.get("radius_known")]]))
        if "mesh_registration" in align:
            m = align["mesh_registration"]
            parts.append("<h3>Mesh registration</h3>" + _table(
                ["markers used", "corner RMS mm", "worst marker mm"],
                [[m.get("used_markers"), _fmt(m.get("rms_m"), 1e3), _fmt(m.get("max_marker_rms_m"), 1e3)]]))
        light = align.get("light")
        if light:
            if light.get("fitted"):
                parts.append("<h3>Light from its markers</h3>" + _table(
                    ["position (m)", "markers' spread (mm)"],
                    [[", ".join(_fmt(v, 1, 5) for v in light.get("position", [])), _fmt(light.get("spread_m"), 1e3)]]))
            else:
                parts.append(f"<h3>Light</h3><p>As the session states it ({html.escape(str(light.get('reason', '')))}).</p>")
    if response:
        parts.append(f"<h3>Camera response</h3><p>Measured from exposure brackets (ibrdf response): "
                     f"{html.escape(str(response.get('summary', '')))}</p>")
    if white:
        scalars = [[k, v] for k, v in white.items() if isinstance(v, (int, float, str)) and k not in ("format", "version")]
        parts.append("<h3>White reference</h3>" + _table(["field", "value"], scalars))
    if colour:
        rows = [[p.get("name"), "used" if "residual" in p else "left out: " + str(p.get("excluded", "")),
                 _fmt(p.get("residual"), 100), ", ".join(_fmt(v, 1, 4) for v in p.get("camera_rgb", []))]
                for p in colour.get("patches", [])]
        chart = ""
        chart_png = os.path.join(run_dir, "colour", "chart.png")
        if os.path.exists(chart_png):
            with open(chart_png, "rb") as f:
                chart = (f'<figure><img src="data:image/png;base64,{base64.b64encode(f.read()).decode("ascii")}" '
                         f'alt="chart.png" style="max-width:480px"><figcaption>the chart as located '
                         f'(colour/chart.png)</figcaption></figure>')
        parts.append(f"<h3>Colour chart</h3><p>{colour.get('patches_used')} patches used; residual RMS "
                     f"{_fmt(colour.get('rms_residual'), 100)} %, worst {_fmt(colour.get('max_residual'), 100)} %.</p>"
                     + chart + _table(["patch", "fit", "residual %", "camera RGB"], rows))
    rejected = side.get("counts", {}).get("rejected", {})
    clipped = {k: v for k, v in rejected.items() if "saturat" in k or "clip" in k}
    if clipped:
        parts.append("<h3>Clipping</h3>" + _table(["rejected as", "pixels"], [[k, v] for k, v in clipped.items()]))
    given = "<p>No calibration stage ran: the session's poses, sample and lights are used as given.</p>"
    if not parts:
        return '<h2 id="acquisition">Acquisition</h2>' + given
    if parts == [thumbnails]:
        return '<h2 id="acquisition">Acquisition</h2>' + "\n" + given + thumbnails
    return '<h2 id="acquisition">Acquisition</h2>' + "\n" + "\n".join(parts)


def uniformity_html(run_dir):
    """The uniformity check (uniformity/uniformity.json, docs/spatial.md): whether the sample is one material, its
    figures and the map of its surface cells drawn over a photo."""
    u = load_json(os.path.join(run_dir, "uniformity", "uniformity.json"))
    if not u:
        return ""
    verdict = next((v for v in u.get("verdicts", []) if v.get("check") == "uniformity.cells"), {})
    cells = u.get("cells", {})
    spread = ", ".join("n/a" if x is None else f"{x:.2f}x" for x in u.get("spread_p90_p10", []))
    text = (f"<p>Is the sample one material? Its surface in cells of {1e3 * u.get('cell_m', 0):.1f} mm, each cell's "
            f"samples against the reconstructed BRDF (the median ratio per channel): {cells.get('deviating')} of "
            f"{cells.get('scored')} cells deviate ({100 * u.get('deviating_fraction', 0):.1f} %); the cells' ratios "
            f"spread {spread} (90th over 10th percentile, R, G, B). Verdict: <b>{html.escape(str(verdict.get('verdict')))}"
            f"{' (accepted by the user)' if verdict.get('accepted') else ''}</b>: {html.escape(str(verdict.get('measured')))}"
            f"; bound: {html.escape(str(verdict.get('bound')))}.</p>")
    image = os.path.join(run_dir, "uniformity", u.get("map", "map.png"))
    if os.path.exists(image):
        with open(image, "rb") as f:
            text += (f'<figure><img src="data:image/png;base64,{base64.b64encode(f.read()).decode("ascii")}" '
                     f'alt="map.png" style="max-width:640px"><figcaption>where: each sample pixel of photo '
                     f'{u.get("map_photo")} coloured by its cell\'s ratio to the object\'s BRDF (red above, blue below, '
                     f'full colour at 2x; pale: within the bound) (uniformity/map.png)</figcaption></figure>')
    return "<h2>One material?</h2>\n" + text + materials_html(run_dir)


def materials_html(run_dir):
    """With `run --spatial` (materials/materials.json, docs/spatial.md): each group of cells measured as a material of
    its own, the blends and the samples in no basis, each cell's weights over the groups, the verdicts, one photo
    predicted from the model (with its picture), the mesh and pbrt-v4 outputs, and the scores against a synthetic
    truth."""
    m = load_json(os.path.join(run_dir, "materials", "materials.json"))
    if not m:
        return ""
    counts = m.get("samples", {})
    rows = []
    for g in m.get("groups", []):
        if "blend_of" in g:
            what = f"a blend of groups {g['blend_of'][0]} and {g['blend_of'][1]}: not reconstructed"
        elif g.get("reconstructed"):
            e = g.get("error_against_truth")
            what = (f"reconstructed in materials/{html.escape(g['folder'])}/"
                    + (f"; against {html.escape(g.get('truth_name', 'the truth'))}: relative RMS "
                       f"{100 * e['rel_rms_error_all']:.1f} %" if e else ""))
        else:
            what = "not reconstructed (too few samples, or the object's one material: reconstruction/)"
        rows.append(f"<tr><td>{g['group']}</td><td>{g['samples']}</td><td>{what}</td></tr>")
    labels = m.get("labels")
    score = (f" Against the synthetic map: labels right on {100 * labels['right_fraction']:.1f} % of "
             f"{labels['scored_samples']} samples away from its boundaries." if labels else "")
    text = (f"<h3>Materials (run --spatial)</h3>\n<p>Each group measured as a material of its own; "
            f"{counts.get('mixed', 0)} of {counts.get('rows', 0)} samples lie on a boundary or in a blend and are in no "
            f"group's reconstruction.{score} The BRDF above is still the whole object's average.</p>\n"
            f"<table><tr><th>group</th><th>samples</th><th>measured as</th></tr>{''.join(rows)}</table>\n")
    w = m.get("weights")
    if w:
        truth = w.get("truth")
        text += (f"<p>Each surface cell as a non-negative combination of groups {', '.join(str(b) for b in w['bases'])} "
                 f"(Lensch et al. 2003's projection): {w['cells_fitted']} cells fitted, "
                 f"{100 * w['not_fitting_fraction']:.1f} % fit no combination (materials.json's weights.cell_list), "
                 f"median residual {100 * w['median_rel_rms']:.1f} %"
                 + (f"; the weights are off the truth's by {100 * truth['error_median']:.1f} % median "
                    f"({100 * truth['mixed_error_median']:.1f} % in {truth['mixed_cells']} mixed cells)" if truth else "")
                 + ".</p>\n")
    for v in m.get("verdicts", []):
        text += (f"<p>materials {html.escape(v['check'])}: <b>{html.escape(v['verdict'])}</b>"
                 + (" (accepted by the user)" if v.get("accepted") else "")
                 + f": {html.escape(v.get('measured', ''))}; bound: {html.escape(v.get('bound', ''))}</p>\n")
    p = m.get("prediction")
    if p:
        def pct(x):
            return "n/a" if x is None else f"{100 * x:.1f} %"
        text += (f"<p>Photo {p['photo']} {'held out of this stage' if p['held_out'] else '(in the measurement)'} "
                 f"predicted from the model: {p['predicted']} of {p['samples']} samples, median |model / measured - 1| "
                 f"{pct(p['model_median_abs_rel_error_all'])}; the one average BRDF "
                 f"{pct(p['single_brdf_median_abs_rel_error_all'])}; the truth {pct(p['truth_median_abs_rel_error_all'])}"
                 f".</p>\n")
        image = os.path.join(run_dir, "materials", p["image"]) if p.get("image") else None
        if image and os.path.exists(image):
            with open(image, "rb") as f:
                text += (f'<figure><img src="data:image/png;base64,{base64.b64encode(f.read()).decode("ascii")}" '
                         f'alt="{html.escape(p["image"])}" style="max-width:960px"><figcaption>photo {p["photo"]}; the '
                         f'photo as the model renders its sample pixels (model / measured times the photo); the ratio '
                         f'(red: the model brighter, blue: darker, full colour at 1.5x) (materials/{html.escape(p["image"])})'
                         f'</figcaption></figure>\n')
    for key, what in (("mesh", "the mesh with each vertex's weights"), ("pbrt", "a pbrt-v4 scene of the photo")):
        part = m.get(key, {})
        if part.get("written"):
            name = part.get("file") or part.get("scene")
            text += f"<p>{what}: materials/{html.escape(name)}"
            if key == "pbrt" and part.get("ibrdf_image"):
                folder = os.path.dirname(name)
                text += (f"; ibrdf's own render of the same model, to compare pbrt's with: materials/"
                         f"{html.escape(os.path.join(folder, part['ibrdf_image']))} ({part.get('ibrdf_pixels', 0)} pixels)")
            if key == "pbrt" and part.get("mitsuba_scene"):
                text += f"; the same scene for Mitsuba 3: materials/{html.escape(part['mitsuba_scene'])}"
            text += "</p>\n"
        elif part:
            text += f"<p>{what}: not written ({html.escape(part.get('reason', ''))})</p>\n"
    return text


def notices_html(run_dir, side):
    """Every calibration verdict that is not ok (response, align, lights white, colour, uniformity, materials), the stages' warnings and the
    samples' scale, at the top of the report: what the run could not trust, or had to be told."""
    items = []
    if side.get("intensity_scale") == "relative":
        items.append(("relative scale", "the lights' intensities are known up to one common scale (ratios "
                      "measured, the scale not): every BRDF value here, the table and the fits are the material's "
                      "times one unknown constant"))
    align = load_json(os.path.join(run_dir, "align", "alignment.json")) or {}
    stage_jsons = [("response", load_json(os.path.join(run_dir, "response", "response.json")) or {}), ("align", align),
                   ("lights", load_json(os.path.join(run_dir, "lights", "white-reference.json")) or {}),
                   ("colour", load_json(os.path.join(run_dir, "colour", "colour.json")) or {}),
                   ("uniformity", load_json(os.path.join(run_dir, "uniformity", "uniformity.json")) or {}),
                   ("materials", load_json(os.path.join(run_dir, "materials", "materials.json")) or {})]
    for stage, stage_json in stage_jsons:
        for v in stage_json.get("verdicts", []):
            if v.get("verdict") == "ok":
                continue
            label = (f"{stage} {v.get('check')}: {v.get('verdict')}" +
                     (" (accepted by the user)" if v.get("accepted") else ""))
            items.append((label, f"{v.get('measured')}; bound: {v.get('bound')}; remedy: {v.get('remedy')}"))
    for w in align.get("warnings", []):
        items.append(("align", w))
    for w in side.get("exposure", {}).get("warnings", []):
        if isinstance(w, dict) and "message" in w:
            items.append(("derender", w["message"]))
    if not items:
        return "<p>Verdicts: every calibration check ok; no stage warned.</p>"
    rows = "\n".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>" for k, v in items)
    return f"<h2>Verdicts and warnings</h2>\n<table>{rows}</table>"


def main():
    args = [a for a in sys.argv[1:] if a != "--data-later"]
    data_later = len(args) + 1 < len(sys.argv)
    if len(args) != 2:
        sys.exit("usage: report.py RUN_DIR OUT_DIR [--data-later]")
    run_dir, out = args
    ready = (lambda: wait_for_data(out)) if data_later else (lambda: True)
    try:
        s = np.load(os.path.join(run_dir, "samples.npy"), mmap_mode="r")  # read where the figures use it
        side = load_json(os.path.join(run_dir, "samples.npy.json")) or {}
        c = load_json(os.path.join(run_dir, "consistency.json"))
        t = load_json(os.path.join(run_dir, "truth-comparison.json"))
        times = stamps(run_dir)
    except Exception:
        # Started early (--data-later): a run folder `ibrdf report` refuses is its error to report.
        if data_later and not ready():
            sys.exit(3)
        raise

    early = {
        # The slowest first (the coverage figure takes the most CPU of these on the demo).
        "coverage": lambda: coverage_figure(s, out),
        "reciprocity": lambda: consistency_figure(c, "reciprocity", "Reciprocity: each sample against the measured "
                                                  "sample nearest its reciprocal point f(te, ti, -dphi)", out),
        "bilateral": lambda: consistency_figure(c, "bilateral_symmetry", "Bilateral symmetry: each sample against "
                                                "the measured sample nearest f(ti, te, -dphi)", out),
        "timings": lambda: timings_figure(times, side.get("counts", {}), out),
        "bands": lambda: truth_bands_figure(t, out),
    }

    def explorer_job():
        data = report_data(out)
        return write_explorer(data, out, data.get("title") or os.path.basename(os.path.abspath(run_dir)))

    result = run_figures(early, out, ready, explorer_job)
    if result is None:
        sys.exit(3)
    figures, explorer = result
    data = report_data(out)
    recon = data.get("reconstruction")
    r = load_json(os.path.join(os.path.dirname(recon), "summary.json")) if recon else None
    title = data.get("title") or os.path.basename(os.path.abspath(run_dir))
    rows = headline_rows(s, side, c, t, r, data, times)
    table = "\n".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in rows)
    explorer_link = (f'<p><a href="{explorer}">Open the BRDF explorer</a> (explorer.html beside this file: '
                     'sliders for the incidence angle and slice azimuth, polar and Cartesian plots, linear/log, '
                     'samples, table and fits overlaid, a theta_h x theta_d slice, a lit sphere under a movable '
                     'light, a second BRDF file to compare against; offline).</p>') if explorer else ""

    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>ibrdf report: {html.escape(title)}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; max-width: 1500px; }}
table {{ border-collapse: collapse; }} th, td {{ border: 1px solid #ccc; padding: 3px 8px; text-align: left; }}
th {{ font-weight: normal; color: #444; }} figure {{ display: inline-block; margin: 0.5em; vertical-align: top; }}
figure img {{ max-width: 100%; }} figcaption {{ font-size: 0.85em; color: #555; max-width: 24em; }}
.thumbs figure {{ margin: 0.3em; }} .thumbs figcaption {{ max-width: 200px; }}
</style></head><body>
<h1>ibrdf consistency report: {html.escape(title)}</h1>
<p>Run folder: <code>{html.escape(os.path.abspath(run_dir))}</code>. Figures after Marschner et al. 1999, Image-Based
BRDF Measurement. Every figure is embedded in this file; the same PNGs lie beside it.</p>
{explorer_link}
{notices_html(run_dir, side)}
<h2>Headline figures</h2>
<table>{table}</table>
<h2>The sample itself</h2>
<p>The measured photo at full resolution beside each model rendered from the same camera, geometry and light: at every
pixel that gave a sample, f_model(wi, wo) times the irradiance term E cos(theta_i) the derenderer divided by
(so sphere, cylinder or scanned mesh alike, shadows included), on the photo's tone scale; and the signed difference.</p>
{appearance_html(data, out, figures)}
{held_out_html(data, out, figures)}
{lights_section(out, data)}
{acquisition_html(run_dir, side, data, out)}
{uniformity_html(run_dir)}
<h2>Sample coverage</h2>
{figure_html(out, figures['coverage'], 'exitant directions sampled at each incidence angle')}
<h2>Incidence plane, three colour channels</h2>
{figure_html(out, figures['plane'], 'fixed-incidence and fixed-exitance samples; each model evaluated at the samples themselves (solid) and in the exact plane (dotted)')}
<h2>Reciprocity and bilateral symmetry</h2>
{figure_html(out, figures['reciprocity_curves'], 'the paper figure: fixed-incidence against fixed-exitance curves')}
{figure_html(out, figures['reciprocity'], 'reciprocal sample pairs, binned')}
{figure_html(out, figures['bilateral'], 'mirrored sample pairs, binned')}
{('<h2>Against the truth</h2>' + figure_html(out, figures['bands'], 'median relative error by band')) if figures['bands'] else ''}
<h2>Timings and rejected samples</h2>
{figure_html(out, figures['timings'], 'stage wall-clock times and pixels rejected by reason')}
</body></html>
"""
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write(page)


if __name__ == "__main__":
    main()
