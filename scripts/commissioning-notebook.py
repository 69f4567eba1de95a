#!/usr/bin/env python3
"""Writes docs/commissioning.ipynb: the commissioning chain of a worm-gear rotary
table from Python — identify, tune, compensate, predict, and the check on the machine —
its cells executed in order and their printed output stored, as a notebook's would be
(python/tests/test_commissioning_notebook.py runs the cells again and compares).

Run from the repository's root with the module installed: python scripts/commissioning-notebook.py
"""

import contextlib
import io
import json
import sys
from pathlib import Path

CELLS = [
    ("markdown", """# Commissioning a rotary table from Python

The chain a commissioning engineer runs on a worm-gear rotary table, from a measurement
of its drive to the settings that go into the controller and what they will do, with
the identification's uncertainty carried through:

1. **identify** the drive's stiffnesses from a frequency response;
2. **tune** the velocity and position loops and the notch filters on the identified
   model;
3. **compensate** the backlash and the positioning error the identified model's own
   ISO 230-2 cycle shows, with the tuned controller;
4. **predict** the ISO 230-2 values before and after, with intervals from parameter
   sets drawn from the fit and from the backlash's datasheet tolerance;
5. **check** on the machine.

The machine here is virtual: the `worm-gear` preset (the paper's table) with stiffer
or softer meshes and more backlash than its datasheet says, so that the
identification has something to find and the prediction something to hold. Every
number below is rtid's command line's (`rtid identify`, `rtid tune`, `rtid compensate
--fit`, `rtid predict`: python/tests/ checks each against the binary). docs/python.md
describes the module; docs/tuning.md and docs/compensation.md the methods."""),
    ("code", """import rtid

# The table as it is, unknown to the engineer, and its datasheet.
datasheet = rtid.params("worm-gear")
machine = rtid.params("worm-gear", Kw=3.25e5, Kg=870.0, theta_bw=1.15 * datasheet["theta_bw"])
# Its frequency response, 50–400 Hz, with 1 % noise as an analyser's (the linear test).
measured = rtid.run_experiment("frequency-response", machine, linear=True, from_hz=50.0, to_hz=400.0,
                               step_hz=2.0, complex_noise_percent=1.0)
print(measured.kind, measured.columns["frequency_hz"].size, "lines")"""),
    ("markdown", """## 1. Identify

The drive stiffnesses Kw (worm mesh) and Kg (spur mesh) fitted to the complex response
from the datasheet's values; everything else stays at the datasheet's."""),
    ("code", """fit = rtid.identify(measured, datasheet, fit=["Kw", "Kg"], model="linear", progress=False)
print(fit.report())"""),
    ("markdown", """## 2. Tune

`rtid.tune` places notches at the motor's compliance resonances, searches velocity PIs
and position gains whose cascade, exact on the sampled loop, keeps a 50° phase margin
and 6 dB gain margins both ways, and weighs them on the nonlinear model — the ISO
230-2 cycle after the compensation built for each, a step, the following error —
against today's settings. Given the fit, the settings must hold over the machine as
the data leave it: the fit's intervals and the datasheet's held ranges, the ones that
move today's margins (`tuning.summary["range"]`)."""),
    ("code", """tuning = rtid.tune(fit.params, fit=fit, progress=False)
print("range:", ", ".join(f"{v['name']} x{v['low']:.3g}..{v['high']:.3g}" for v in tuning.summary["range"]["vary"]))
for name in ("Kvp", "Kvi", "Kpp"):
    print(f"{name:4} {tuning.before[name]:10.4g} -> {tuning.after[name]:10.4g}")
print("filters:", [f"{f['type']} {f.get('centre_hz', f.get('frequency_hz')):.1f} Hz" for f in tuning.after["filters"]])
margin = lambda s: s["cascade"]["phase_margin_deg"]
print(f"cascade phase margin {margin(tuning.before):.1f}° -> {margin(tuning.after):.1f}°")
print("proposes new settings:", tuning.proposes)"""),
    ("markdown", """## 3. Compensate

The identified model with the tuned controller runs its own ISO 230-2 cycle; its
mean reversal B̄ is the backlash compensation and −x̄↑ at each target the error table
(the reversal the backlash, the meshes' elastic lost motion and the friction make
together)."""),
    ("code", """tuned = fit.params.with_controller(tuning)
compensation = rtid.compensate(tuned)
print(compensation)
print(f"backlash compensation {compensation.backlash:.2f}″, {len(compensation.to_dict()['table']['positions'])} table points")"""),
    ("markdown", """## 4. Predict

The ISO 230-2 test before (today's settings, no compensation) and after (tuned and
compensated) on the identified model and on 12 parameter sets drawn from the fit's
standard errors and correlations, with the worm mesh's backlash drawn within ±20 % of
the datasheet's (`uncertain`): each value at the fit with its 95 % interval, in
arc-seconds."""),
    ("code", """prediction = rtid.predict(fit, compensation=compensation, tune=tuning, draws=12, runs=2,
                          uncertain={"theta_bw": 0.2}, progress=False)
for case in prediction.cases:
    values = ", ".join(f"{v['name']} {v['nominal']:.2f} [{v['lower']:.2f}, {v['upper']:.2f}]"
                       for v in case["values"] if v["name"] in ("B", "E", "R", "A"))
    print(f"{case['case']:6}: {values}")"""),
    ("markdown", """## 5. Check on the machine

The ISO 230-2 test on the machine itself, before and with the tuned controller and
the compensation, against the prediction."""),
    ("code", """before = rtid.evaluate(rtid.run_experiment("positioning", machine, runs=2))["axis"]
after = rtid.evaluate(rtid.run_experiment("positioning", machine.with_controller(tuning), runs=2,
                                          compensation=compensation))["axis"]
for case, measured_a in (("before", before["A"]), ("after", after["A"])):
    p = prediction.value("positioning", case, "A")
    inside = p["lower"] <= measured_a <= p["upper"]
    print(f"A {case:6} on the machine {measured_a:6.2f}″, predicted {p['nominal']:6.2f}″ "
          f"[{p['lower']:.2f}, {p['upper']:.2f}]: {'inside' if inside else 'outside'}")"""),
    ("markdown", """The settings go to the drive and the CNC as the files the command line reads:
`tuning.params.save("tuned.json")` (`--tune`), `compensation.save("compensation.json")`
(`--compensation`), `compensation.sinumerik(4)` (the CNC's error compensation
program), `tuning.sinamics()` and `tuning.sinumerik(4)` (the drive's and the CNC's
servo parameters, docs/drive-settings.md); `fit.to_dict()` is the result file of
`rtid identify --out`."""),
]


def run(cells):
    """The notebook's cells, code cells executed in one namespace with their output."""
    namespace = {}
    out = []
    count = 0
    for i, (kind, source) in enumerate(cells):
        cell = {"cell_type": kind, "id": f"cell-{i}", "metadata": {},
                "source": source.splitlines(keepends=True)}
        if kind == "code":
            count += 1
            buffer = io.StringIO()
            with contextlib.redirect_stdout(buffer):
                exec(compile(source, f"<cell {count}>", "exec"), namespace)
            text = buffer.getvalue()
            cell.update(execution_count=count, outputs=[
                {"name": "stdout", "output_type": "stream", "text": text.splitlines(keepends=True)}
            ] if text else [])
        out.append(cell)
    return out, namespace


def main():
    cells, _ = run(CELLS)
    notebook = {
        "cells": cells,
        "metadata": {
            "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
            "language_info": {"name": "python"},
        },
        "nbformat": 4,
        "nbformat_minor": 5,
    }
    path = Path(__file__).resolve().parents[1] / "docs/commissioning.ipynb"
    path.write_text(json.dumps(notebook, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
