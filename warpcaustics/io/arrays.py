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


def write_netcdf(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``frame_NNNN.nc`` through xarray: ``floor_irradiance`` (time, wavelength, y, x) and ``par``
    (time, y, x), units and descriptions as attributes (NetCDF3 via scipy when netCDF4 is not
    installed)."""
    try:
        import xarray as xr
    except ImportError:
        from warpcaustics.errors import WarpcausticsError

        raise WarpcausticsError("output.netcdf = true needs xarray: pip install 'warpcaustics[science]' "
                                "(or set output.netcdf = false)") from None
    path = out_dir / f"frame_{frame:04d}.nc"
    a = science_arrays(result)
    ds = xr.Dataset(
        {"floor_irradiance": (("time", "wavelength", "y", "x"), a["floor_irradiance"][None],
                              {"units": "W m-2 nm-1", "long_name": "floor spectral irradiance"}),
         "par": (("time", "y", "x"), a["par_umol_m2_s"][None],
                 {"units": "umol m-2 s-1",
                  "long_name": "photosynthetically available radiation (400-700 nm)"})},
        coords={"time": ("time", a["time_s"], {"units": "s"}),
                "wavelength": ("wavelength", a["wavelength_nm"], {"units": "nm"}),
                "y": ("y", a["y_m"], {"units": "m"}), "x": ("x", a["x_m"], {"units": "m"})},
        attrs={"source": "warpcaustics", "config": str(result.scene.source or ""),
               "bin_edges_nm": a["bin_edges_nm"]})
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp)
    return {"netcdf": path}
