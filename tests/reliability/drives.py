"""The short straight drive the hostile-input tests start from, as scenario text."""

from __future__ import annotations


def straight_drive(length_m: float = 100, sensors: str = "", tail: str = "") -> str:
    """A scenario: accelerate to 10 m/s, then ``length_m`` straight; ``sensors`` is the body
    of the ``sensors:`` block (indented lines, none for a drive without sensors) and ``tail``
    any further top-level text (faults, estimators)."""
    text = ("name: t\n"
            "start: {lat: 37.5, lon: 127.0}\n"
            "trajectory:\n"
            "  kind: segments\n"
            "  segments:\n"
            "    - accelerate: {to_speed: 10, accel: 1.5}\n"
            f"    - straight: {{length: {length_m}}}\n")
    if sensors:
        text += "sensors:\n" + sensors
    return text + tail
