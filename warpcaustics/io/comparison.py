"""``caustics.method = "both"`` (photons beside beams) or a method with the flux-ratio map beside
it (``sunmap``, ``eikonal``, ``wave3d``): the other method's frame, the signed difference, their
run.json record and the measures of how far the maps differ."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.io.exr import EMISSIVE_UNITS, RADIANCE_UNITS, write_exr
from warpcaustics.io.images import write_spectral_image


def write_comparison_frame(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``frame_NNNN_<other>.exr/.png``, ``camera_NNNN_<other>.exr/.png`` (with a camera) and
    ``frame_NNNN_<method>_minus_<other>.exr`` (spectral channels only; R, G, B are zero)."""
    paths = {}
    other = result.comparison
    name = other.method
    stem = f"frame_{frame:04d}_{name}"
    paths[f"{name}_exr"], paths[f"{name}_png"] = out_dir / f"{stem}.exr", out_dir / f"{stem}.png"
    header = {"warpcaustics.quantity": f"floor spectral irradiance ({name})",
              "warpcaustics.extent_m": f"{result.extent_m:g}"}
    write_spectral_image(other, other.floor_irradiance[:, ::-1, :], paths[f"{name}_exr"],
                         paths[f"{name}_png"], header, EMISSIVE_UNITS)
    if other.camera_radiance is not None:
        stem = f"camera_{frame:04d}_{name}"
        paths[f"camera_{name}_exr"] = out_dir / f"{stem}.exr"
        paths[f"camera_{name}_png"] = out_dir / f"{stem}.png"
        header = {"warpcaustics.quantity": f"spectral radiance at the camera ({name})"}
        write_spectral_image(other, other.camera_radiance, paths[f"camera_{name}_exr"],
                             paths[f"camera_{name}_png"], header, RADIANCE_UNITS)
    paths["difference_exr"] = out_dir / f"frame_{frame:04d}_{result.method}_minus_{name}.exr"
    difference = (result.floor_irradiance - other.floor_irradiance)[:, ::-1, :]
    quantity = (f"floor spectral irradiance, {result.method} minus {name} (R, G, B are zero: a signed "
                "difference has no colour)")
    write_exr(paths["difference_exr"], np.zeros(difference.shape[1:] + (3,), np.float32), difference,
              result.wavelengths_nm, {"warpcaustics.quantity": quantity,
                                      "warpcaustics.time_s": f"{result.time_s:g}"})
    return paths


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
