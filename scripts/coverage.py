#!/usr/bin/env python3
"""Coverage of `rtid predict`'s intervals on machines that are not the model.

Draws machines around the worm-gear preset (backlash and frictions moved; on the
second half also held parameters: Kw, theta_bg, Jt — ranges the preset carries; with
--other-held the machines move held parameters the preset has no range for, or
another: Kg, Jw, W), records on each the tests a user would (a noisy torque curve and
unbalance test), runs the chain of docs/compensation.md (identify theta_bw, fm, fw ->
compensate --fit -> predict) as a user types it, with rtid's defaults, then the
machine's own ISO 230-2 test before and after that compensation, and counts how many
of the machine's values fall inside the predicted intervals.

    python3 scripts/coverage.py [--rtid target/release/rtid] [--machines 6]
        [--first 1] [--other-held] [--held-moved] [--out DIR] [-- IDENTIFY-OPTIONS...]

Options after `--` are given to `rtid identify` (e.g. `--intervals standard-errors`
or `--uncertain Kw=0%`); without any, the default chain (by rtid's defaults the fit's
intervals are the bootstrap's on this rough cost, each replicate drawing the preset's
held ranges, and predict draws the replicates). Besides predict's intervals, the
identification's (±1.96 standard errors; the bootstrap's) are checked against the
machine's own parameters, and each step of the chain is timed (wall seconds).

Standard library only; prints one line per value and the coverage; writes
DIR/coverage.json. docs/validation.md reports what it measured.
"""
import argparse
import json
import os
import random
import subprocess
import sys
import time

OUTPUTS = ["B_mean", "B", "E", "M", "R", "A"]
#: Arc-seconds within which a bound and a value are the same number.
TIE = 1e-6


