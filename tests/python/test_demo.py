"""The demo (scripts/demo: samples/bluepaint-sphere) from Python and from the CLI: the same run
folder, byte for byte (times aside, test_run.compare_runs), report included."""
from test_run import compare_runs, run_both


def test_demo_is_the_clis(source, tmp_path):
    summary = run_both(source / "samples/bluepaint-sphere", tmp_path)
    assert max(summary["truth"]["samples_median_rel_error"]) < 0.05
    compare_runs(tmp_path / "cli", tmp_path / "python")
