"""docs/commissioning.ipynb run as a notebook runs it: its code cells in order in one
namespace, each cell's printed output the one the notebook holds (written by
scripts/commissioning-notebook.py) — the commissioning chain identify → tune →
compensate → predict → check on the machine, from Python."""

import contextlib
import io
import json

import pytest

import rtid


def test_the_commissioning_notebook_runs_and_prints_its_numbers(root, monkeypatch, tmp_path):
    notebook = json.loads((root / "docs/commissioning.ipynb").read_text(encoding="utf-8"))
    monkeypatch.chdir(tmp_path)
    namespace = {}
    code = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    assert len(code) >= 6
    for cell in code:
        source = "".join(cell["source"])
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(source, f"<cell {cell['execution_count']}>", "exec"), namespace)
        stored = "".join(t for out in cell["outputs"] for t in out.get("text", []))
        assert printed.getvalue() == stored, source
    # The chain's results, as the text says them.
    fit, tuning, prediction = namespace["fit"], namespace["tuning"], namespace["prediction"]
    assert fit.success and not fit.warnings and set(fit.values) == {"Kw", "Kg"}
    assert fit.values["Kw"] == pytest.approx(3.25e5, rel=2e-3)
    assert tuning.proposes and len(tuning.after["filters"]) == 3
    assert isinstance(namespace["compensation"], rtid.Compensation)
    for case, measured in (("before", namespace["before"]["A"]), ("after", namespace["after"]["A"])):
        a = prediction.value("positioning", case, "A")
        assert a["lower"] <= measured <= a["upper"], (case, measured, a)
