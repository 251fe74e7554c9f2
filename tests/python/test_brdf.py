"""ibrdf.Brdf: loading every kind of material and evaluating it over numpy arrays."""
import json
import math

import numpy as np
import pytest

import ibrdf
from conftest import random_directions


def write_merl(path, rgb):
    """A MERL table (BRDFRead.cpp's layout) holding the same RGB value in every cell."""
    scale = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
    cells = 90 * 90 * 180
    with open(path, "wb") as f:
        np.array([90, 90, 180], dtype="<i4").tofile(f)
        for c in range(3):
            np.full(cells, rgb[c] / scale[c], dtype="<f8").tofile(f)


def test_lambertian_is_albedo_over_pi(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/lambertian50.json"))
    assert brdf.model == "lambertian"
    wi, wo = random_directions(1000, 1), random_directions(1000, 2)
    f = brdf.eval(wi, wo)
    assert f.shape == (1000, 3)
    albedo = np.array(brdf.to_json()["albedo"])
    np.testing.assert_allclose(f, np.broadcast_to(albedo / math.pi, f.shape), rtol=1e-12)


@pytest.mark.parametrize("name", ["bluepaint.json", "glossy-ggx.json", "gold-paint.json"])
def test_analytic_materials_are_reciprocal(source, name):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials" / name))
    wi, wo = random_directions(2000, 3), random_directions(2000, 4)
    np.testing.assert_allclose(brdf.eval(wi, wo), brdf.eval(wo, wi), rtol=1e-10, atol=1e-14)


def test_below_the_horizon_is_zero(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    wi = random_directions(10, 5)
    wo = random_directions(10, 6) * np.array([1.0, 1.0, -1.0])
    assert np.all(brdf.eval(wi, wo) == 0.0)


def test_eval_angles_matches_eval(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    ti, to, pd = np.radians(30.0), np.radians(50.0), np.radians(120.0)
    wi = np.array([[math.sin(ti), 0.0, math.cos(ti)]])
    wo = np.array([[math.sin(to) * math.cos(pd), math.sin(to) * math.sin(pd), math.cos(to)]])
    np.testing.assert_allclose(brdf.eval_angles(ti, to, pd).reshape(1, 3), brdf.eval(wi, wo), rtol=1e-12)


def test_eval_angles_broadcasts(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    theta = np.radians(np.linspace(0.0, 80.0, 9))
    f = brdf.eval_angles(theta[:, None], theta[None, :], 0.0)
    assert f.shape == (9, 9, 3)
    np.testing.assert_allclose(f, np.swapaxes(f, 0, 1), rtol=1e-10)  # reciprocity in the incidence plane


def test_eval_takes_float32_and_lists(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    wi, wo = random_directions(50, 7), random_directions(50, 8)
    reference = brdf.eval(wi, wo)
    np.testing.assert_allclose(brdf.eval(wi.astype(np.float32), wo.astype(np.float32)), reference, rtol=1e-5)
    np.testing.assert_allclose(brdf.eval(wi.tolist(), wo.tolist()), reference, rtol=1e-12)


def test_eval_rejects_wrong_shapes(source):
    brdf = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        brdf.eval(np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="same number of rows"):
        brdf.eval(np.zeros((4, 3)), np.zeros((5, 3)))


def test_merl_table_lookup(tmp_path):
    path = tmp_path / "constant.binary"
    write_merl(path, [0.1, 0.2, 0.3])
    brdf = ibrdf.Brdf.load(str(path))
    assert brdf.model == "merl"
    f = brdf.eval(random_directions(500, 9), random_directions(500, 10))
    np.testing.assert_allclose(f, np.broadcast_to([0.1, 0.2, 0.3], f.shape), rtol=1e-12)
    table = brdf.table
    assert table.shape == (90, 90, 180, 3)
    np.testing.assert_allclose(table[10, 20, 30], [0.1, 0.2, 0.3], rtol=1e-12)


def test_material_file_naming_a_merl_table(tmp_path):
    write_merl(tmp_path / "t.binary", [0.05, 0.05, 0.05])
    (tmp_path / "m.json").write_text(json.dumps({"model": "merl", "file": "t.binary"}))
    brdf = ibrdf.Brdf.load(str(tmp_path / "m.json"))
    assert brdf.model == "merl"
    assert brdf.eval([[0.0, 0.0, 1.0]], [[0.0, 0.0, 1.0]])[0, 0] == pytest.approx(0.05)


def test_reconstruction_outputs_load(small_reconstruction):
    out, summary = small_reconstruction
    wi, wo = random_directions(2000, 11), random_directions(2000, 12)
    merl = ibrdf.Brdf.load(str(out / "brdf.binary"))
    bsdf = ibrdf.Brdf.load(str(out / "small.bsdf"))
    fit = ibrdf.Brdf.load(str(out / "lafortune.json"))
    assert (merl.model, bsdf.model, fit.model) == ("merl", "rgl_bsdf", "lafortune")
    for brdf in (merl, bsdf, fit):
        f = brdf.eval(wi, wo)
        assert f.shape == (2000, 3) and np.all(np.isfinite(f)) and np.all(f >= 0.0)
    assert bsdf.table is None


def test_truth_file_loads(small_session, source):
    truth = ibrdf.Brdf.load_truth(str(small_session.parent / "truth.json"))
    paper = ibrdf.Brdf.load(str(source / "samples/materials/bluepaint.json"))
    wi, wo = random_directions(100, 13), random_directions(100, 14)
    np.testing.assert_allclose(truth.eval(wi, wo), paper.eval(wi, wo), rtol=1e-12)


def test_missing_material_names_the_file(tmp_path):
    with pytest.raises(ibrdf.Error, match="nothing.json"):
        ibrdf.Brdf.load(str(tmp_path / "nothing.json"))


def test_bad_material_names_the_field(tmp_path):
    path = tmp_path / "m.json"
    path.write_text(json.dumps({"model": "lambertian", "albedo": [0.5, 0.5]}))
    with pytest.raises(ibrdf.Error) as error:
        ibrdf.Brdf.load(str(path))
    assert str(path) in str(error.value) and "albedo" in str(error.value)
