"""Map tuner parameters between their bounds and the unit cube the optimisers work in."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .config import Parameter


@dataclass(frozen=True)
class ParameterSpace:
    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    log: np.ndarray

    @classmethod
    def from_config(cls, parameters: list[Parameter]) -> "ParameterSpace":
        return cls(
            names=tuple(p.name for p in parameters),
            lower=np.array([p.min for p in parameters], dtype=float),
            upper=np.array([p.max for p in parameters], dtype=float),
            log=np.array([p.scale == "log" for p in parameters], dtype=bool),
        )

    def _transformed_bounds(self):
        lo = np.where(self.log, np.log(np.where(self.log, self.lower, 1.0)), self.lower)
        hi = np.where(self.log, np.log(np.where(self.log, self.upper, 1.0)), self.upper)
        return lo, hi

    def from_unit(self, x: np.ndarray) -> np.ndarray:
        """Unit-cube points (n, d) -> parameter values (n, d)."""
        lo, hi = self._transformed_bounds()
        v = lo + np.clip(x, 0.0, 1.0) * (hi - lo)
        return np.where(self.log, np.exp(np.where(self.log, v, 0.0)), v)

    def to_unit(self, values: np.ndarray) -> np.ndarray:
        lo, hi = self._transformed_bounds()
        v = np.where(self.log, np.log(np.where(self.log, np.maximum(values, 1e-300), 1.0)), values)
        return (v - lo) / (hi - lo)

    def start_point(self, parameters: list[Parameter]) -> np.ndarray | None:
        starts = np.array([np.nan if p.start is None else p.start for p in parameters], dtype=float)
        if np.isnan(starts).all():
            return None
        return np.where(np.isnan(starts), np.nan, self.to_unit(np.nan_to_num(starts, nan=1.0)))

    def as_dicts(self, values: np.ndarray) -> list[dict[str, float]]:
        return [dict(zip(self.names, map(float, row))) for row in values]
