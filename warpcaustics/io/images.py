"""A frame's spectral images: each one an EXR (linear RGB + spectral bands) and its sRGB PNG
preview, written as a pair from one colour conversion.

Images are drawn as seen from above with +x to the right and +y up: image row 0 is the floor
array's last row (largest y).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.config import Colourspace, WhiteBalance
from warpcaustics.io.exr import EMISSIVE_UNITS, RADIANCE_UNITS, write_exr
from warpcaustics.io.png import write_png


def write_floor(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``frame_NNNN.exr`` (floor spectral irradiance, RGB + bands) and ``frame_NNNN.png``."""
    image = result.floor_irradiance[:, ::-1, :]  # image row 0 = largest y
    stem = f"frame_{frame:04d}"
    paths = {"exr": out_dir / f"{stem}.exr", "png": out_dir / f"{stem}.png"}
    write_spectral_image(result, image, paths["exr"], paths["png"], {
        "warpcaustics.quantity": "floor spectral irradiance",
        "warpcaustics.extent_m": f"{result.map_extent_m:g}",
        "warpcaustics.center_m": "{:g},{:g}".format(*result.map_center_m)}, EMISSIVE_UNITS)
    return paths


def write_camera(result, out_dir: Path, *, frame: int) -> dict[str, Path]:
    """``camera_NNNN.exr`` (spectral radiance at the camera) and ``camera_NNNN.png``."""
    stem = f"camera_{frame:04d}"
    paths = {"camera_exr": out_dir / f"{stem}.exr", "camera_png": out_dir / f"{stem}.png"}
    write_spectral_image(result, result.camera_radiance, paths["camera_exr"], paths["camera_png"], {
        "warpcaustics.quantity": "spectral radiance at the camera"}, RADIANCE_UNITS)
    return paths


def write_spectral_image(result, image: np.ndarray, exr: Path, png: Path, header: dict[str, str],
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
        units=units, colourspace=out_cfg.colourspace.value)
    write_png(png, colour_out.tone_map_srgb8(srgb, xyz[..., 1], out_cfg.exposure_ev))
