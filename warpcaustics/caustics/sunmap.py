"""Sun-map caustics (GPU Gems ch. 2) on the host: ``caustics.method = "sunmap"``.

The kernels (``kernels/caustics/sunmap.py``) give a grey brightness per floor-map texel by either of
the chapter's variants (``caustics.sunmap_variant``: §2.3–2.4 per vertex, §2.5 per pixel);
the pipeline scales it per band so that its mean equals the flux-ratio map's of the same frame
(the chapter's map has no absolute scale: "zero means no lighting and one means a beam of very
focused light"). The flux-ratio map rides along as the comparison.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from warpcaustics.caustics.fluxratio import ApproximateStage
from warpcaustics.config import Config, SunMapVariant
from warpcaustics.kernels.caustics import sunmap as sunmap_kernels
from warpcaustics.optics.refraction import still_water_refraction
from warpcaustics.water import ProceduralWater, Surface


class SunMapCaustics:
    """Owns the brightness map (M, M) and the sun-map parameters of a scene."""

    def __init__(self, cfg: Config, sun_dir: np.ndarray, ior: float, device: str, *, periodic: bool):
        m = cfg.caustics.map_resolution
        self.device = device
        s = np.asarray(sun_dir, np.float64)
        s = s / np.linalg.norm(s)
        params = sunmap_kernels.SunMap()
        params.up = wp.vec3(*(-still_water_refraction(s, ior)).astype(np.float32))
        params.sun_dir = wp.vec3(*s.astype(np.float32))
        params.eta = float(ior)
        disk = 0.5 * math.radians(cfg.sun.angular_diameter_deg)
        params.disk_rad = disk
        params.cos_disk = math.cos(disk)
        params.halo_rad = 0.5 * math.radians(cfg.caustics.sunmap_halo_deg)
        params.floor_z = -float(cfg.floor.depth_m)
        params.extent_m = float(cfg.water.extent_m)
        params.periodic = int(periodic)
        params.light_scale = (float(ior) - 1.0) / float(cfg.floor.depth_m)
        self.params = params
        self.per_pixel = cfg.caustics.sunmap_variant == SunMapVariant.PER_PIXEL
        self.brightness = wp.empty((m, m), dtype=wp.float32, device=device)
        """Sun-map brightness per floor texel (M, M), 0…1, row index along +y."""

    def run(self, surface: Surface, water, time_s: float) -> wp.array2d:
        """Fill :attr:`brightness` for the surface at ``time_s`` by the configured variant; the
        procedural waves use their analytic height and gradient, every other model its surface
        grid."""
        m = self.brightness.shape[0]
        if isinstance(water, ProceduralWater):
            kernel = (sunmap_kernels.sunmap_pixel_procedural if self.per_pixel
                      else sunmap_kernels.sunmap_procedural)
            wp.launch(
                kernel,
                dim=(m, m),
                inputs=[self.params, water.waves, float(time_s)],
                outputs=[self.brightness],
                device=self.device,
            )
        else:
            wp.launch(
                sunmap_kernels.sunmap_pixel_grid if self.per_pixel else sunmap_kernels.sunmap_grid,
                dim=(m, m),
                inputs=[self.params, surface.positions, surface.normals],
                outputs=[self.brightness],
                device=self.device,
            )
        return self.brightness

    def floor_map(self, surface: Surface, water, time_s: float, highest_m: float, visible: wp.array2d,
                  flux_ratio: np.ndarray) -> tuple[np.ndarray, dict]:
        """(K, M, M) floor map: the sun map scaled per band to ``flux_ratio``'s mean, and the
        RenderResult fields it adds (the grey brightness). ``visible`` is not used: the chapter's
        backward rays know no shading by crests."""
        brightness = self.run(surface, water, time_s).numpy().copy()
        return scale_to_flux_ratio(brightness, flux_ratio), {"sunmap_brightness": brightness}


def scale_to_flux_ratio(brightness: np.ndarray, flux_ratio: np.ndarray) -> np.ndarray:
    """(K, M, M) floor map: the grey ``brightness`` (M, M) scaled per band so that its mean equals
    the mean of ``flux_ratio`` (K, M, M); all zero where no texel sees the sun."""
    b = brightness.astype(np.float64)
    mean = b.mean()
    if mean <= 0.0:
        return np.zeros_like(flux_ratio)
    scale = flux_ratio.mean(axis=(1, 2), dtype=np.float64) / mean
    return (scale[:, None, None] * b[None]).astype(np.float32)


class SunMapStage(ApproximateStage):
    """``sunmap``: GPU Gems ch. 2's sun map, scaled per band to the flux-ratio map's mean."""

    name = "sunmap"

    def make(self, mean_ior: float) -> SunMapCaustics:
        return SunMapCaustics(self.scene.config, self.scene.sun_direction, mean_ior, self.device,
                              periodic=self.water.periodic)

    @classmethod
    def bytes_needed(cls, scene, k: int, groups: int) -> int:
        m = scene.config.caustics.map_resolution
        return super().bytes_needed(scene, k, groups) + m * m * 4
