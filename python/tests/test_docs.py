"""docs/python.md end to end, the way a notebook runs it: its ```python blocks in
order, in one namespace, from the repository's root (the plot written to a temporary
folder). And the stub: every public name typed, every function documented."""

import ast
import inspect
import os
import re
from pathlib import Path

import rtid


def test_the_worked_example_runs(root, tmp_path, monkeypatch, capsys):
    text = (root / "docs/python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 5
    source = "\n".join(blocks).replace('"fixtures/', f'"{root}/fixtures/')
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(source, "docs/python.md", "exec"), namespace)
    assert (tmp_path / "kw-sweep.png").stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "input[1] = nan: not a finite number" in printed
    assert "rough_cost" in printed
    fit = namespace["fit"]
    assert set(fit.values) == {"Jt", "Ct", "ft", "Tload"}


def test_every_public_name_is_typed_and_documented(root):
    stub = ast.parse((root / "python/rtid/__init__.pyi").read_text())
    typed = {n.name for n in stub.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    typed |= {t.id for n in stub.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    typed |= {t.id for n in stub.body if isinstance(n, ast.Assign) for t in n.targets}
    missing = [name for name in rtid.__all__ if name not in typed]
    assert not missing, f"not in rtid/__init__.pyi: {missing}"
    for name in rtid.__all__:
        obj = getattr(rtid, name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            assert obj.__doc__ and len(obj.__doc__.strip()) > 20, name
