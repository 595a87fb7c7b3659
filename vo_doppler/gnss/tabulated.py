"""Satellite states from a provider's table (GSDC ``device_gnss.csv``) instead of ephemerides.

The same contract as :func:`vo_doppler.gnss.satellite_source.transmit_states`: states at signal
transmission in the ECEF frame of the reception epoch, plus the travel times. The table's
states are already at transmission, in the frame of that instant; they are rotated by the Earth
rotation during the travel time (IS-GPS-200 sec. 20.3.3.4.3.4), the geometric one when the
receiver position is given, else the table's own. Queries without a table row at the same epoch
(within 1 ms) are ``valid = False``. For a solution of your own: the GNSS stage does not take
the table, it queries a state source (navigation file or precise orbits) at transmission times
(docs/formats.md, GSDC).
"""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import SatelliteStates, rotate_earth
from vo_doppler.model.satellite_table import SatelliteTable


def table_transmit_states(
    table: SatelliteTable, system, prn, t_receive, receiver_ecef: np.ndarray | None = None
) -> tuple[SatelliteStates, np.ndarray]:
    """States of the queried (system, PRN, reception time) rows and their travel times (s)."""
    system, prn, t_receive = np.broadcast_arrays(
        np.asarray(system, dtype="U1"), np.asarray(prn), np.asarray(t_receive, dtype=float)
    )
    row = table.rows_for(t_receive.ravel(), system.ravel(), prn.ravel())
    found = row >= 0
    out = SatelliteStates.empty(row.size)
    pick = row[found]
    travel = np.full(row.size, np.nan)
    travel[found] = table.travel_time_s[pick]
    if receiver_ecef is not None:
        receiver = np.broadcast_to(np.asarray(receiver_ecef, dtype=float), (row.size, 3))[found]
        for _ in range(2):
            moved = rotate_earth(table.position[pick], travel[found])
            travel[found] = np.linalg.norm(moved - receiver, axis=1) / SPEED_OF_LIGHT
    out.position[found] = rotate_earth(table.position[pick], travel[found])
    out.velocity[found] = rotate_earth(table.velocity[pick], travel[found])
    out.clock_bias_s[found] = table.clock_bias_s[pick]
    out.clock_drift[found] = table.clock_drift[pick]
    out.valid[found] = True
    out.record[found] = pick
    return out, travel
