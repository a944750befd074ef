"""The screening alone, again, on stored blind cases: each effect's share beside its
as-simulated share, and where the slot for the effect that removes most as simulated
(``simgap.diagnosis.ranking.AS_SIMULATED_SLOT``) gives a recalibration the budget did not.

    python benchmarks/as_simulated_slots.py /path/to/blind_set_folder [...] [--all]

For every ``<case>/runs/<run>`` under the folders (a case seen in two folders counts once, the
first): the run's context, the tuners' sensitivities and the screening of the installed effects,
as ``simgap diagnose`` does them, without a recalibration (about 10-30 s a case). Prints one line
per case where the as-simulated leader gets a slot of its own (``--all``: every case, and every
applicable effect), then how many such cases there were. The withheld effects come from the
case's ``case_result.json``; the as-simulated share is
``simgap.diagnosis.ranking.as_simulated_share`` over the screened settings.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def screen(run: Path) -> tuple[list, list, list]:
    """(candidates, the budget's choice without the as-simulated slot, the choice with it)."""
    from simgap.diagnosis import ranking
    from simgap.diagnosis.context import build_context
    from simgap.diagnosis.run import installed_effects, recalibration_choice

    ctx = build_context(run)
    nuisance = ranking.tuner_sensitivities(ctx)
    candidates = ranking.rank_effects(ctx, installed_effects(ctx.config.effects), nuisance, skip=ranking.unexplained_targets(ctx))
    budget = ctx.config.recalibrate.candidates
    with_slot = recalibration_choice(candidates, budget)
    saved = [c.as_simulated for c in candidates]
    for c in candidates:
        c.as_simulated = 0.0
    without = recalibration_choice(candidates, budget)
    for c, v in zip(candidates, saved):
        c.as_simulated = v
    return candidates, without, with_slot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", type=Path, nargs="+")
    parser.add_argument("--all", action="store_true", help="every case and every applicable effect")
    args = parser.parse_args()
    seen, added = set(), 0
    total = 0
    for folder in args.folders:
        for result in sorted(folder.glob("*/case_result.json")):
            case = json.loads(result.read_text())
            runs = sorted((result.parent / "runs").glob("*"))
            if case["case"] in seen or not runs:
                continue
            seen.add(case["case"])
            try:
                candidates, without, with_slot = screen(runs[0])
            except Exception as exc:  # a case whose model or data moved: say so, go on
                print(f"{case['case']}: not screened ({type(exc).__name__}: {exc})", flush=True)
                continue
            total += 1
            extra = [c for c in with_slot if c not in without]
            added += bool(extra)
            if extra or args.all:
                slot = ", ".join(f"+{c.name} ({c.as_simulated:.0%} as simulated, share {c.share:.0%})" for c in extra) or "-"
                print(f"{case['case']}: withheld {'+'.join(case.get('withheld') or []) or 'nothing'}; "
                      f"claimed before {','.join(case.get('claimed') or []) or '-'}; slot {slot}", flush=True)
            if args.all:
                for c in candidates:
                    if c.applicable:
                        print(f"    {c.name:22s} share {c.share:6.1%} significant {c.significant!s:5s} "
                              f"as simulated {c.as_simulated:7.1%} recalibrated {c in with_slot}", flush=True)
    print(f"\nthe as-simulated slot adds a recalibration in {added} of {total} cases")


if __name__ == "__main__":
    main()
