"""Writers: OpenEXR (RGB + spectral bands), a PNG preview and run.json, each written atomically.

Images are drawn as seen from above with +x to the right and +y up: image row 0 is the floor
array's last row (largest y).
"""

from __future__ import annotations

import csv
import json
import os
import platform
import struct
import zlib
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import numpy as np

from warpcaustics import __version__
from warpcaustics.config import Colourspace, WhiteBalance, config_to_dict

EMISSIVE_UNITS = "W.m^-2.nm^-1"
RADIANCE_UNITS = "W.m^-2.sr^-1.nm^-1"


@contextmanager
def atomic_path(path: Path):
    """Yield a temporary name beside ``path``; rename it onto ``path`` only if the block succeeds."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_csv(path: Path, rows: list[dict], fieldnames: list[str] | None = None) -> None:
    """Rows as a CSV table, written atomically: the columns ``fieldnames`` (a row without one
    leaves it empty), or the first row's keys."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]) if fieldnames is None else fieldnames)
        writer.writeheader()
        writer.writerows(rows)


def pyplot(needs: str):
    """matplotlib's pyplot on the Agg backend, or a one-line ConfigError: ``needs`` says what needs
    it (e.g. "the study's plots need") and the error names the extra to install."""
    from warpcaustics.errors import ConfigError

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ConfigError(f"{needs} matplotlib: pip install -e '.[study]'") from None
    return plt


def spectral_channel_name(wavelength_nm: float) -> str:
    """Fichet, Pacanowski & Wilkie (2021) spectral EXR channel: ``S0.550,000000nm``."""
    return "S0." + f"{wavelength_nm:.6f}".replace(".", ",") + "nm"


def write_exr(path: Path, rgb: np.ndarray, spectral: np.ndarray | None, wavelengths_nm: np.ndarray,
              extra_header: dict[str, str], units: str = EMISSIVE_UNITS) -> None:
    import OpenEXR

    channels = {name: np.ascontiguousarray(rgb[..., i], dtype=np.float32) for i, name in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    if spectral is not None:
        for k, wl in enumerate(wavelengths_nm):
            channels[spectral_channel_name(wl)] = np.ascontiguousarray(spectral[k], dtype=np.float32)
        header["spectralLayoutVersion"] = "1.0"
        header["emissiveUnits"] = units
    header.update(extra_header)
    with atomic_path(path) as tmp, OpenEXR.File(header, channels) as exr:
        exr.write(str(tmp))


def write_png(path: Path, rgb8: np.ndarray) -> None:
    """Minimal 8-bit RGB PNG writer (zlib + CRC), so previews need no imaging library."""
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[row].tobytes() for row in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    with atomic_path(path) as tmp:
        tmp.write_bytes(png)


def write_json(path: Path, data: dict) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2, default=_jsonable) + "\n", encoding="utf-8")


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)


