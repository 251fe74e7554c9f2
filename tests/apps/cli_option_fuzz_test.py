#!/usr/bin/python3
"""The CLI's options fuzzed: for every subcommand (nested ones too) the flags and their kinds are read
from its --help (CLI11's listing), and seeded random flag sets and values are run against a small
synthetic session, its run folder and files made in a temporary folder. Every run must end in
success (0) or a clear error (1 or 2, with a message), never a signal, an internal check, an
uncaught exception, a sanitizer report or a hang (a timeout per run).

Usage: cli_option_fuzz_test.py IBRDF_BINARY SOURCE_DIR [--runs N] [--seed S] [--jobs J]
Reproduce one case: the failure report prints its command line and its case id (SUBCOMMAND#I); the
cases depend only on the seed, not on the order they run in.
"""
import argparse
import concurrent.futures
import json
import os
import random
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

# Output that only a defect prints.
FORBIDDEN = ["Check failed", "assert", "terminate called", "what():", "Segmentation fault", "core dumped",
             "AddressSanitizer", "runtime error:", "std::bad_alloc", "basic_string", "stoi", "stod",
             "filesystem error", "nlohmann", "[json.exception"]

# Values a user would give (so that cases get past the parser into the stage) and hostile ones.
PLAUSIBLE = {"int": ["1", "2", "3"], "float": ["0.25", "1", "3", "30"],
             "text": ["s", "s/session.json", "r/samples.npy", "m.json", "r", "mirror", "s/truth.json", "w"],
             "args": ["--stride 2", ""]}
INT_VALUES = ["-1", "0", "1", "2", "3", "-2147483649", "2147483648", "99999999999999999999", "1.5", "x", ""]
FLOAT_VALUES = ["-1", "0", "1e-9", "0.25", "1", "3", "90", "1e300", "-1e300", "nan", "inf", "-inf", "x", "1e", ""]
TEXT_VALUES = ["", "-", "x", "nonexistent/file.json", "a" * 300, "s", "s/session.json", "s/truth.json",
               "s/photos/000.png", "r", "r/samples.npy", "r/samples.npy.json", "r/reconstruction", "tri.ply",
               "m.json", "rec", "rec/recipe.json", "b.json", "mirror", "mirror/session.json", "broken.json",
               "empty.npy", "--overwrite", "-q", "\u00e9t\u00e9", "d i r"]
ARGS_VALUES = ["", "--stride 2", "--bogus", "--degree 9", "--out x", "'", "--max-theta-deg nan", "-- x"]
OUTPUT_OPTIONS = {"--out", "--write-session"}

OPTION_LINE = re.compile(r'^  (?:-\w,)?(--[A-Za-z0-9][\w-]*)(.*)$')
POSITIONAL_LINE = re.compile(r'^  ([a-z_][\w]*) (TEXT(?::FILE|:DIR)?)( \.\.\.)?( REQUIRED)?')
SUBCOMMAND_LINE = re.compile(r'^  ([a-z][\w-]*)(\s{2,}|$)')
KIND = re.compile(r'^ (TEXT|INT|UINT|FLOAT|VALUE|"ARGS")(:\{([^}]*)\}|:FILE|:DIR)?( x (\d+))?(=\S+)?( \.\.\.)?')


def run(binary, args, cwd, timeout=60):
    return subprocess.run([binary] + args, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=timeout, text=True, errors="replace")


def parse_help(text):
    """(options, positionals, subcommands) of a CLI11 --help listing."""
    options, positionals, subcommands, section = [], [], [], None
    for line in text.splitlines():
        if re.match(r'^[A-Z][A-Za-z ]*:\s*$', line) or re.match(r'^(Positionals|Options|Subcommands):', line):
            section = line.split(":")[0].strip()
            continue
        if section == "Options":
            m = OPTION_LINE.match(line)
            if not m or m.group(1) in ("--help", "--version"):
                continue
            rest = m.group(2)
            k = KIND.match(rest)
            if not k:
                options.append({"flag": m.group(1), "kind": "flag"})
                continue
            kind = {"TEXT": "text", "VALUE": "text", '"ARGS"': "args", "INT": "int", "UINT": "int",
                    "FLOAT": "float"}[k.group(1)]
            option = {"flag": m.group(1), "kind": kind, "count": int(k.group(5) or 1), "vector": bool(k.group(7))}
            if k.group(3) is not None:
                option["kind"], option["choices"] = "choice", k.group(3).split(",")
            options.append(option)
        elif section == "Positionals":
            m = POSITIONAL_LINE.match(line)
            if m:
                positionals.append({"name": m.group(1), "many": bool(m.group(3)), "required": bool(m.group(4))})
        elif section == "Subcommands":
            m = SUBCOMMAND_LINE.match(line)
            if m:
                subcommands.append(m.group(1))
    return options, positionals, subcommands


