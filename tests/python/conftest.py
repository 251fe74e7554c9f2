"""Fixtures of the ibrdf module's tests: the source tree, a small synthetic session and what the
stages make of it (derendered and reconstructed once per test run, in a temporary folder)."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import ibrdf

SOURCE = pathlib.Path(os.environ.get("IBRDF_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def source():
    return SOURCE


@pytest.fixture(scope="session")
def tool():
    return ibrdf.tool_path()


@pytest.fixture(scope="session")
def small_session(tmp_path_factory, tool):
    """A 160x120, 6-photo synthetic sphere of the seed paper's blue paint: its session.json."""
    out = tmp_path_factory.mktemp("synth") / "s"
    subprocess.run([tool, "--silent", "synth", "--material", str(SOURCE / "samples/materials/bluepaint.json"),
                    "--out", str(out), "--width", "160", "--height", "120", "--photos", "6", "--seed", "1"],
                   check=True)
    return out / "session.json"


@pytest.fixture(scope="session")
def small_samples(tmp_path_factory, small_session):
    """The small session derendered to a sample file (samples.npy and its sidecar)."""
    path = tmp_path_factory.mktemp("derender") / "samples.npy"
    ibrdf.derender(str(small_session), out=str(path))
    return path


@pytest.fixture(scope="session")
def small_reconstruction(tmp_path_factory, small_samples):
    """The small samples reconstructed: brdf.binary, small.bsdf, lafortune.json, summary.json."""
    out = tmp_path_factory.mktemp("reconstruct") / "r"
    summary = ibrdf.reconstruct(str(small_samples), str(out), name="small")
    return out, summary


def random_directions(n, seed=0):
    """n unit directions on the upper hemisphere, uniform in solid angle."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(0.02, 1.0, n)
    phi = rng.uniform(-np.pi, np.pi, n)
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
