"""The fuzz targets' inputs replayed through the module's readers: a regression input must raise
ibrdf.Error naming the file, a corpus input load or raise it; none may crash the interpreter."""
import shutil

import numpy as np
import pytest

import ibrdf

# Fuzz target: its file name (as fuzz/*_fuzzer.cc writes the input) and the module's reader.
TARGETS = {
    "session_json": ("session.json", ibrdf.Session.load),
    "material_json": ("material.json", ibrdf.Brdf.load),
    "merl": ("input.binary", ibrdf.Brdf.load),
    "bsdf": ("input.bsdf", ibrdf.Brdf.load),
    "npy": ("input.npy", ibrdf.read_samples),
    "truth_json": ("truth.json", ibrdf.Brdf.load_truth),
}


def replay(source, tmp_path, target, folder):
    name, read = TARGETS[target]
    inputs = sorted((source / "fuzz" / folder / target).iterdir())
    assert inputs, f"no inputs in fuzz/{folder}/{target}"
    accepted = 0
    for i, input_path in enumerate(inputs):
        scratch = tmp_path / str(i)
        scratch.mkdir()
        path = scratch / name
        shutil.copyfile(input_path, path)
        try:
            loaded = read(str(path))
        except ibrdf.Error as error:
            assert str(scratch) in str(error), f"{input_path}: the error names no input file: {error}"
            continue
        accepted += 1
        if isinstance(loaded, ibrdf.Brdf):  # what a reader accepts must evaluate
            loaded.eval(np.array([[0.0, 0.6, 0.8]]), np.array([[0.6, 0.0, 0.8]]))
    return accepted, len(inputs)


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_regression_inputs_raise(source, tmp_path, target):
    accepted, total = replay(source, tmp_path, target, "regressions")
    assert accepted == 0, f"{accepted} of {total} regression inputs of {target} were accepted"


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_corpus_inputs_load_or_raise(source, tmp_path, target):
    replay(source, tmp_path, target, "corpus")