def rtid(binary, *args):
    r = subprocess.run([binary, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"rtid {' '.join(args)} failed:\n{r.stderr}")
    return r.stdout


def machine(k, held_moved, other):
    """The parameter overrides of machine k: backlash and frictions within ±40 %;
    with `held_moved`, Kw ±10 %, theta_bg ×0.5…1.5 and Jt ±10 % as well, or with
    `other` Kg ±15 % (no range in the preset), Jw ×0.7…1.3 and W ×0.5…1.7."""
    rng = random.Random(1000 + k)
    sets = {
        "theta_bw": 8e-5 * rng.uniform(0.6, 1.4),
        "fm": 0.14 * rng.uniform(0.6, 1.4),
        "fw": 0.24 * rng.uniform(0.6, 1.4),
    }
    if held_moved and other:
        sets["Kg"] = 850 * rng.choice([0.85, 1.15])
        sets["Jw"] = 4.3e-4 * rng.uniform(0.7, 1.3)
        sets["W"] = 1.5e-5 * rng.uniform(0.5, 1.7)
    elif held_moved:
        sets["Kw"] = 3.1e5 * rng.choice([0.9, 1.1])
        sets["theta_bg"] = 3e-4 * rng.uniform(0.5, 1.5)
        sets["Jt"] = 0.108 * rng.uniform(0.9, 1.1)
    return sets


def iso_values(binary, manifest):
    axis = json.loads(rtid(binary, "evaluate", manifest, "--json"))["axis"]
    return {name: axis[name] for name in OUTPUTS}


def timed(seconds, step, binary, *args):
    started = time.monotonic()
    out = rtid(binary, *args)
    seconds[step] = round(time.monotonic() - started, 1)
    return out


def one(binary, k, held_moved, args, root):
    d = os.path.join(root, f"machine-{k}")
    os.makedirs(d, exist_ok=True)
    sets = machine(k, held_moved, args.other_held)
    seconds = {}
    setargs = [a for n, v in sets.items() for a in ("--set", f"{n}={v!r}")]
    params = os.path.join(d, "machine.json")
    rtid(binary, "params", "--preset", "worm-gear", *setargs, "--out", params, "--quiet")
    m = ["--params", params, "--quiet"]
    rtid(binary, "experiment", "torque-curve", *m, "--noise-percent", "1", "--seed", str(k),
         "--out", os.path.join(d, "records"))
    rtid(binary, "experiment", "unbalance", *m, "--noise-arcsec", "0.5", "--seed", str(k),
         "--out", os.path.join(d, "records"))
    fit = os.path.join(d, "fit.json")
    timed(seconds, "identify", binary, "identify", os.path.join(d, "records", "torque_curve.json"),
          os.path.join(d, "records", "unbalance.json"), "--preset", "worm-gear",
          "--fit", "theta_bw,fm,fw", "--out", fit, "--quiet", *args.identify)
    comp = os.path.join(d, "compensation.json")
    timed(seconds, "compensate", binary, "compensate", "--fit", fit, "--preset", "worm-gear",
          "-o", comp, "--quiet")
    pred = json.loads(timed(seconds, "predict", binary, "predict", fit, "--preset", "worm-gear",
                            "--compensation", comp, "--json", "--quiet"))
    rtid(binary, "experiment", "positioning", *m, "--out", os.path.join(d, "before"))
    rtid(binary, "experiment", "positioning", *m, "--compensation", comp,
         "--out", os.path.join(d, "after"))
    truth = {
        "before": iso_values(binary, os.path.join(d, "before", "positioning.json")),
        "after": iso_values(binary, os.path.join(d, "after", "positioning.json")),
    }
    result = json.load(open(fit))
    fitted = result["parameters"]
    rows = []
    for name, value in fitted.items():
        se = dict(result["uncertainty"]["standard_errors"]).get(name)
        boot = (result.get("resampling") or {}).get("intervals", {}).get(name)
        for kind, lo, hi in [("se", value - 1.96 * se if se else None, value + 1.96 * se if se else None),
                             ("bootstrap", boot and boot["lower"], boot and boot["upper"])]:
            if lo is None:
                continue
            rows.append({"machine": k, "held_moved": held_moved, "case": "identify-" + kind,
                         "name": name, "machine_value": sets[name], "nominal": value,
                         "lower": lo, "upper": hi, "inside": lo <= sets[name] <= hi})
    for case in pred["cases"]:
        for v in case["values"]:
            if v["name"] not in OUTPUTS:
                continue
            value = truth[case["case"]][v["name"]]
            lo, hi = v["lower"], v["upper"]
            # A bound equal to the value but for rounding holds it (the ISO values
            # of a quantised encoder repeat exactly).
            inside = lo is not None and lo - TIE <= value <= hi + TIE
            rows.append({"machine": k, "held_moved": held_moved, "case": case["case"],
                         "name": v["name"], "machine_value": value, "nominal": v["nominal"],
                         "lower": lo, "upper": hi, "inside": inside})
    return {"machine": k, "sets": sets, "fitted": fitted, "rows": rows, "notes": pred["notes"],
            "seconds": seconds}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtid", default="target/release/rtid")
    ap.add_argument("--machines", type=int, default=6)
    ap.add_argument("--first", type=int, default=1, help="number of the first machine")
    ap.add_argument("--other-held", action="store_true",
                    help="the second half moves Kg, Jw and W instead of Kw, theta_bg and Jt")
    ap.add_argument("--held-moved", action="store_true",
                    help="every machine moves held parameters, not only the second half")
    ap.add_argument("--out", default="coverage-run")
    ap.add_argument("identify", nargs="*", help="options for rtid identify (after --)")
    args = ap.parse_args()
    results = []
    for k in range(args.first, args.first + args.machines):
        held_moved = args.held_moved or k - args.first >= args.machines // 2
        r = one(args.rtid, k, held_moved, args, args.out)
        results.append(r)
        print(f"machine {k}: " + ", ".join(f"{s} {t} s" for s, t in r["seconds"].items())
              + f", chain {sum(r['seconds'].values()):.1f} s", flush=True)
        for row in r["rows"]:
            print(f"machine {k} {row['case']:18} {row['name']:8} machine {row['machine_value']:10.4g}  "
                  f"predicted {row['nominal']:10.4g} [{row['lower']:.4g} … {row['upper']:.4g}]"
                  f"  {'in' if row['inside'] else 'OUT'}", flush=True)
    every = [row for r in results for row in r["rows"]]
    for label, rows in [("predict (ISO 230-2 before and after)",
                         [row for row in every if row["case"] in ("before", "after")]),
                        ("identify ±1.96 standard errors",
                         [row for row in every if row["case"] == "identify-se"]),
                        ("identify bootstrap",
                         [row for row in every if row["case"] == "identify-bootstrap"])]:
        if not rows:
            continue
        inside = sum(row["inside"] for row in rows)
        print(f"{label}: {inside} of {len(rows)} ({100 * inside / len(rows):.0f} %)")
        for held in (False, True):
            part = [row for row in rows if row["held_moved"] == held]
            if part:
                n = sum(row["inside"] for row in part)
                print(f"  held parameters {'moved' if held else 'as the preset'}: {n} of {len(part)}")
    chains = [sum(r["seconds"].values()) for r in results]
    print(f"chain (identify, compensate, predict): {min(chains):.1f} … {max(chains):.1f} s a machine")
    with open(os.path.join(args.out, "coverage.json"), "w") as f:
        json.dump({"identify": args.identify, "other_held": args.other_held,
                   "machines": results}, f, indent=1)


if __name__ == "__main__":
    main()