def discover(binary, cwd, path=()):
    """{subcommand path: (options, positionals)} for every leaf subcommand."""
    out = run(binary, list(path) + ["--help"], cwd)
    if out.returncode != 0:
        raise SystemExit("%s --help failed (%d): %s" % (" ".join(path), out.returncode, out.stdout[-500:]))
    options, positionals, subcommands = parse_help(out.stdout)
    leaves = {}
    if path and not subcommands:
        if not options:
            raise SystemExit("%s --help lists no options: the listing format changed" % " ".join(path))
        leaves[path] = (options, positionals)
    for sub in subcommands:
        leaves.update(discover(binary, cwd, path + (sub,)))
    return leaves


def make_fixtures(binary, source, tmp):
    def must(args):
        out = run(binary, ["--silent"] + args, tmp, timeout=300)
        if out.returncode != 0:
            raise SystemExit("fixture `ibrdf %s` failed: %s" % (" ".join(args), out.stdout[-2000:]))
    shutil.copy(os.path.join(source, "samples", "materials", "lambertian50.json"), os.path.join(tmp, "m.json"))
    must(["synth", "--material", "m.json", "--out", "s", "--width", "32", "--height", "24", "--photos", "3"])
    must(["run", "s", "--out", "r", "--no-report", "--no-fits"])
    # A session whose light intensity comes from a white reference (`lights white`'s input).
    must(["synth", "--material", "m.json", "--out", "w", "--width", "32", "--height", "24", "--photos", "3",
          "--light-unknown"])
    must(["lights", "synth", "--out", "mirror", "--lights", "2", "--focal-px", "300"])
    os.makedirs(os.path.join(tmp, "rec"))
    with open(os.path.join(tmp, "rec", "recipe.json"), "w") as f:
        json.dump({"format": "ibrdf-recipe", "version": 1, "name": "rec", "material": "../m.json",
                   "synth": ["--width", "32", "--height", "24", "--photos", "3"]}, f)
    with open(os.path.join(tmp, "b.json"), "w") as f:
        json.dump({"format": "ibrdf-batch", "version": 1, "out": "bout", "sessions": ["s", "rec"]}, f)
    with open(os.path.join(tmp, "tri.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n0.01 0 0\n0 0.01 0\n3 0 1 2\n")
    with open(os.path.join(tmp, "broken.json"), "w") as f:
        f.write('{"format": "ibrdf-session", "version": 2, "camera": ')
    open(os.path.join(tmp, "empty.npy"), "w").close()


# A valid, cheap command line per subcommand: ("pinned" arguments are never dropped, so that no case
# runs a full batch through Snakemake or renders full-size photos). OUT is replaced by a fresh path.
BASE = {
    ("targets",): ([], ["--out", "OUT", "--dpi", "72"]),
    ("session", "init"): ([], ["s/photos/000.png", "s/photos/001.png", "--out", "OUT"]),
    ("capture", "check"): (["--samples-per-view", "400", "--suggest", "1", "--azimuth-step-deg", "60"],
                           ["s", "--out", "OUT"]),
    ("synth",): (["--width", "32", "--height", "24", "--photos", "3"], ["--material", "m.json", "--out", "OUT"]),
    ("scan",): ([], ["tri.ply", "--out", "OUT.ply"]),
    ("lights", "calibrate"): ([], ["mirror", "--out", "OUT.json"]),
    ("lights", "white"): ([], ["w", "--out", "OUT"]),
    ("lights", "synth"): (["--lights", "2", "--focal-px", "300"], ["--out", "OUT"]),
    ("align",): ([], ["s", "--out", "OUT"]),
    ("colour",): ([], ["s", "--out", "OUT"]),
    ("response",): ([], ["s", "--out", "OUT"]),
    ("derender",): (["--stride", "2"], ["s", "--out", "OUT.npy"]),
    ("reconstruct",): (["--no-fits", "--no-bsdf"], ["r/samples.npy", "--out", "OUT"]),
    ("check",): ([], ["r/samples.npy", "--out", "OUT.json"]),
    ("uniformity",): ([], ["r/samples.npy", "--brdf", "r/reconstruction/brdf.binary", "--out", "OUT"]),
    ("materials",): (["--no-fits", "--no-bsdf"],
                     ["r/samples.npy", "--uniformity", "r/uniformity/uniformity.json", "--out", "OUT"]),
    ("report",): (["--render-size-px", "32", "--no-explorer"], ["r", "--out", "OUT", "--held-out", "0"]),
    ("run",): (["--no-report", "--no-fits", "--stride", "2"], ["s", "--out", "OUT"]),
    ("batch",): (["-n"], ["b.json"]),
    ("library",): (["--sphere-size-px", "16"], ["r", "--out", "OUT"]),
    ("compare",): ([], ["r/samples.npy", "--truth", "s/truth.json"]),
}
# Options whose random values would make a case run for minutes (a full batch, full-size renders,
# the report's held-out refits).
SLOW = {("batch",): {"--cores", "--slurm", "--profile", "--snakemake-args", "-n", "--dry-run"},
        ("synth",): {"--shape", "--scan-spacing-m", "--truth-mesh-spacing-m", "--exposure-target"},
        ("lights", "synth"): {"--focal-px", "--radius-m", "--distance-m"},
        ("targets",): {"--dpi"},
        ("capture", "check"): {"--samples-per-view", "--candidate-samples-per-view", "--elevation-step-deg",
                               "--azimuth-step-deg"},
        ("report",): {"--held-out"},
        ("compare",): {"--lookups"},
        ("reconstruct",): {"--fit-samples", "--fit-start-samples", "--bandwidth-samples"}}


def value(rng, option, fresh):
    kind = option["kind"]
    if option["flag"] in OUTPUT_OPTIONS:
        return [fresh()]
    if kind == "flag":
        return []
    if kind == "choice":
        return [rng.choice(option["choices"] + ["bogus", ""])]
    pool = {"int": INT_VALUES, "float": FLOAT_VALUES, "text": TEXT_VALUES, "args": ARGS_VALUES}[kind]
    if rng.random() < 0.5:
        pool = PLAUSIBLE[kind]
    count = option["count"]
    if option["vector"]:
        count = rng.randint(1, 3)
    elif count > 1 and rng.random() < 0.2:
        count = rng.choice([count - 1, count + 1])
    return [rng.choice(pool) for _ in range(count)]


def make_case(seed, path, options, positionals, index):
    rng = random.Random("%d/%s/%d" % (seed, " ".join(path), index))
    counter = [0]

    def fresh():
        counter[0] += 1
        return "out/%s-%d-%d" % ("-".join(path), index, counter[0])
    free, pinned = BASE[path]
    args = [fresh() if a == "OUT" else fresh() + a[3:] if a.startswith("OUT.") else a for a in pinned]
    free = list(free)
    if free and rng.random() < 0.2:
        del free[rng.randrange(len(free))]
    slow = SLOW.get(path, set())
    candidates = [o for o in options if o["flag"] not in slow]
    for option in rng.sample(candidates, min(len(candidates), rng.randint(1, 4))):
        args += [option["flag"]] + value(rng, option, fresh)
    if rng.random() < 0.15 and positionals:
        args.append(rng.choice(TEXT_VALUES))  # one positional too many, or one more input
    if rng.random() < 0.1:
        args += ["--threads", rng.choice(["0", "-1", "1", "x"])]
    return list(path) + free + args


def verdict(out):
    if out is None:
        return "hang (no exit within the timeout)"
    if out.returncode < 0:
        return "killed by signal %d" % -out.returncode
    if out.returncode not in (0, 1, 2):
        return "exit code %d" % out.returncode
    for word in FORBIDDEN:
        if word in out.stdout:
            return "output holds %r" % word
    if out.returncode != 0 and not out.stdout.strip():
        return "exit %d without a message" % out.returncode
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary")
    parser.add_argument("source")
    parser.add_argument("--runs", type=int, default=12, help="cases per subcommand")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=4)
    parser.add_argument("--timeout", type=float, default=120, help="seconds one case may run (a hang)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    a = parser.parse_args()
    binary = os.path.abspath(a.binary)
    tmp = tempfile.mkdtemp(prefix="ibrdf-cli-fuzz-")
    start = time.time()
    try:
        make_fixtures(binary, os.path.abspath(a.source), tmp)
        os.makedirs(os.path.join(tmp, "out"))
        leaves = discover(binary, tmp)
        missing = sorted(" ".join(p) for p in leaves if p not in BASE)
        if missing:
            raise SystemExit("no base command line for: %s (add it to BASE)" % ", ".join(missing))
        cases = []
        for path, (options, positionals) in sorted(leaves.items()):
            for i in range(a.runs):
                cases.append(("%s#%d" % (" ".join(path), i), make_case(a.seed, path, options, positionals, i)))
        fixtures_s = time.time() - start

        def one(case):
            try:
                out = run(binary, ["--silent"] + case[1], tmp, timeout=a.timeout)
            except subprocess.TimeoutExpired:
                out = None
            return case, out

        failures, codes = [], {0: 0, 1: 0, 2: 0}
        with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
            for (name, args), out in pool.map(one, cases):
                why = verdict(out)
                if out is not None and out.returncode in codes:
                    codes[out.returncode] += 1
                if why:
                    failures.append("%s: %s\n  ibrdf --silent %s\n  %s" % (
                        name, why, " ".join(shlex.quote(x) for x in args),
                        (out.stdout.strip()[-800:] if out else "").replace("\n", "\n  ")))
        print("%d subcommands, %d cases (seed %d): %d exit 0, %d exit 1, %d exit 2; fixtures %.1f s, total %.1f s"
              % (len(leaves), len(cases), a.seed, codes[0], codes[1], codes[2], fixtures_s, time.time() - start))
        if codes[0] == 0:
            failures.append("no case succeeded: the base command lines no longer run")
        for f in failures:
            print("FAIL " + f)
        return 1 if failures else 0
    finally:
        if a.keep:
            print("kept", tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
