#!/usr/bin/python3
"""The README's demo figures, regenerated from a run rather than typed (issue 16).

Usage: scripts/readme_figures.py RUN_DIR [--update README.md]

Prints the lines `scripts/demo` ends with, from RUN_DIR/summary.json (an `ibrdf run` of
samples/bluepaint-sphere; `scripts/demo` makes one in demo-out/bluepaint-sphere). With --update, replaces
the code block between the markers `<!-- readme-figures -->` and `<!-- /readme-figures -->` of the README
with them, so the README shows what a run printed, with the date it was regenerated.
"""
import datetime
import json
import os
import sys

BEGIN, END = "<!-- readme-figures -->", "<!-- /readme-figures -->"


def lines(run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)

    def pct(values):
        return ", ".join(f"{100 * x:.2f} %" for x in values)

    out = [f"{s['samples']['accepted']} samples; stages took {s['timings_s']['stages_total']:.1f} s"]
    t = s.get("truth") or {}
    if t.get("samples_median_rel_error"):
        out.append("Median relative error of the samples against the true BRDF (R, G, B): "
                   f"{pct(t['samples_median_rel_error'])} (bound: 5 %)")
    c = s.get("consistency") or {}
    bilateral = c.get("bilateral_symmetry", c.get("isotropy"))
    if c.get("reciprocity") is not None and bilateral is not None:
        out.append(f"Reciprocity error {100 * c['reciprocity']:.2f} %, bilateral-symmetry error {100 * bilateral:.2f} %")
    if t.get("brdf_rel_rmse"):
        out.append(f"Reconstructed BRDF against the truth, relative RMS over {t['brdf_cells_scored']} MERL cells "
                   f"(R, G, B): {pct(t['brdf_rel_rmse'])}")
    if s.get("report"):
        out.append(f"Report: {s['report']}")
    return out


def update(readme, block):
    with open(readme) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{readme}: no {BEGIN} ... {END} markers to replace between")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    stamp = datetime.date.today().isoformat()
    new = (f"{head}{BEGIN}\n```\n" + "\n".join(block) + f"\n```\n(regenerated {stamp} by "
           f"`scripts/readme_figures.py`; stage times are wall clock as recorded on the machine that ran it)\n{END}{tail}")
    tmp = readme + ".tmp"
    with open(tmp, "w") as f:
        f.write(new)
    os.replace(tmp, readme)


def main():
    args = sys.argv[1:]
    if not args or args[0].startswith("-"):
        sys.exit(__doc__)
    run_dir = args[0]
    if not os.path.isfile(os.path.join(run_dir, "summary.json")):
        sys.exit(f"{run_dir}/summary.json: does not exist (expected the folder of an `ibrdf run`)")
    block = lines(run_dir)
    if len(args) == 3 and args[1] == "--update":
        update(args[2], block)
    elif len(args) != 1:
        sys.exit(__doc__)
    print("\n".join(block))


if __name__ == "__main__":
    main()