def versions() -> dict[str, str]:
    out = {"warpcaustics": __version__, "python": platform.python_version()}
    for dist in ("warp-lang", "numpy", "colour-science", "openexr"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def save_frame(result, out_dir: Path, *, frame: int = 0) -> dict[str, Path]:
    """Write one frame's ``frame_NNNN.exr`` (RGB + spectral bands) and ``frame_NNNN.png``."""

    out_dir.mkdir(parents=True, exist_ok=True)
    image = result.floor_irradiance[:, ::-1, :]  # image row 0 = largest y
    stem = f"frame_{frame:04d}"
    paths = {"exr": out_dir / f"{stem}.exr", "png": out_dir / f"{stem}.png"}
    _write_spectral_image(result, image, paths["exr"], paths["png"], {
        "warpcaustics.quantity": "floor spectral irradiance",
        "warpcaustics.extent_m": f"{result.map_extent_m:g}",
        "warpcaustics.center_m": "{:g},{:g}".format(*result.map_center_m)}, EMISSIVE_UNITS)
    if result.camera_radiance is not None:
        stem = f"camera_{frame:04d}"
        paths["camera_exr"] = out_dir / f"{stem}.exr"
        paths["camera_png"] = out_dir / f"{stem}.png"
        _write_spectral_image(result, result.camera_radiance, paths["camera_exr"], paths["camera_png"], {
            "warpcaustics.quantity": "spectral radiance at the camera"}, RADIANCE_UNITS)
    if result.scene.config.output.vtk:
        paths.update(write_vtk(result, out_dir, frame=frame))
    if result.scene.config.output.npz:
        paths["npz"] = write_npz(result, out_dir / f"frame_{frame:04d}.npz")
    if result.scene.config.output.netcdf:
        paths["netcdf"] = write_netcdf(result, out_dir / f"frame_{frame:04d}.nc")
    if result.comparison is not None:  # "both" or "sunmap": the other method's frame and the difference
        other = result.comparison
        name = other.method
        stem = f"frame_{frame:04d}_{name}"
        paths[f"{name}_exr"], paths[f"{name}_png"] = out_dir / f"{stem}.exr", out_dir / f"{stem}.png"
        header = {"warpcaustics.quantity": f"floor spectral irradiance ({name})",
                  "warpcaustics.extent_m": f"{result.extent_m:g}"}
        _write_spectral_image(other, other.floor_irradiance[:, ::-1, :], paths[f"{name}_exr"],
                              paths[f"{name}_png"], header, EMISSIVE_UNITS)
        if other.camera_radiance is not None:
            stem = f"camera_{frame:04d}_{name}"
            paths[f"camera_{name}_exr"] = out_dir / f"{stem}.exr"
            paths[f"camera_{name}_png"] = out_dir / f"{stem}.png"
            header = {"warpcaustics.quantity": f"spectral radiance at the camera ({name})"}
            _write_spectral_image(other, other.camera_radiance, paths[f"camera_{name}_exr"],
                                  paths[f"camera_{name}_png"], header, RADIANCE_UNITS)
        paths["difference_exr"] = out_dir / f"frame_{frame:04d}_{result.method}_minus_{name}.exr"
        difference = (result.floor_irradiance - other.floor_irradiance)[:, ::-1, :]
        quantity = (f"floor spectral irradiance, {result.method} minus {name} (R, G, B are zero: a signed "
                    "difference has no colour)")
        write_exr(paths["difference_exr"], np.zeros(difference.shape[1:] + (3,), np.float32), difference,
                  result.wavelengths_nm, {"warpcaustics.quantity": quantity,
                                          "warpcaustics.time_s": f"{result.time_s:g}"})
    return paths


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


def write_npz(result, path: Path) -> Path:
    """``frame_NNNN.npz``: :func:`science_arrays` (floor_irradiance in W m⁻² nm⁻¹, PAR in
    µmol photons m⁻² s⁻¹, coordinates in nm, m and s)."""
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **science_arrays(result))
    return path


def write_netcdf(result, path: Path) -> Path:
    """``frame_NNNN.nc`` through xarray: ``floor_irradiance`` (time, wavelength, y, x) and ``par``
    (time, y, x), units and descriptions as attributes (NetCDF3 via scipy when netCDF4 is not
    installed)."""
    try:
        import xarray as xr
    except ImportError:
        from warpcaustics.errors import WarpcausticsError

        raise WarpcausticsError("output.netcdf = true needs xarray: pip install 'warpcaustics[science]' "
                                "(or set output.netcdf = false)") from None
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
    return path


def band_name(wavelength_nm: float) -> str:
    """Name of a per-band VTK array: ``irradiance_437.5nm``."""
    return f"irradiance_{wavelength_nm:g}nm"


def _save_mesh(mesh, path: Path) -> None:
    """pyvista picks the writer from the extension, so the temporary name keeps it."""
    tmp = path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")
    try:
        mesh.save(str(tmp))
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_vtk(result, out_dir: Path, *, frame: int = 0) -> dict[str, Path]:
    """VTK files of one frame (readable by ParaView and pyvista), each written atomically:

    - ``surface_NNNN.vts``: the water surface's N×N vertices [m] with point data ``normal``;
    - ``floor_NNNN.vti``: the floor map as image cells over the patch at the floor's rest depth,
      cell data ``irradiance_<λ>nm`` [W m^-2 nm^-1] per band;
    - ``receivers_NNNN.vtp`` (photons, beams): the receiver meshes other than the floor, cell data
      ``irradiance_<λ>nm`` per band and ``receiver`` (1 = walls, 2 + i = ``receivers[i]``).
    """
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pyvista as pv

    paths = {}
    stem = f"{frame:04d}"
    pos = result.surface_positions.astype(np.float64)
    grid = pv.StructuredGrid(pos[..., 0].T, pos[..., 1].T, pos[..., 2].T)
    grid.point_data["normal"] = result.surface_normals.reshape(-1, 3)  # points run x fastest, as here
    paths["surface_vtk"] = out_dir / f"surface_{stem}.vts"
    _save_mesh(grid, paths["surface_vtk"])

    m = result.floor_irradiance.shape[-1]
    extent = result.map_extent_m
    cx, cy = result.map_center_m
    image = pv.ImageData(dimensions=(m + 1, m + 1, 1), spacing=(extent / m, extent / m, 1.0),
                         origin=(cx - extent / 2, cy - extent / 2, -result.scene.config.floor.depth_m))
    for wl, band in zip(result.wavelengths_nm, result.floor_irradiance):
        image.cell_data[band_name(wl)] = band.ravel()  # row index along +y: x varies fastest
    paths["floor_vtk"] = out_dir / f"floor_{stem}.vti"
    _save_mesh(image, paths["floor_vtk"])

    if result.receiver_mesh is not None:
        points, triangles = result.receiver_mesh
        faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel()
        poly = pv.PolyData(points, faces)
        irradiance = result.face_flux_w_nm / result.face_area_m2[:, None]
        for k, wl in enumerate(result.wavelengths_nm):
            poly.cell_data[band_name(wl)] = irradiance[:, k]
        poly.cell_data["receiver"] = result.face_receiver
        paths["receivers_vtk"] = out_dir / f"receivers_{stem}.vtp"
        _save_mesh(poly, paths["receivers_vtk"])
    return paths


