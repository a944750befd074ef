"""What the blind benches on models simgap did not write share: a case calibrated and diagnosed
through the ``simgap`` command as a user runs them, and the claims read back from its stored
diagnosis (``diagnosis_energyplus.py``, ``diagnosis_pythonfmu.py``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path


def run_shard(cases: list, seeds: str | None, shard: str, out: Path, run_one) -> Path:
    """Run this process's shard (``k/n``) of the cases asked for (``seeds``: comma-separated, or
    all): ``run_one(case, folder)`` -> the case's result row, printed and written to
    ``out/results.json`` after each case (``[]`` where the shard is empty). Returns that file. The
    shard splits the cases asked for: two seeds over two processes run one each."""
    k, n = map(int, shard.split("/"))
    asked = [c for c in cases if not seeds or str(c.seed) in seeds.split(",")]
    out.mkdir(parents=True, exist_ok=True)
    path = out / "results.json"
    results = []
    path.write_text("[]")
    for case in asked[k - 1::n]:
        print(f"{case.label} (seed {case.seed}) ...", flush=True)
        results.append(run_one(case, out / f"seed{case.seed}"))
        print(json.dumps(results[-1], default=str), flush=True)
        path.write_text(json.dumps(results, indent=1, default=str))
    return path


def print_reach(cases: list, seeds: str | None, shard: str, measure) -> list[dict]:
    """Each single-effect case's reach (``measure(case)`` -> ``{"p", "excess", "retuned"}``, as
    ``simgap.models.blind.retuning_reach`` measures it) as a table row: can a perfect
    recalibration tell the withheld error from re-tuning (decidable, p ≤ the bench's level), and
    could the claim rule credit it (claimable)? This process's shard (``k/n``) of the cases asked
    for; returns the rows."""
    from simgap.models.blind import REACH_SIGNIFICANCE, claimable

    k, n = map(int, shard.split("/"))
    asked = [c for c in cases if c.effect and (not seeds or str(c.seed) in seeds.split(","))]
    print("| case | seed | p (perfect against re-tuning) | excess on validation (noise variances) | decidable | claimable | re-tuned | at a bound |")
    print("|---|---|---|---|---|---|---|---|")
    rows = []
    for case in asked[k - 1::n]:
        r = measure(case)
        r.setdefault("decidable", bool(r["p"] == r["p"] and r["p"] <= REACH_SIGNIFICANCE))
        yes = {True: "yes", False: "**no**", None: "–"}
        print(f"| {case.label} | {case.seed} | {r['p']:.2g} | " + ", ".join(f"{t} {v:.2f}" for t, v in r["excess"].items())
              + f" | {yes[r['decidable']]} | {yes[claimable(r)]} | "
              + ("{} {:.4g}, ".format(*r["other"]) if r.get("other") else "") + ", ".join(f"{k} {v:.4g}" for k, v in r["retuned"].items())
              + f" | {', '.join(r.get('at_bound', [])) or '–'} |",
              flush=True)
        rows.append({"seed": case.seed, **r})
    return rows


def export_pythonfmu(folder: Path, name: str, source: str) -> Path:
    """``source`` (a pythonfmu slave class named ``name``) exported as ``folder/name.fmu``, once
    per folder: the benches' FMUs another tool wrote."""
    fmu = folder / f"{name}.fmu"
    if not fmu.exists():
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{name}.py").write_text(source)
        subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(folder / f"{name}.py"), "-d", str(folder)],
                       check=True, capture_output=True)
    return fmu


def calibrate_and_diagnose(workflow: Path, folder: Path, workers: int) -> tuple[Path | None, dict]:
    """``simgap run`` then ``simgap diagnose`` with their defaults, logs beside the workflow:
    (the run folder, timings and load), or (None, {"error": ...}) where a command failed."""
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "simgap.cli", "run", str(workflow), "--workers", str(workers), "--figures", "none"],
                         cwd=folder, capture_output=True, text=True)
    t1 = time.perf_counter()
    (folder / "run.log").write_text(run.stdout + run.stderr)
    if run.returncode != 0:
        return None, {"error": f"simgap run exited {run.returncode}"}
    run_dir = max((p for p in folder.iterdir() if p.is_dir() and (p / "summary.json").exists()), key=lambda p: p.stat().st_mtime)
    diag = subprocess.run([sys.executable, "-m", "simgap.cli", "diagnose", str(run_dir), "--workers", str(workers)],
                          cwd=folder, capture_output=True, text=True)
    t2 = time.perf_counter()
    (folder / "diagnose.log").write_text(diag.stdout + diag.stderr)
    if diag.returncode != 0:
        return None, {"error": f"simgap diagnose exited {diag.returncode}"}
    return run_dir, {"calibration_s": round(t1 - t0, 1), "diagnosis_s": round(t2 - t1, 1), "load": os.getloadavg()}


