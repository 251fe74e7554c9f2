"""docs/python.md's walk-through: its python blocks run in order, in one namespace, from the project
folder, writing into a temporary folder."""
import os
import re


def test_walk_through_runs(source, tmp_path, monkeypatch):
    text = (source / "docs/python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 6
    monkeypatch.chdir(source)
    monkeypatch.setenv("IBRDF_DOCS_OUT", str(tmp_path / "run"))
    namespace = {}
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/python.md, python block {i + 1}", "exec"), namespace)
    assert (tmp_path / "run" / "slice.png").stat().st_size > 1000
    assert 0.0 < namespace["albedo"] < 1.0
