"""Generic effects around a model with no switches: the quickstart zone.

The quickstart data are rewritten with an effect the quickstart FMU cannot represent (a slow
zone-temperature sensor, a logger clock running late), the zone is calibrated with a small
budget, and the diagnosis must find and confirm the generic effect around the simulator.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from ruamel.yaml import YAML

from simgap.around import _hysteresis, _lag, parse
from simgap.calibrate import calibrate
from simgap.diagnosis import diagnose
from simgap.errors import ConfigError
from simgap.setup import prepare

REPO = Path(__file__).resolve().parents[1]
QUICKSTART = REPO / "workflows" / "quickstart.yaml"
DATA = REPO / "examples" / "data" / "quickstart_measured.csv"


def _workflow(folder: Path, frame: pd.DataFrame, **changes) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    frame.to_csv(folder / "measured.csv", index=False)
    yaml = YAML()
    doc = yaml.load(QUICKSTART.read_text())
    doc["data"]["file"] = str(folder / "measured.csv")
    doc["simulator"]["options"]["source"] = str(REPO / "examples" / "models" / "quickstart_zone")
    doc["optimiser"] = {"plugin": "nsga2", "options": {"population": 16}, "seed": 2, "budget": {"evaluations": 320}}
    doc["output"] = str(folder / "runs")
    for key, value in changes.items():
        doc[key] = value
    path = folder / "workflow.yaml"
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    return path


def _seconds(frame):
    t = pd.to_datetime(frame["time"])
    return (t - t.iloc[0]).dt.total_seconds().to_numpy()


def test_around_transforms_on_known_series():
    t = np.arange(0.0, 36000.0, 60.0)
    step = (t >= 3600.0).astype(float)
    lagged = _lag(step, t, 600.0)
    # a first-order lag reaches 63 % of a step after one time constant
    assert lagged[np.searchsorted(t, 3600.0 + 600.0)] == pytest.approx(0.63, abs=0.05)
    demand = ((t // 3600) % 2 == 1).astype(float) * 0.7
    delayed = _hysteresis(demand, t, 0.05, 600.0, 300.0)
    first_on = t[np.argmax(delayed > 0)]
    assert first_on == pytest.approx(3600.0 + 600.0)
    assert delayed[np.searchsorted(t, 7200.0 + 240.0)] == pytest.approx(0.7)  # still running in the off delay
    assert delayed[np.searchsorted(t, 7200.0 + 360.0)] == 0.0


def test_around_bad_entry_names_its_line(tmp_path):
    frame = pd.read_csv(DATA)
    path = _workflow(tmp_path, frame)
    text = path.read_text().replace("  initial:", "  around:\n  - {apply: output_lag, variable: T_nowhere, tau: 60}\n  initial:", 1)
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        prepare(path)
    assert "T_nowhere" in str(err.value) and "workflow.yaml" in str(err.value)
    assert parse([{"apply": "input_gain", "variable": "u", "gain": "g"}])[0].gain == "g"


@pytest.mark.parametrize(
    "effect, withhold",
    [
        ("sensor_time_constant", lambda frame, t: frame.assign(T_zone_degC=_lag(frame["T_zone_degC"].to_numpy(), t, 2400.0))),
        # the logger's clock 20 min late: every series appears 20 min after it happened
        ("clock_shift", lambda frame, t: frame.assign(**{c: np.interp(t - 1200.0, t, frame[c].to_numpy())
                                                         for c in ("T_zone_degC", "P_el_W")})),
    ],
)
def test_generic_effect_found_and_confirmed_on_the_quickstart_zone(tmp_path, effect, withhold):
    frame = pd.read_csv(DATA)
    frame = withhold(frame, _seconds(frame))
    run_dir = calibrate(prepare(_workflow(tmp_path, frame)), workers=2)
    result = diagnose(
        run_dir,
        overrides={"recalibrate": {"candidates": 2, "population": 12, "generations": 4, "workers": 2}},
        progress=None,
    )
    ranking = [c for c in result["candidates"] if c.applicable]
    assert effect in [c.name for c in ranking[:3]], [(c.name, c.share, c.p_value) for c in ranking]
    assert result["claimed"][:1] == [effect], [(c.name, c.gap_shrink, c.shrink_vs_control, c.p_vs_control) for c in ranking]
    text = Path(result["report"]).read_text()
    assert f"most likely unmodelled effect: {effect}" in text
    derived = next(r for r in result["recalibration"] if r["effect"] == effect)
    assert derived["gap_shrink"] > 0.5, derived
