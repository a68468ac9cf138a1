"""Merging a named preset into a sensor's scenario block: the one place where preset values fill
the keys a user left out, so the resolved scenario shows every value the sensor uses.

Public functions
----------------
known_preset, fill_from_preset.
"""

from __future__ import annotations

from typing import Any

from simulator.scenario.schema import INVALID, Context, Field, Path


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