def _write_spectral_image(result, image: np.ndarray, exr: Path, png: Path, header: dict[str, str],
                          units: str) -> None:
    """(K, H, W) spectral image (row 0 at the top) → EXR (RGB + bands) and an sRGB PNG preview."""
    from warpcaustics.optics import colour as colour_out

    bins = result.bins
    out_cfg = result.scene.config.output
    xyz = colour_out.spectral_to_xyz(image, bins)
    white = None
    if out_cfg.white_balance is WhiteBalance.SUN:
        white = colour_out.spectral_to_xyz(result.sun_irradiance[:, None, None], bins)[0, 0]
    rgb = colour_out.xyz_to_linear_rgb(xyz, out_cfg.colourspace.value, white)
    srgb = rgb
    if out_cfg.colourspace is not Colourspace.SRGB:  # the PNG preview is always sRGB
        srgb = colour_out.xyz_to_linear_rgb(xyz, "sRGB", white)
    write_exr(exr, rgb, image if out_cfg.spectral_exr else None, result.wavelengths_nm, {
        **header, "warpcaustics.time_s": f"{result.time_s:g}",
        "warpcaustics.rgb": f"linear {out_cfg.colourspace.value}, white balance "
                            f"{out_cfg.white_balance.value}"},
        units=units)
    write_png(png, colour_out.tone_map_srgb8(srgb, xyz[..., 1], out_cfg.exposure_ev))


def comparison_entry(frame: int, r) -> dict:
    """``both`` (photons beside beams) or ``sunmap`` (the flux-ratio map beside it): the other
    method's files, flux and stats, and how far the maps differ."""
    other = r.comparison
    name = other.method
    files = [f"frame_{frame:04d}_{name}.exr", f"frame_{frame:04d}_{name}.png",
             f"frame_{frame:04d}_{r.method}_minus_{name}.exr"]
    if other.camera_radiance is not None:
        files += [f"camera_{frame:04d}_{name}.exr", f"camera_{frame:04d}_{name}.png"]
    l1 = relative_l1(r.floor_irradiance, other.floor_irradiance)
    entry = {"method": name, "files": files, "floor_flux_w_nm": other.floor_flux_w_nm,
             "transmitted_flux_w_nm": other.transmitted_flux_w_nm,
             f"floor_relative_l1_{r.method}_vs_{name}": l1}
    if other.photon_stats is not None:
        entry["photons"] = other.photon_stats
    if name == "fluxratio":  # the approximate method against the reference, maps normalised
        entry[f"floor_correlation_{r.method}_vs_{name}"] = map_correlation(
            r.floor_irradiance, other.floor_irradiance, r.bin_widths_nm)
    return entry


def relative_l1(a: np.ndarray, reference: np.ndarray) -> float:
    """Σ|a − ref| / Σ|ref| over all bands and texels (float64)."""
    a = np.asarray(a, np.float64)
    ref = np.asarray(reference, np.float64)
    return float(np.abs(a - ref).sum() / max(np.abs(ref).sum(), 1e-300))


