#!/usr/bin/python3
"""The README's demo figures, regenerated from a run rather than typed, so they cannot go stale.

Usage: scripts/readme_figures.py RUN_DIR [--update README.md]
       scripts/readme_figures.py --check README.md

Prints the lines `scripts/demo` ends with (the headline figures) and the table of stage times, from
RUN_DIR/summary.json (an `ibrdf run` of samples/bluepaint-sphere; `scripts/demo` makes one in
demo-out/bluepaint-sphere). With --update, replaces what lies between the markers
`<!-- readme-figures -->` and `<!-- /readme-figures -->` of the README with them (a code block, the
stage-time table and a line saying when and from what it was regenerated). With --check, exits non-zero
unless the README's block has exactly this script's format (every line, not the values): a block typed
by hand or left from an older format fails.
"""
import datetime
import json
import os
import re
import sys

BEGIN, END = "<!-- readme-figures -->", "<!-- /readme-figures -->"
STAGES = ["synth", "scan", "align", "derender", "check", "compare", "reconstruct", "uniformity", "report"]

# The format of every line of the block, in order (a regular expression per line; NUM a number).
NUM = r"[0-9]+(?:\.[0-9]+)?"
PCT = NUM + " %"
RGB = f"{PCT}, {PCT}, {PCT}"
HEADLINE_FORMATS = [
    rf"[0-9]+ samples from [0-9]+ photos; stages took {NUM} s \(wall clock, as recorded\)"
    rf"(?:; the run {NUM} s, check and compare beside reconstruct)?",
    rf"Median relative error of the samples against the true BRDF \(R, G, B\): {RGB} \(bound: 5 %\)",
    rf"Reciprocity error (?:{PCT}|n/a), bilateral-symmetry error (?:{PCT}|n/a) \(medians over bins; "
    rf"95th percentiles (?:{PCT}|n/a), (?:{PCT}|n/a)\)",
    rf"Reconstructed BRDF against the truth, relative RMS over [0-9]+ MERL cells \(R, G, B\): {RGB}",
    r"Report: \S+/report/index\.html",
]
TABLE_HEADER = ["| stage | wall clock, s | share |", "| --- | ---: | ---: |"]
TABLE_ROW = rf"\| ({'|'.join(STAGES)}|total) \| {NUM} \| {NUM} % \|"
STAMP = r"\(regenerated [0-9]{4}-[0-9]{2}-[0-9]{2} from `\S+/summary.json` by `scripts/readme_figures.py`\)"


def pct(x):
    return "n/a" if x is None else f"{100 * x:.2f} %"


def headline(s):
    """The headline lines (the code block)."""
    timings = s.get("timings_s", {})
    samples = s.get("samples", {})
    out = [f"{samples.get('accepted', 0)} samples from {samples.get('photos', 0)} photos; stages took "
           f"{timings.get('stages_total', 0.0):.1f} s (wall clock, as recorded)"]
    # With check and compare beside reconstruct (docs/workflow.md) the stages' sum exceeds the run's wall.
    run_s = timings.get("this_invocation")
    if run_s is not None and run_s < timings.get("stages_total", 0.0) - 0.05:
        out[0] += f"; the run {run_s:.1f} s, check and compare beside reconstruct"
    t = s.get("truth") or {}
    if t.get("samples_median_rel_error"):
        out.append("Median relative error of the samples against the true BRDF (R, G, B): "
                   f"{', '.join(pct(x) for x in t['samples_median_rel_error'])} (bound: 5 %)")
    c = s.get("consistency") or {}
    if c:
        bilateral = c.get("bilateral_symmetry", c.get("isotropy"))  # isotropy: a summary of the previous release
        out.append(f"Reciprocity error {pct(c.get('reciprocity'))}, bilateral-symmetry error {pct(bilateral)} "
                   f"(medians over bins; 95th percentiles {pct(c.get('reciprocity_p95'))}, "
                   f"{pct(c.get('bilateral_symmetry_p95'))})")
    if t.get("brdf_rel_rmse"):
        out.append(f"Reconstructed BRDF against the truth, relative RMS over {t['brdf_cells_scored']} MERL cells "
                   f"(R, G, B): {', '.join(pct(x) for x in t['brdf_rel_rmse'])}")
    if s.get("report"):
        out.append(f"Report: {s['report']}")
    return out


