"""``truth_sensors.parquet`` (docs/dataset-format.md): the true value over time of every sensor
error an estimator may estimate, named as the solution's sensor-error columns
(``columns.SENSOR_ERRORS``), for scoring only.

Rows are on a common grid t = k / ``TRUE_ERROR_RATE_HZ`` (10 Hz) over the drive; each sensor's
own series (``true_errors`` of the sensor models: the IMU's kept every ``rate / 10``-th sample,
the odometer's at its rate, the receiver clock at the GNSS epochs) is interpolated linearly onto
it, and is NaN outside its own time span. The faults that change a true error are added on top
over their intervals: ``imu_bias_step`` (its ``gyro`` or ``accel`` step on each axis it names)
and ``odometer_slip`` / ``odometer_scale_change`` (the measured-to-true speed ratio multiplied
by 1 + ratio). Faults that corrupt samples without a persistent error (saturation bursts,
dropouts, jitter) are not sensor errors and leave the table alone.

Public functions
----------------
truth_sensors_table.
"""

from __future__ import annotations

import json

import numpy as np

from simulator import columns as col
from simulator.faults.base import in_intervals
from simulator.sensors.base import TRUE_ERROR_RATE_HZ, sample_times
from simulator.tables import ColumnTable

_SCALE_FAULTS = {"odometer_slip": "slip", "odometer_scale_change": "scale_change"}


def _apply_faults(table: ColumnTable, fault_rows: list[dict]) -> None:
    t = table["t"]
    for row in fault_rows:
        kind = row["kind"]
        if kind != "imu_bias_step" and kind not in _SCALE_FAULTS:
            continue
        params = json.loads(row["detail"])
        inside = in_intervals(t, [(row["t_start"], row["t_end"])])
        if kind == "imu_bias_step":
            for axis in params["axes"]:
                group, _, xyz = axis.partition("_")
                name = f"{group}_bias_{xyz}"
                if name in table:
                    table[name] = np.where(inside, table[name] + params[group], table[name])
        elif "odometer_scale_factor" in table:
            ratio = 1.0 + params[_SCALE_FAULTS[kind]]
            table["odometer_scale_factor"] = np.where(inside, table["odometer_scale_factor"]
                                                      * ratio, table["odometer_scale_factor"])


def truth_sensors_table(true_errors: dict[str, tuple[np.ndarray, np.ndarray]],
                        duration_s: float, fault_rows: list[dict]) -> ColumnTable | None:
    """The truth_sensors table (module docstring), or None when no sensor has a true error.

    Parameters
    ----------
    true_errors : column -> (t (s), true value), merged from the sensor models.
    duration_s : the drive's duration.
    fault_rows : the events rows of the applied faults (``kind``, ``t_start``, ``t_end`` and
        ``detail``, the JSON of the fault's parameters).
    """
    names = [name for name in col.SENSOR_ERRORS if name in true_errors]
    if not names:
        return None
    t = sample_times(duration_s, TRUE_ERROR_RATE_HZ)
    table: ColumnTable = {"t": t}
    for name in names:
        t_sensor, values = true_errors[name]
        table[name] = np.interp(t, t_sensor, np.asarray(values, dtype=float),
                                left=np.nan, right=np.nan)
    _apply_faults(table, fault_rows)
    return table
