"""ibrdf.run: the whole workflow from Python writes what `ibrdf run` writes into the same folder, byte
for byte, except the times its JSON files record (stage seconds, timings_s) and the report's two files
that show the stage times (the timings figure, and the page that embeds it with the times' rows)."""
import filecmp
import json
import os
import shutil
import signal
import subprocess
import threading

import pytest

import ibrdf

# JSON keys whose values are wall-clock or CPU times, or file modification times (the stamps').
TIME_KEYS = {"timings_s", "seconds", "decode_cpu", "total", "mtime_ns"}
# Files that show the stage times: compared by presence only.
TIMED_FILES = {"report/timings.png", "report/index.html"}


def files_of(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def without_times(value):
    """A JSON value with every time (TIME_KEYS, keys ending in _s) left out, and the size a stamp records
    of a JSON file (its times' digits vary)."""
    if isinstance(value, dict):
        timed_json = str(value.get("path", "")).endswith(".json")
        return {k: without_times(v) for k, v in value.items()
                if not (k.endswith("_s") or k in TIME_KEYS or (timed_json and k == "size"))}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


def compare_runs(cli, python):
    """Asserts that the run folders `cli` and `python` (made at the same path, then moved) hold the same
    files with the same bytes, JSON files compared without their times; returns the files compared."""
    names = files_of(cli)
    assert names == files_of(python)
    different = []
    for name in names:
        if filecmp.cmp(cli / name, python / name, shallow=False):
            continue
        if name.endswith(".json"):
            a, b = (without_times(json.loads((f / name).read_text())) for f in (cli, python))
            if a == b:
                continue
        if name.startswith("logs/") or name in TIMED_FILES:
            continue  # the stages' own output with its timing lines; the report's times
        different.append(name)
    assert not different, f"differ: {different}"
    return names


def run_both(input_path, tmp_path, cli_flags=(), **options):
    """`ibrdf run` and ibrdf.run of the same input into the same folder, moved to tmp_path/cli and
    tmp_path/python after each; returns ibrdf.run's summary."""
    folder = tmp_path / "run"
    subprocess.run([ibrdf.tool_path(), "--silent", "run", str(input_path), "--out", str(folder), *cli_flags],
                   check=True, stdout=subprocess.DEVNULL)
    shutil.move(folder, tmp_path / "cli")
    summary = ibrdf.run(str(input_path), str(folder), **options)
    shutil.move(folder, tmp_path / "python")
    return summary


def test_run_is_the_clis(small_session, tmp_path):
    summary = run_both(small_session, tmp_path, ["--no-report"], report=False)
    assert summary["format"] == "ibrdf-run"
    assert len(compare_runs(tmp_path / "cli", tmp_path / "python")) > 10


def test_run_resumes(small_session, tmp_path):
    ibrdf.run(str(small_session), str(tmp_path / "r"), report=False, stop_after="derender")
    summary = ibrdf.run(str(small_session), str(tmp_path / "r"), report=False, stop_after="derender")
    assert summary["stages"]["derender"]["status"] == "skipped"


def test_run_refuses_another_inputs_folder(small_session, tmp_path, source):
    ibrdf.run(str(small_session), str(tmp_path / "r"), report=False, stop_after="derender")
    with pytest.raises(ibrdf.Error, match="another input"):
        ibrdf.run(str(source / "samples/bluepaint-sphere"), str(tmp_path / "r"), stop_after="synth")


def test_run_bad_option():
    with pytest.raises(ValueError, match="stride"):
        ibrdf.run("samples/bluepaint-sphere", "/tmp/never", pixel_stride=0)


def test_ctrl_c_stops_the_run_after_its_stage(small_session, tmp_path):
    threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
    with pytest.raises(KeyboardInterrupt):
        ibrdf.run(str(small_session), str(tmp_path / "r"), report=False)
    assert not (tmp_path / "r" / "summary.json").exists()