def map_correlation(a: np.ndarray, reference: np.ndarray, bin_widths_nm: np.ndarray) -> float:
    """Pearson correlation of the maps integrated over the bands, Σ E_k Δλ_k (1: the same pattern
    up to scale); 0 when either map is uniform."""
    x = np.einsum("kij,k->ij", np.asarray(a, np.float64), bin_widths_nm).ravel()
    y = np.einsum("kij,k->ij", np.asarray(reference, np.float64), bin_widths_nm).ravel()
    x, y = x - x.mean(), y - y.mean()
    norm = np.sqrt((x * x).sum() * (y * y).sum())
    return float((x * y).sum() / norm) if norm > 0 else 0.0


def frame_entry(frame: int, r) -> dict:
    """run.json's record of one frame (JSON-ready: arrays become lists)."""
    entry = {
        "frame": frame,
        "time_s": r.time_s,
        "files": [f"frame_{frame:04d}.exr", f"frame_{frame:04d}.png"] + (
            [f"camera_{frame:04d}.exr", f"camera_{frame:04d}.png"] if r.camera_radiance is not None else []),
        "timings_s": r.timings_s,
        "floor_mean_irradiance_w_m2_nm": r.floor_irradiance.mean(axis=(1, 2), dtype=np.float64),
        **({"sky_floor_mean_irradiance_w_m2_nm": r.sky_floor_irradiance.mean(axis=(1, 2), dtype=np.float64)}
           if r.sky_floor_irradiance is not None else {}),
        "floor_flux_w_nm": r.floor_flux_w_nm,
        "transmitted_flux_w_nm": r.transmitted_flux_w_nm,
        "fold_fraction": r.fold_fraction,
        **({"photons": r.photon_stats} if r.photon_stats is not None else {}),
        **({"beams": r.beam_stats} if r.beam_stats is not None else {}),
        **({"eikonal": r.eikonal_stats} if r.eikonal_stats is not None else {}),
        **({"wave3d": r.wave3d_stats} if r.wave3d_stats is not None else {}),
        **({"multiple_scattering": r.multiple_scattering_stats} if r.multiple_scattering_stats is not None
           else {}),
        **({"comparison": comparison_entry(frame, r)} if r.comparison is not None else {}),
        "statistics": frame_statistics_entry(r),
    }
    return json.loads(json.dumps(entry, default=_jsonable))


def frame_statistics_entry(r) -> dict:
    """run.json's irradiance statistics of a frame, with the probe values an animation's time
    statistics are built from."""
    from warpcaustics.batch.stats import frame_statistics, probe_values

    cfg = r.scene.config.stats
    return {**frame_statistics(r, cfg), "probe_irradiance_w_m2": probe_values(r, cfg).tolist()}


def time_statistics(frames: list[dict], first) -> dict | None:
    """Statistics of the probes' E(t) over an animation (three frames or more, equally spaced);
    ``first`` is the first frame's RenderResult (for the config and the map)."""
    from warpcaustics.batch.stats import probe_points, series_statistics

    if len(frames) < 3:
        return None
    stats_cfg = first.scene.config.stats
    times = np.array([f["time_s"] for f in frames])
    series = np.array([f["statistics"]["probe_irradiance_w_m2"] for f in frames])
    dt = float(np.mean(np.diff(times)))
    return {"probes_m": [list(p) for p in probe_points(stats_cfg, first.map_center_m)], "dt_s": dt,
            **series_statistics(series, dt, stats_cfg.flash_threshold)}


def write_run_json(out_dir: Path, results: list, *, frames: list[dict] | None = None) -> Path:
    """Write ``run.json`` (resolved config, versions, device, per-frame timings and totals).

    ``frames``: the per-frame records (:func:`frame_entry`) when they are not all in ``results``
    (a resumed pool animation); by default one per result, numbered from 0. Written last, after
    every frame file: its presence marks a complete run.
    """
    first = results[0]
    path = out_dir / "run.json"
    frames = frames if frames is not None else [frame_entry(i, r) for i, r in enumerate(results)]
    series = time_statistics(frames, first)
    write_json(path, {
        "source": first.scene.source,
        "config": config_to_dict(first.scene.config),
        "device": first.device,
        "versions": versions(),
        "wavelengths_nm": first.wavelengths_nm,
        "bin_widths_nm": first.bin_widths_nm,
        "attenuation_per_m": first.attenuation_per_m,
        "ior": first.ior,
        "sun_irradiance_w_m2_nm": first.sun_irradiance,
        "frames": frames,
        **({"time_statistics": series} if series is not None else {}),
    })
    return path
