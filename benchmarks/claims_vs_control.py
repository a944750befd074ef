"""Per target, what each recalibrated effect of stored blind diagnoses leaves of the gap that
re-tuning alone (the control) closes: right claims against wrong ones.

    python benchmarks/claims_vs_control.py /path/to/blind_set_folder [...]

Reads every ``<case>/case_result.json`` under the folders (a case seen in two folders counts
once, the first) and the ``diagnosis.json`` beside its report; for each recalibration of a
single effect, the most negative per-target shrink beyond the control (``shrink_vs_control``:
−0.8 means the effect leaves 80 % of that target's original gap that re-tuning alone closed).
Prints how many right and wrong claims leave more than 20, 40, 50 and 100 %, and lists the claims
that leave more than ``--list-above``. A claim is right when it names a withheld effect or one of
its physics (``simgap.models.blind.same_physics``). The diagnosis's threshold is
``simgap.diagnosis.ranking.REOPENS_AT_MOST``; diagnoses made with the rule already hold no
claim above it."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path


def rows(folders: list[Path]) -> list[dict]:
    from simgap.models.blind import same_physics

    seen, out = set(), []
    for folder in folders:
        for path in sorted(folder.glob("*/case_result.json")):
            case = json.loads(path.read_text())
            if case["case"] in seen or not case.get("report"):
                continue
            diagnosis = Path(case["report"]).parent / "diagnosis.json"
            if not diagnosis.is_file():
                continue
            seen.add(case["case"])
            truth = set().union(*[same_physics(w) for w in case.get("withheld") or []])
            claimed = case.get("claimed") or []
            for r in json.loads(diagnosis.read_text()).get("recalibration", []):
                per_target = r.get("shrink_vs_control")
                if r.get("effect") == "control" or "on_top_of" in r or not per_target:
                    continue
                finite = {t: v for t, v in per_target.items() if v is not None and math.isfinite(v)}
                if not finite:
                    continue
                worst = min(finite, key=finite.get)
                out.append({"case": case["case"], "effect": r["effect"], "right": r["effect"] in truth,
                            "claimed": r["effect"] in claimed, "first": bool(claimed) and claimed[0] == r["effect"],
                            "target": worst, "left": -finite[worst]})
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", type=Path, nargs="+", help="blind-set folders (the --out of diagnosis_blind.py)")
    parser.add_argument("--list-above", type=float, default=0.3, help="list the claims that leave more than this share")
    args = parser.parse_args()
    found = rows(args.folders)
    cases = len({r["case"] for r in found})
    print(f"{len(found)} recalibrations of single effects in {cases} cases")
    cuts = (0.2, 0.4, 0.5, 1.0)
    print("claims".ljust(16) + "n".rjust(5) + "".join(f"  left > {c:.0%}".rjust(14) for c in cuts))
    for label, right in (("right claims", True), ("wrong claims", False)):
        group = [r for r in found if r["claimed"] and r["right"] == right]
        print(label.ljust(16) + str(len(group)).rjust(5) + "".join(str(sum(r["left"] > c for r in group)).rjust(14) for c in cuts))
    print(f"\nclaims leaving more than {args.list_above:.0%} of a target's gap that re-tuning alone closes:")
    for r in sorted(found, key=lambda r: -r["left"]):
        if r["claimed"] and r["left"] > args.list_above:
            print(f"  {'right' if r['right'] else 'WRONG'} {'first' if r['first'] else 'later'} {r['case'][:66]:66s} "
                  f"{r['effect']:22s} {r['target']:10s} {r['left']:.0%}")


if __name__ == "__main__":
    main()
