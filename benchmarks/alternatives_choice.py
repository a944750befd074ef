"""Which alternative of an effect of alternatives the screening keeps, against which one each
alternative's own test would: stored blind diagnoses, screened again one alternative at a time.

    python benchmarks/alternatives_choice.py /path/to/blind_set_folder [...] [--effects input_gain_error]

An effect of alternatives (``Effect.alternatives``: one input's gain, one reading's time
constant) is recalibrated on one alternative only, the one whose setting explained the residual
best by the chance-corrected share (``ranking.alternative_setting``). This screens each
alternative alone, at every solution the stored diagnosis screened (the base calibration's
chosen solution and, where the diagnosis restarted, the control's), and prints per diagnosis
each alternative's share and p (the shift test, Bonferroni over the targets), the one the
share keeps and the one the lowest p would keep. Rows are grouped by what the case withheld:
null cases, the effect itself (the alternative that is the truth named where the bench wrote
an input gain or a sensor lag), other effects. Nothing is recalibrated (about 20 s per zone
diagnosis on one core, minutes for a heat pump's).

Written in session 67 to decide whether the zone's solar input, tried by the input gain error
since 9797097, should be kept by its p where the compressor signal's share is larger: on the
zone's null cases the solar input's p is as small as on the cases that withhold its gain (see
docs/diagnosis_bench.md, session 67)."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path


def screened_solutions(case_dir: Path) -> list[tuple[Path, int | None, str]]:
    """(run folder, solution, 'base' or 'restart') the stored diagnosis screened."""
    out = []
    for report in sorted(case_dir.glob("runs/*/diagnosis/report.md")):
        found = re.search(r"solution (\d+)", report.read_text())
        out.append((report.parents[1], int(found.group(1)) if found else None, "base"))
        if (report.parent / "retuned").is_dir():
            out += [(run, 0, "restart") for run in sorted(report.parent.glob("recalibration/control/runs/*"))]
    return out


def alternatives(run: Path, solution: int | None, names: set[str]) -> dict[str, dict]:
    """Per effect of alternatives: each alternative's (label, share, p), and the one kept."""
    from simgap.diagnosis import ranking
    from simgap.diagnosis.context import build_context
    from simgap.diagnosis.run import installed_effects

    ctx = build_context(run, solution=solution)
    nuisance = ranking.tuner_sensitivities(ctx)
    data = ctx.data()
    out = {}
    for effect in installed_effects(ctx.config.effects):
        if not getattr(effect, "alternatives", False) or (names and effect.name not in names) or effect.applies(data):
            continue
        entries = effect.entries(data)
        if len(entries) < 2:
            continue
        rows = []
        for entry, parameters in entries:
            alone = type(effect)()
            alone.entries = lambda _data, entry=entry, parameters=parameters: [(entry, parameters)]
            cand = ranking.rank_effects(ctx, [alone], nuisance)[0]
            rows.append({"alternative": entry.get("variable", "?"), "share": cand.share, "p": cand.p_value,
                         "parameters": [p.name for p in parameters]})
        cand = ranking.rank_effects(ctx, [effect], nuisance)[0]
        kept = {p.name for p in cand.addition.parameters} if cand.addition is not None else set()
        # the typical setting moves every alternative at once (a time constant's typical value
        # is not its neutral one): where it explained most, the recalibration takes them all
        kept_rows = [r["alternative"] for r in rows if kept & set(r["parameters"])]
        out[effect.name] = {"alternatives": rows, "kept_by_share": kept_rows[0] if len(kept_rows) == 1 else "all",
                            "kept_by_p": min(rows, key=lambda r: r["p"])["alternative"]}
    return out


def truth_of(case: dict, effect: str, labels: list[str]) -> str | None:
    """Of ``labels`` (the alternatives' variables), the one the bench wrote, read from the case
    label: the measured column is the variable's name or it with a unit suffix (Q_sol_W)."""
    found = re.search(rf"{effect}\(([A-Za-z0-9_]+?)(?:_logged_x|tau)", case["case"])
    if not found:
        return None
    column = found.group(1)
    return next((v for v in labels if column == v or column.startswith(v + "_")), column)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", type=Path, nargs="+", help="blind set folders (their <case>/case_result.json), or case folders")
    parser.add_argument("--effects", default="", help="comma-separated effect names (default: every effect of alternatives)")
    args = parser.parse_args()
    names = {n for n in args.effects.split(",") if n}
    cases = []
    for folder in args.folders:
        cases += [folder] if (folder / "case_result.json").is_file() else sorted(p.parent for p in folder.glob("*/case_result.json"))
    seen, lines = set(), []
    for case_dir in cases:
        case = json.loads((case_dir / "case_result.json").read_text())
        if case["case"] in seen:
            continue
        seen.add(case["case"])
        withheld = case.get("withheld") or []
        for run, solution, kind in screened_solutions(case_dir):
            for effect, row in alternatives(run, solution, names).items():
                group = "null" if not withheld else ("withheld" if effect in withheld else "other")
                truth = truth_of(case, effect, [r["alternative"] for r in row["alternatives"]]) if group == "withheld" else None
                alts = "  ".join(f"{r['alternative']} {r['share']:6.1%} p={r['p']:.2g}" for r in row["alternatives"])
                line = (f"{group:8s} {effect:22s} {case['case'][:72]:72s} {kind:7s} {alts}  share keeps {row['kept_by_share']}, "
                        f"p would keep {row['kept_by_p']}" + (f"; the truth {truth}" if truth else ""))
                lines.append((group, effect, row["kept_by_share"], row["kept_by_p"], truth))
                print(line, flush=True)
    print()
    for group in ("null", "withheld", "other"):
        for effect in sorted({e for g, e, _, _, _ in lines if g == group}):
            rows = [(share, p, truth) for g, e, share, p, truth in lines if g == group and e == effect]
            every = sum(share == "all" for share, _, _ in rows)
            differ = sum(share != "all" and share != p for share, p, _ in rows)
            told = [(share, p, truth) for share, p, truth in rows if truth]
            right = (f"; where the bench wrote one, the share keeps it in {sum(s == t for s, _, t in told)} of {len(told)}, "
                     f"the p would in {sum(p == t for _, p, t in told)}") if told else ""
            print(f"{group:8s} {effect:22s} {len(rows):3d} screened diagnoses: the typical setting (every alternative at once) "
                  f"kept in {every}, the p would keep another single one in {differ}{right}")


if __name__ == "__main__":
    main()
