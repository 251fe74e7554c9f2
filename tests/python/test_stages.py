"""The stage functions: derender, check, compare, reconstruct, with the CLI's outputs, options as
keyword arguments, progress callbacks and interruption."""
import filecmp
import os
import signal
import subprocess

import numpy as np
import pytest

import ibrdf


def test_derender_gives_the_sample_files_dtype(small_session, small_samples):
    samples = ibrdf.derender(str(small_session))
    assert samples.dtype == np.load(small_samples).dtype == ibrdf.sample_dtype()
    assert samples.dtype.itemsize == 76 and len(samples) > 1000
    np.testing.assert_array_equal(samples, np.load(small_samples))


def test_derender_shares_its_samples(small_session):
    samples = ibrdf.derender(ibrdf.Session.load(str(small_session)))
    assert not samples.flags.owndata and samples.base is not None  # the library's buffer, not a copy


def test_derender_file_is_the_clis(small_session, small_samples, tmp_path, tool):
    cli = tmp_path / "cli.npy"
    subprocess.run([tool, "--silent", "derender", str(small_session), "--out", str(cli)], check=True)
    assert filecmp.cmp(cli, small_samples, shallow=False)


def test_derender_options_and_summary(small_session):
    samples, summary = ibrdf.derender(str(small_session), pixel_stride=2, max_theta_i_deg=60.0, with_summary=True)
    assert samples["theta_i"].max() <= np.radians(60.0) + 1e-6
    assert summary["format"] == "ibrdf-samples" and summary["counts"]["accepted"] == len(samples)


def test_derender_bad_option_value(small_session):
    with pytest.raises(ValueError, match="pixel_stride"):
        ibrdf.derender(str(small_session), pixel_stride=0)


def test_derender_unknown_option(small_session):
    with pytest.raises(AttributeError):
        ibrdf.derender(str(small_session), stride=2)


def test_derender_refuses_to_overwrite(small_session, small_samples):
    with pytest.raises(ibrdf.Error, match="exists"):
        ibrdf.derender(str(small_session), out=str(small_samples))


def test_read_samples(small_samples):
    samples = ibrdf.read_samples(str(small_samples))
    np.testing.assert_array_equal(samples, np.load(small_samples))


def test_check_returns_the_report(small_samples, tmp_path, tool):
    report = ibrdf.check(str(small_samples), out=str(tmp_path / "py.json"))
    assert report["format"] == "ibrdf-consistency"
    subprocess.run([tool, "--silent", "check", str(small_samples), "--out", str(tmp_path / "cli.json")], check=True)
    assert filecmp.cmp(tmp_path / "py.json", tmp_path / "cli.json", shallow=False)


def test_check_takes_an_array(small_samples):
    from_file = ibrdf.check(str(small_samples), theta_bin_deg=15.0)
    from_array = ibrdf.check(np.load(small_samples), theta_bin_deg=15.0)
    assert from_file == from_array


def test_check_refuses_another_dtype():
    with pytest.raises(TypeError, match="dtype"):
        ibrdf.check(np.zeros(10))


def test_compare_with_the_truth(small_samples):
    figures = ibrdf.compare(str(small_samples))
    assert max(figures["overall"]["median_rel_error"]) < 0.1


def test_reconstruct_summary(small_reconstruction):
    out, summary = small_reconstruction
    assert summary["format"] == "ibrdf-reconstruction"
    assert (out / "brdf.binary").exists() and (out / "small.bsdf").exists()


def test_reconstruct_from_an_array(small_samples, tmp_path):
    options = ibrdf.ReconstructOptions(fits=False, bsdf=False)
    options.regression.degree = 1
    summary = ibrdf.reconstruct(np.load(small_samples), str(tmp_path / "r"), options=options)
    assert (tmp_path / "r" / "brdf.binary").exists() and summary["format"] == "ibrdf-reconstruction"


def test_progress_callback_is_called(small_samples, tmp_path):
    seen = []
    ibrdf.reconstruct(str(small_samples), str(tmp_path / "r"), fits=False, bsdf=False,
                      progress=lambda label, done, total: seen.append((label, done, total)))
    assert seen and seen[-1][0] == "tabulate" and seen[-1][1] == seen[-1][2]


def test_callback_exception_stops_the_stage(small_samples, tmp_path):
    class Stop(Exception):
        pass

    def stop(label, done, total):
        raise Stop(label)

    with pytest.raises(Stop):
        ibrdf.reconstruct(str(small_samples), str(tmp_path / "r"), fits=False, bsdf=False, progress=stop)
    assert not (tmp_path / "r").exists()  # nothing committed
    assert not list(tmp_path.iterdir())  # no temporaries left


def test_ctrl_c_interrupts(small_samples, tmp_path):
    def interrupt(label, done, total):
        os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        ibrdf.reconstruct(str(small_samples), str(tmp_path / "r"), fits=False, bsdf=False, progress=interrupt)
    assert not (tmp_path / "r").exists()
    assert not list(tmp_path.iterdir())
