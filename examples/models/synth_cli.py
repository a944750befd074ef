"""``simgap synth``: write a synthetic "measured" data set with known truth (:mod:`simgap.models.synth`).

Settings come from a small YAML/JSON file (``--spec``) and from options; an option overrides
the file (for the mappings — parameters, effects, noise, offsets, decimals — key by key).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import click
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from simgap.durations import Duration, parse_duration
from simgap.errors import ConfigError, SimgapError


class SynthSpec(BaseModel):
    """What a spec file may hold: the keyword arguments of :func:`simgap.models.synth.write_dataset`."""

    model_config = ConfigDict(extra="forbid")

    seasons: list[str] | None = None
    days_per_season: int | None = Field(None, ge=1)
    resolution: str | float | None = None
    parameters: dict[str, float] = Field(default_factory=dict)
    effects: dict[str, dict[str, float] | None] = Field(default_factory=dict)
    noise: dict[str, float] = Field(default_factory=dict)
    offsets: dict[str, float] = Field(default_factory=dict)
    decimals: dict[str, int] = Field(default_factory=dict)
    missing_fraction: float | None = Field(None, ge=0.0, lt=1.0)
    mean_gap: Duration = None
    record: Literal["all", "electric_only"] | None = None
    seed: int | None = None
    start: str | None = None
    label: Literal["start", "end"] | None = None
    warmup: Duration = None

    @field_validator("effects", mode="before")
    @classmethod
    def _names_or_mapping(cls, value):
        # a plain list of effect names means each with its default parameters
        return {name: {} for name in value} if isinstance(value, list) else value

    @field_validator("noise")
    @classmethod
    def _non_negative(cls, value):
        bad = {k: v for k, v in value.items() if v < 0}
        if bad:
            raise ValueError(f"a noise standard deviation cannot be negative: {bad}")
        return value


def read_spec(path: Path) -> SynthSpec:
    from simgap.config import validation_error
    from simgap.yamlfile import read_yaml

    if not path.is_file():
        raise ConfigError(f"synth spec file not found: {path}")
    doc = read_yaml(path)
    try:
        return SynthSpec.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_error(doc, exc) from None


def _pairs(option: str, items: tuple[str, ...], convert) -> dict:
    """``NAME=VALUE`` strings from a repeated option as a mapping."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise SimgapError(f"{option} {item!r}: expected NAME=VALUE")
        try:
            out[name] = convert(value)
        except ValueError:
            kind = "an integer" if convert is int else "a number"
            raise SimgapError(f"{option} {item!r}: {value!r} is not {kind}") from None
    return out


def _effects(items: tuple[str, ...]) -> dict[str, dict[str, float]]:
    """``--effect start_up_lag`` or ``--effect cycling:TCycOff=320,dTCycHys=4``."""
    out = {}
    for item in items:
        name, _, rest = item.partition(":")
        name = name.strip()
        if not name:
            raise SimgapError(f"--effect {item!r}: expected NAME or NAME:PARAMETER=VALUE,...")
        values = tuple(p for p in rest.split(",") if p.strip()) if rest else ()
        out.setdefault(name, {}).update(_pairs(f"--effect {name}:", values, float))
    return out


def _resolution(value):
    try:
        return float(value)
    except (TypeError, ValueError):
        return value


def describe_model(model: str) -> str:
    """The model's inputs, recorded columns, tuners and effects, as text."""
    from . import synth

    spec = synth.MODELS.get(model)
    if spec is None:
        raise SimgapError(f"unknown synthetic model {model!r}; expected one of {', '.join(synth.MODELS)}")
    lines = [f"{model}: example model {synth.models_dir() / spec.folder}"]
    lines.append(f"  recorded columns (record=all): {', '.join(synth.recorded_columns(model, 'all'))}")
    if model == "air_source_hp":
        lines.append(f"  recorded columns (record=electric_only): {', '.join(synth.recorded_columns(model, 'electric_only'))}")
    lines.append("  tuners (default, bounds):")
    for name, b in spec.tuners.items():
        lines.append(f"    {name} = {b.default:g} [{b.lower:g}, {b.upper:g}] {b.unit}".rstrip())
    lines.append("  effects (--effect NAME:PARAMETER=VALUE,...):")
    for effect in spec.effects.values():
        params = ", ".join(f"{p}={b.default:g} [{b.lower:g}, {b.upper:g}]" for p, b in effect.parameters.items())
        lines.append(f"    {effect.name} ({effect.switch}): {params}")
        lines.append(f"      {effect.what}")
    return "\n".join(lines)


