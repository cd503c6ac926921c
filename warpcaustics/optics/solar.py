"""The sun's position from a date, time and place (``sun.datetime``, ``sun.latitude_deg``,
``sun.longitude_deg``), through pvlib's NREL SPA (Reda & Andreas 2004), an optional extra.

pvlib measures azimuth clockwise from north (east = 90°); ours runs from +x (east) towards +y
(north), so ours = 90° − pvlib's. The elevation is the apparent one (corrected for atmospheric
refraction at the given pressure and temperature): the direction the sunlight arrives from.
"""

from __future__ import annotations

from datetime import datetime

from warpcaustics.errors import ConfigError

STANDARD_PRESSURE_HPA = 1013.25
"""Sea-level standard atmosphere, for the refraction correction."""


def parse_datetime(text: str) -> datetime:
    """An ISO 8601 date and time with its UTC offset (e.g. ``2009-07-14T11:30:00+02:00``)."""
    try:
        # Python 3.10's fromisoformat takes no trailing "Z"
        when = datetime.fromisoformat(text[:-1] + "+00:00" if text.endswith(("Z", "z")) else text)
    except (TypeError, ValueError):
        raise ConfigError(f"sun.datetime = {text!r} is not an ISO 8601 date and time; write e.g. "
                          "\"2009-07-14T11:30:00+02:00\"") from None
    if not any(sep in text for sep in "Tt "):  # a date alone: midnight, and any offset was dropped
        raise ConfigError(f"sun.datetime = {text!r} has no time of day; write e.g. "
                          f"\"{when.date().isoformat()}T12:00:00+00:00\"")
    if when.tzinfo is None:
        raise ConfigError(f"sun.datetime = {text!r} has no UTC offset; add one, e.g. {text}+00:00 or "
                          f"{text}Z")
    return when


def sun_position(when: datetime, latitude_deg: float, longitude_deg: float, *, altitude_m: float = 0.0,
                 pressure_hpa: float = STANDARD_PRESSURE_HPA, temperature_c: float = 12.0,
                 delta_t_s: float = 67.0) -> tuple[float, float]:
    """(apparent elevation, azimuth from +x towards +y) [deg] of the sun at ``when`` seen from the
    place; ``delta_t_s`` is TT − UT1 (pvlib's default, as in its SPA example)."""
    try:
        import pandas as pd
        from pvlib import solarposition
    except ImportError:
        raise ConfigError("sun.datetime needs pvlib: pip install 'warpcaustics[science]' (or give "
                          "sun.elevation_deg and sun.azimuth_deg)") from None
    times = pd.DatetimeIndex([pd.Timestamp(when)])
    pos = solarposition.get_solarposition(times, latitude_deg, longitude_deg, altitude=altitude_m,
                                          pressure=pressure_hpa * 100.0, method="nrel_numpy",
                                          temperature=temperature_c, delta_t=delta_t_s)
    elevation = float(pos["apparent_elevation"].iloc[0])
    azimuth_north_cw = float(pos["azimuth"].iloc[0])
    azimuth = (90.0 - azimuth_north_cw + 180.0) % 360.0 - 180.0
    return elevation, azimuth
