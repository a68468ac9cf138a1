"""Merging a named preset into a sensor's scenario block: the one place where preset values fill
the keys a user left out, so the resolved scenario shows every value the sensor uses.

Public functions
----------------
known_preset, fill_from_preset, preset_sensor_field; class PresetSensor.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from simulator.schema import INVALID, Context, Field, Path, Record, Text


def known_preset(name: str, presets: dict[str, dict], what: str, path: Path,
                 ctx: Context) -> bool:
    """True if ``name`` is a preset; otherwise report it at ``path.preset``."""
    if name in presets:
        return True
    ctx.error(path + ("preset",), f"unknown {what} preset {name!r}; known: "
                                  f"{', '.join(sorted(presets))}")
    return False


def fill_from_preset(given: dict, preset: dict, fields: dict[str, Field], path: Path,
                     ctx: Context, defaults: dict[str, Any]) -> dict:
    """Keys left unset (None) in ``given`` take the preset's value (checked and converted to SI
    by the key's field, so presets may be written with datasheet units), else ``defaults[key]``
    (absent from ``defaults``: 0.0). A preset value that fails its check makes the result INVALID.
    """
    out = dict(given)
    for key, field in fields.items():
        if out.get(key) is not None:
            continue
        raw = preset.get(key)
        if raw is None:
            out[key] = defaults.get(key, 0.0)
        else:
            out[key] = field.check(raw, path + (key,), ctx)
            if out[key] is INVALID:
                return INVALID
    return out


def preset_sensor_field(what: str, presets: dict[str, dict], fields: dict[str, Field],
                        defaults: dict[str, Any], ideal_doc: str,
                        check: Callable[[dict, Path, Context], Any] | None = None) -> Record:
    """The scenario block of a sensor configured by ``preset`` plus single-key overrides.

    ``check(resolved, path, ctx)`` runs after the preset filled the block (cross-key checks);
    it returns the block, or INVALID after reporting a problem.
    """
    def resolve(value: dict, path: Path, ctx: Context) -> Any:
        if not known_preset(value["preset"], presets, what, path, ctx):
            return INVALID
        out = fill_from_preset(value, presets[value["preset"]], fields, path, ctx, defaults)
        if out is INVALID or check is None:
            return out
        return check(out, path, ctx)

    return Record({"preset": Text("ideal", doc=f"named parameter set; 'ideal' {ideal_doc}"),
                   **fields}, default=None, post=resolve)


class PresetSensor:
    """Base of the sensors built from a resolved preset block: keeps the block, the rate, the
    ``drawn`` record of the true error values (starting with the preset's name) and
    ``true_errors``, the true values over time of the errors an estimator may estimate (column
    of ``columns.SENSOR_ERRORS`` -> (t, values)), filled by ``generate``."""

    name = ""
    # scenario keys that set a true value rather than a datasheet figure, with the nominal value
    # a user would assume instead (the manifest's ``datasheet`` shows that one)
    truth_keys: dict[str, float] = {}

    def __init__(self, config: dict):
        self.config = config
        self.rate_hz = float(config["rate"])
        self.drawn: dict = {"preset": config["preset"]}
        self.true_errors: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def timing(self) -> dict[str, dict]:
        """How each stream of the sensor is stamped (the manifest's ``timing``): stream ->
        {stamp, delay_s (the effective delay of the value behind its stamp)}."""
        return {self.name: {"stamp": "the sampling instant", "delay_s": 0.0}}