def stored_claims(run_dir: Path, withheld: str | None) -> dict:
    """A stored diagnosis's claims (and the re-tuned solution's, where it went on from there):
    what it claimed, the first claim's parameters, the top three, the verdict, and the withheld
    effect's own recalibration (beyond re-tuning, p, its parameters)."""
    result = json.loads((run_dir / "diagnosis" / "diagnosis.json").read_text())
    claimed = list(result.get("claimed") or [])
    chain = result.get("chain") or []
    again = run_dir / "diagnosis" / "retuned" / "diagnosis.json"
    if not chain and again.exists():  # diagnosed again from the re-tuned solution: its claims are there
        chain = json.loads(again.read_text()).get("chain") or []
    recal = {r["effect"]: r for r in result.get("recalibration", []) if r.get("effect")}
    if again.exists():  # diagnosed again from the re-tuned solution: its recalibrations count
        recal = {r["effect"]: r for r in json.loads(again.read_text()).get("recalibration", []) if r.get("effect")}
    mine = recal.get(withheld or "", {})
    return {
        "claimed": claimed,
        "found": dict(chain[0].get("effect_parameters") or {}) if chain else {},
        "ranking": [c.get("name") for c in result.get("ranking", [])][:3],
        "roles": result.get("roles"), "verdict": result.get("verdict"),
        "withheld_beyond_retuning": mine.get("gap_shrink_vs_control"), "withheld_p": mine.get("p_vs_control"),
        "withheld_found": mine.get("effect_parameters"),
    }


def score_case(case, run_dir: Path, reading_right) -> dict:
    """A case's score from its stored diagnosis: right where the first claim is the withheld
    effect as ``reading_right(case, effect, found)`` judges it, or, for a null case, nothing is
    claimed. ``case``: a bench's case (``label``, ``seed``, ``effect``)."""
    stored = stored_claims(run_dir, case.effect)
    claimed, found = stored["claimed"], stored["found"]
    first = claimed[0] if claimed else None
    right = (not claimed) if case.effect is None else bool(first and reading_right(case, first, found))
    return {"case": case.label, "seed": case.seed, "withheld": case.effect, **stored, "right": right}


def print_table(paths: list[Path], withheld_by_seed: dict, top_three: bool = False) -> None:
    """The scored cases of ``paths`` (results.json files) as a table, then the counts; an error
    row holds no score and is counted by its case, not as a null. ``top_three``: a column with the
    ranking's first three and their count."""
    rows = []
    for p in paths:
        rows += json.loads(Path(p).read_text())
    rows.sort(key=lambda r: r["seed"])
    extra = " top three |" if top_three else ""
    print(f"| case | seed | claimed (found) |{extra} withheld: beyond re-tuning (p) | right? |")
    print("|---|---|---|" + ("---|" if top_three else "") + "---|---|")
    for r in rows:
        if "error" in r:
            print(f"| {r['case']} | {r['seed']} | {r['error']} |" + (" |" if top_three else "") + " | no |")
            continue
        found = ", ".join(f"{k} {v:.3g}" for k, v in r["found"].items())
        beyond = r.get("withheld_beyond_retuning")
        withheld = (f"{beyond:.0%} ({r['withheld_p']:.2g})" if beyond is not None and r.get("withheld_p") is not None
                    else "not recalibrated" if r["withheld"] else "–")
        ranking = f" {', '.join(r['ranking'])} |" if top_three else ""
        print(f"| {r['case']} | {r['seed']} | {', '.join(r['claimed']) or 'nothing'}{' (' + found + ')' if found else ''} |"
              f"{ranking} {withheld} | {'yes' if r['right'] else 'no'} |")
    effects = [r for r in rows if withheld_by_seed.get(r["seed"]) and "error" not in r]
    nulls = [r for r in rows if not withheld_by_seed.get(r["seed"]) and "error" not in r]
    top3 = f" (top three {sum(withheld_by_seed[r['seed']] in r['ranking'] for r in effects)}/{len(effects)})" if top_three else ""
    failed = sum("error" in r for r in rows)
    print(f"\nsingle effects right: {sum(r.get('right', False) for r in effects)}/{len(effects)}{top3}; "
          f"null cases with a claim: {sum(not r.get('right', False) for r in nulls)}/{len(nulls)}"
          + (f"; {failed} case(s) without a score" if failed else ""))