def run_synth(
    model: str,
    output: Path,
    *,
    spec_file: Path | None = None,
    seasons: str | None = None,
    days_per_season: int | None = None,
    resolution: str | None = None,
    set_values: tuple[str, ...] = (),
    effects: tuple[str, ...] = (),
    noise: tuple[str, ...] = (),
    offsets: tuple[str, ...] = (),
    decimals: tuple[str, ...] = (),
    missing: float | None = None,
    mean_gap: str | None = None,
    record: str | None = None,
    seed: int | None = None,
    start: str | None = None,
    label: str | None = None,
    warmup: str | None = None,
):
    """Merge the spec file with the options and call :func:`simgap.models.synth.write_dataset`."""
    from . import synth

    spec = read_spec(spec_file) if spec_file is not None else SynthSpec()
    kwargs: dict = {
        "parameters": {**spec.parameters, **_pairs("--set", set_values, float)},
        "effects": {k: dict(v or {}) for k, v in spec.effects.items()},
        "noise": {**spec.noise, **_pairs("--noise", noise, float)},
        "offsets": {**spec.offsets, **_pairs("--offset", offsets, float)},
        "decimals": {**spec.decimals, **_pairs("--decimals", decimals, int)},
    }
    for name, values in _effects(effects).items():
        kwargs["effects"].setdefault(name, {}).update(values)
    if any(v < 0 for v in kwargs["noise"].values()):
        raise SimgapError(f"--noise: a standard deviation cannot be negative: {kwargs['noise']}")

    season_list = [s.strip() for s in seasons.split(",") if s.strip()] if seasons else spec.seasons
    if season_list is not None:
        kwargs["seasons"] = tuple(season_list)
    scalars = {
        "days_per_season": days_per_season if days_per_season is not None else spec.days_per_season,
        "resolution": _resolution(resolution) if resolution is not None else spec.resolution,
        "missing_fraction": missing if missing is not None else spec.missing_fraction,
        "record": record or spec.record,
        "seed": seed if seed is not None else spec.seed,
        "start": start or spec.start,
        "label": label or spec.label,
    }
    kwargs.update({k: v for k, v in scalars.items() if v is not None})
    for key, option, value in (("mean_gap_s", "--mean-gap", mean_gap or spec.mean_gap), ("warmup_s", "--warmup", warmup or spec.warmup)):
        if value is not None:
            try:
                kwargs[key] = parse_duration(value).total_seconds()
            except ValueError as exc:
                raise SimgapError(f"{option}: {exc}") from None
    if kwargs.get("start") is not None:
        import pandas as pd

        try:
            pd.Timestamp(kwargs["start"])
        except (ValueError, TypeError):
            raise SimgapError(f"--start: expected a timestamp such as '2024-01-01 00:00', got {kwargs['start']!r}") from None
    return synth.write_dataset(output, model, **kwargs)


def register(main: click.Group) -> None:
    """Add the ``synth`` command to the ``simgap`` command group."""

    @main.command()
    @click.argument("model")
    @click.argument("output", type=click.Path(path_type=Path), required=False)
    @click.option("--spec", "spec_file", type=click.Path(path_type=Path), help="YAML or JSON file with any of the settings below (options override it)")
    @click.option("--seasons", metavar="LIST", help="comma-separated days in order, from autumn, winter, summer (default: all three)")
    @click.option("--days-per-season", type=click.IntRange(min=1), help="days per season (default 1)")
    @click.option("--resolution", metavar="RES", help="1s, 1min, 5min or seconds: interval means (default 1min)")
    @click.option("--set", "set_values", multiple=True, metavar="NAME=VALUE", help="true value of a model parameter (repeat)")
    @click.option("--effect", "effects", multiple=True, metavar="NAME[:P=V,...]", help="switch on an effect, optionally with its parameters (repeat)")
    @click.option("--noise", multiple=True, metavar="COLUMN=SIGMA", help="Gaussian sensor noise, in the column's unit (repeat)")
    @click.option("--offset", "offsets", multiple=True, metavar="COLUMN=VALUE", help="constant sensor offset (repeat)")
    @click.option("--decimals", multiple=True, metavar="COLUMN=N", help="round a column to N decimals, like a logger (repeat)")
    @click.option("--missing", type=click.FloatRange(0.0, 1.0, max_open=True), help="share of rows lost, in gaps")
    @click.option("--mean-gap", metavar="DURATION", help="mean length of a gap of lost rows (default 10min)")
    @click.option("--record", type=click.Choice(["all", "electric_only"]), help="electric_only: air_source_hp without fan, pump and compressor signals")
    @click.option("--seed", type=int, help="seed of weather, noise and gaps (default 0)")
    @click.option("--start", metavar="TIMESTAMP", help="time of the first sample (default 2024-01-01 00:00)")
    @click.option("--label", type=click.Choice(["start", "end"]), help="stamp each interval mean with its start (default, a logger) or its end (a meter)")
    @click.option("--warmup", metavar="DURATION", help="simulated before the record and cut off (default 6h / 2 days)")
    @click.option("--describe", is_flag=True, help="list the model's columns, tuners and effects, and exit")
    def synth(model, output, spec_file, describe: bool, **options):
        """Write a synthetic measurement of MODEL to OUTPUT (.parquet) with its truth beside it.

        MODEL is air_source_hp, water_to_water_hp or brine_water_hp. Beside OUTPUT come
        <name>.truth.json (every true value, effect, seed and setting) and <name>.clean.parquet
        (every model variable, noise-free).

        Example: simgap synth air_source_hp winter.parquet --seasons winter --resolution 1s
        --set scaleHPQCon_nominal=0.9 --effect start_up_lag:tauStartUp=120
        --noise THCFlow_K=0.05 --record electric_only --seed 7
        """
        import time

        if describe:
            click.echo(describe_model(model))
            return
        if output is None:
            raise SimgapError("give the OUTPUT file (.parquet) to write, or --describe to list the model")
        t0 = time.perf_counter()
        result = run_synth(model, output, spec_file=spec_file, **options)
        truth = result.truth
        rows = truth.get("rows_dropped", 0)
        click.echo(
            f"wrote {result.data_path} ({len(truth['columns'])} columns at {truth['resolution_s']:g} s, "
            f"{rows} rows dropped) in {time.perf_counter() - t0:.1f} s"
        )
        click.echo(f"  truth: {result.truth_path}")
        click.echo(f"  noise-free, every variable: {result.clean_path}")
