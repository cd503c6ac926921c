"""The floor map as plain arrays: ``frame_NNNN.npz`` (numpy) and ``frame_NNNN.nc`` (NetCDF)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.io.files import atomic_path


def science_arrays(result) -> dict[str, np.ndarray]:
    """The floor map and its coordinates as plain arrays (for .npz and NetCDF): row index along +y
    (not flipped as in the images)."""
    from warpcaustics.batch.stats import par_map

    x, y = result.map_coordinates()
    edges = result.bins.edges_nm if result.bins is not None else np.array([])
    return {"floor_irradiance": result.floor_irradiance.astype(np.float32),
            "wavelength_nm": np.asarray(result.wavelengths_nm, np.float64),
            "bin_edges_nm": np.asarray(edges, np.float64), "x_m": x, "y_m": y,
            "time_s": np.array([result.time_s]),
            "par_umol_m2_s": par_map(result.floor_irradiance, edges).astype(np.float32)}


def write_npz(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``frame_NNNN.npz``: :func:`science_arrays` (floor_irradiance in W m⁻² nm⁻¹, PAR in
    µmol photons m⁻² s⁻¹, coordinates in nm, m and s)."""
    path = out_dir / f"frame_{frame:04d}.npz"
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **science_arrays(result))
    return {"npz": path}


CF_CONVENTIONS = "CF-1.10"


def time_units(result) -> tuple[str, str]:
    """CF's time units and a comment: seconds since ``sun.datetime`` (in UTC) when the scene gives
    one, else since 1970-01-01 00:00:00 UTC standing for the simulation's t = 0."""
    text = result.scene.config.sun.datetime
    if text:
        from warpcaustics.optics.solar import parse_datetime

        start = parse_datetime(text)
        if start.tzinfo is not None:
            import datetime

            start = start.astimezone(datetime.timezone.utc).replace(tzinfo=None)
        return (f"seconds since {start:%Y-%m-%d %H:%M:%S}",
                f"simulation time from sun.datetime = {text!r} (UTC)")
    return ("seconds since 1970-01-01 00:00:00",
            "simulation time; the scene gives no date (sun.datetime), so t = 0 is written as 1970-01-01 UTC")


def write_netcdf(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``frame_NNNN.nc`` through xarray, following CF-1.10: ``floor_irradiance`` (time, wavelength, y,
    x) and ``par`` (time, y, x) with units and long names; coordinates with ``axis`` and their CF
    standard names (projection x/y, time in "seconds since …", radiation_wavelength with the bin
    edges as ``bounds``). NetCDF4 through netCDF4 or h5netcdf when installed, else NetCDF3 (scipy)."""
    import importlib.util

    try:
        import xarray as xr
    except ImportError:
        from warpcaustics.errors import WarpcausticsError

        raise WarpcausticsError("output.netcdf = true needs xarray: pip install 'warpcaustics[science]' "
                                "(or set output.netcdf = false)") from None
    path = out_dir / f"frame_{frame:04d}.nc"
    a = science_arrays(result)
    edges = a["bin_edges_nm"]
    units, comment = time_units(result)
    ds = xr.Dataset(
        {"floor_irradiance": (("time", "wavelength", "y", "x"), a["floor_irradiance"][None],
                              {"units": "W m-2 nm-1", "long_name": "spectral irradiance on the sea floor, "
                               "bin average"}),
         "par": (("time", "y", "x"), a["par_umol_m2_s"][None],
                 {"units": "umol m-2 s-1",
                  "long_name": "photosynthetically available radiation (400-700 nm) on the sea floor"}),
         "wavelength_bnds": (("wavelength", "nv"), np.stack([edges[:-1], edges[1:]], axis=1),
                             {"units": "nm", "long_name": "wavelength bin edges"})},
        coords={"time": ("time", a["time_s"], {"units": units, "calendar": "standard", "axis": "T",
                                               "standard_name": "time", "comment": comment}),
                "wavelength": ("wavelength", a["wavelength_nm"],
                               {"units": "nm", "standard_name": "radiation_wavelength",
                                "long_name": "wavelength bin centre", "bounds": "wavelength_bnds"}),
                "y": ("y", a["y_m"], {"units": "m", "axis": "Y", "standard_name": "projection_y_coordinate",
                                      "long_name": "y of the texel centre (the patch centred at 0)"}),
                "x": ("x", a["x_m"], {"units": "m", "axis": "X", "standard_name": "projection_x_coordinate",
                                      "long_name": "x of the texel centre (the patch centred at 0)"})},
        attrs={"Conventions": CF_CONVENTIONS, "title": "sea-floor caustics rendered by warpcaustics",
               "source": f"warpcaustics {result_version()}", "config": str(result.scene.source or ""),
               "references": "https://cfconventions.org (CF-1.10); docs/architecture.md (outputs)"})
    engine = next((e for e, module in (("netcdf4", "netCDF4"), ("h5netcdf", "h5netcdf"))
                   if importlib.util.find_spec(module)), "scipy")
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=engine, format="NETCDF4" if engine != "scipy" else "NETCDF3_64BIT")
    return {"netcdf": path}


def result_version() -> str:
    from warpcaustics import __version__

    return __version__
