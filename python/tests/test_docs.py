"""docs/python.md's walk-through runs as written: its ```python blocks, in order,
in one namespace, in a scratch folder."""
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_walk_through(tmp_path, monkeypatch, capsys):
    text = open(os.path.join(ROOT, "docs", "python.md"), encoding="utf-8").read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 6
    monkeypatch.chdir(tmp_path)
    namespace = {}
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/python.md block {i + 1}", "exec"), namespace)
    out = capsys.readouterr().out
    # The error block's printed form is the one the page shows.
    shown = re.search(r"```\n(typo\.sdf:.*?)```", text, re.S).group(1)
    assert shown in out
    assert os.path.exists(tmp_path / "built.sdf")