def stage_table(s):
    """The stage times as recorded in summary.json, a Markdown table."""
    timings = s.get("timings_s", {})
    total = timings.get("stages_total") or sum(timings.get(n, 0.0) for n in STAGES)
    rows = list(TABLE_HEADER)
    for name in STAGES:
        if name in timings:
            share = 100 * timings[name] / total if total > 0 else 0.0
            rows.append(f"| {name} | {timings[name]:.1f} | {share:.0f} % |")
    rows.append(f"| total | {total:.1f} | 100 % |")
    return rows


def block(run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)
    stamp = (f"(regenerated {datetime.date.today().isoformat()} from `{os.path.abspath(run_dir)}/summary.json` by "
             "`scripts/readme_figures.py`)")
    return ["```"] + headline(s) + ["```", ""] + stage_table(s) + ["", stamp]


def split(text, readme):
    if BEGIN not in text or END not in text:
        sys.exit(f"{readme}: no {BEGIN} ... {END} markers")
    head, rest = text.split(BEGIN, 1)
    body, tail = rest.split(END, 1)
    return head, body, tail


def update(readme, lines):
    with open(readme) as f:
        head, _, tail = split(f.read(), readme)
    tmp = readme + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"{head}{BEGIN}\n" + "\n".join(lines) + f"\n{END}{tail}")
    os.replace(tmp, readme)


def check(readme):
    """The README's block against this script's format; returns the problems (empty: it matches)."""
    with open(readme) as f:
        _, body, _ = split(f.read(), readme)
    lines = body.strip("\n").split("\n")
    problems = []
    try:
        first, last = lines.index("```"), lines.index("```", 1)
    except ValueError:
        return [f"{readme}: the block has no ``` code block of headline lines"]
    code = lines[first + 1:last]
    # The samples line first; then, in order, those of the others the run has (truth, report: optional).
    if not code or not re.fullmatch(HEADLINE_FORMATS[0], code[0]):
        problems.append(f"{readme}: the first headline line is not the script's samples line: "
                        f"{code[0] if code else ''!r}")
    at = 1
    for line in code[1:]:
        while at < len(HEADLINE_FORMATS) and not re.fullmatch(HEADLINE_FORMATS[at], line):
            at += 1
        if at == len(HEADLINE_FORMATS):
            problems.append(f"{readme}: headline line not in the script's format (or out of order): {line!r}")
            break
        at += 1
    rest = [line for line in lines[last + 1:] if line.strip()]
    table = [line for line in rest if line.startswith("|")]
    if table[:2] != TABLE_HEADER:
        problems.append(f"{readme}: no stage-time table with the header {TABLE_HEADER[0]!r}")
    rows = table[2:]
    if not rows or not rows[-1].startswith("| total |"):
        problems.append(f"{readme}: the stage-time table has no total row")
    for row in rows:
        if not re.fullmatch(TABLE_ROW, row):
            problems.append(f"{readme}: stage-time row not in the script's format: {row!r}")
    others = [line for line in rest if not line.startswith("|")]
    if len(others) != 1 or not re.fullmatch(STAMP, others[0]):
        problems.append(f"{readme}: no line saying when and from what the block was regenerated")
    return problems


def main():
    args = sys.argv[1:]
    if len(args) == 2 and args[0] == "--check":
        problems = check(args[1])
        if problems:
            sys.exit("\n".join(problems + ["regenerate it: scripts/readme_figures.py RUN_DIR --update README.md"]))
        print(f"{args[1]}: the figures block has the format of scripts/readme_figures.py")
        return
    if not args or args[0].startswith("-"):
        sys.exit(__doc__)
    run_dir = args[0]
    if not os.path.isfile(os.path.join(run_dir, "summary.json")):
        sys.exit(f"{run_dir}/summary.json: does not exist (expected the folder of an `ibrdf run`)")
    lines = block(run_dir)
    if len(args) == 3 and args[1] == "--update":
        update(args[2], lines)
    elif len(args) != 1:
        sys.exit(__doc__)
    print("\n".join(line for line in lines if line not in ("```",)))


if __name__ == "__main__":
    main()
