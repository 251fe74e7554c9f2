"""ibrdf.Session and the errors: a bad session raises ibrdf.Error with the CLI's message."""
import json
import shutil
import subprocess

import pytest

import ibrdf


def cli_error(tool, *arguments):
    """The message `ibrdf ARGUMENTS` prints after "ibrdf: error: " (it must fail with exit status 1)."""
    run = subprocess.run([tool, *arguments], capture_output=True, text=True)
    assert run.returncode == 1, run.stderr
    line = run.stderr.strip().splitlines()[-1]
    assert line.startswith("ibrdf: error: "), line
    return line[len("ibrdf: error: "):]


def broken_copy(small_session, tmp_path, edit):
    """A copy of the small session's folder whose manifest `edit` changed (a function of the dict)."""
    folder = tmp_path / "bad"
    shutil.copytree(small_session.parent, folder)
    manifest = json.loads((folder / "session.json").read_text())
    edit(manifest)
    (folder / "session.json").write_text(json.dumps(manifest))
    return folder / "session.json"


def test_load_reads_the_session(small_session):
    session = ibrdf.Session.load(str(small_session))
    assert session.num_photos == 6
    assert session.sample_kind == "sphere"
    assert session.image_size == (160, 120)
    assert session.manifest_path == str(small_session)
    assert len(session.input_files()) >= 6
    session.validate()


def test_load_takes_the_folder(small_session):
    assert ibrdf.Session.load(str(small_session.parent)).num_photos == 6


def test_save_round_trips(small_session, tmp_path):
    session = ibrdf.Session.load(str(small_session))
    path = session.save(str(tmp_path / "copy"))
    again = ibrdf.Session.load(path)
    assert again.num_photos == session.num_photos
    assert again.photo_path(0) == session.photo_path(0)


def test_to_json_is_the_manifest(small_session):
    manifest = ibrdf.Session.load(str(small_session)).to_json()
    assert isinstance(manifest, dict) and len(manifest["photos"]) == 6


def test_unknown_key_has_the_cli_message(small_session, tmp_path, tool):
    bad = broken_copy(small_session, tmp_path, lambda m: m.update(colour="blue"))
    with pytest.raises(ibrdf.Error) as error:
        ibrdf.Session.load(str(bad))
    assert str(error.value) == cli_error(tool, "derender", str(bad), "--out", str(tmp_path / "x.npy"))
    assert str(bad) in str(error.value) and "colour" in str(error.value)


def test_wrong_type_has_the_cli_message(small_session, tmp_path, tool):
    bad = broken_copy(small_session, tmp_path, lambda m: m["camera"].update(width="wide"))
    with pytest.raises(ibrdf.Error) as error:
        ibrdf.derender(str(bad))
    assert str(error.value) == cli_error(tool, "derender", str(bad), "--out", str(tmp_path / "x.npy"))
    assert "/camera/width" in str(error.value)


def test_missing_photo_has_the_cli_message(small_session, tmp_path, tool):
    def drop(m):
        m["photos"][2]["file"] = "missing.png"
    bad = broken_copy(small_session, tmp_path, drop)
    with pytest.raises(ibrdf.Error) as error:
        ibrdf.Session.load(str(bad))
    assert str(error.value) == cli_error(tool, "derender", str(bad), "--out", str(tmp_path / "x.npy"))
    assert "missing.png" in str(error.value)


def test_missing_session(tmp_path):
    with pytest.raises(ibrdf.Error, match="nowhere"):
        ibrdf.Session.load(str(tmp_path / "nowhere"))


def test_not_json(tmp_path):
    path = tmp_path / "session.json"
    path.write_text("{ not json")
    with pytest.raises(ibrdf.Error, match=str(path)):
        ibrdf.Session.load(str(path))
