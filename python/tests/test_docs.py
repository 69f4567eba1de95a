"""docs/python.md end to end, the way a notebook runs it: its ```python blocks in
order, in one namespace, from the repository's root (the plots written to a
temporary folder); a block that imports an optional package (pandas,
python-control) is left out where that package is missing. And the stub: every
public name typed, every function documented."""

import ast
import importlib.util
import inspect
import re

import numpy as np
import pytest

import rtid

OPTIONAL = {"pandas", "control", "tqdm"}


def missing_optional(block: str) -> set:
    """The optional packages `block` imports that are not installed."""
    imported = set()
    for node in ast.parse(block).body:
        if isinstance(node, ast.Import):
            imported |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module.split(".")[0])
    return {m for m in imported & OPTIONAL if importlib.util.find_spec(m) is None}


def test_the_worked_example_runs(root, tmp_path, monkeypatch, capsys):
    text = (root / "docs/python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 10
    runnable = [b for b in blocks if not missing_optional(b)]
    source = "\n".join(runnable).replace('"fixtures/', f'"{root}/fixtures/')
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(source, "docs/python.md", "exec"), namespace)
    assert (tmp_path / "kw-sweep.png").stat().st_size > 1000
    assert (tmp_path / "fit-curves.png").stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "input[1] = nan: not a finite number" in printed
    assert "rough_cost" in printed
    fit = namespace["fit"]
    assert set(fit.values) == {"Jt", "Ct", "ft", "Tload"}
    # The walk-through's numbers, as the text gives them.
    fr_fit = namespace["fr_fit"]
    assert fr_fit.success and not fr_fit.warnings
    assert round(fr_fit.values["Kw"]) == 310142 and round(fr_fit.values["Kg"], 2) == 849.76
    report = text.split("```text\n", 1)[1].split("```", 1)[0]
    assert fr_fit.report().strip() == report.strip()
    assert "[192.2, 252.7, 1510.7]" in text and "[192.2, 252.7, 1510.7]" in printed
    if "pd" in namespace:
        mu = namespace["indices"].query("statistic == 'mu_star' and output == 'resonance_3_hz'")
        assert mu.set_index("parameter").value.round(1).to_dict()["Kb"] == 419.1
    if "control" in namespace:
        assert namespace["h"] == pytest.approx(
            rtid.frequency_response(namespace["truth"], 100.0, output="theta_t"), rel=1e-9)
    assert np.isfinite(namespace["poles"]).all()


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
