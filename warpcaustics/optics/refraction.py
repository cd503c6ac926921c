"""Per-vertex refraction of the sun through the water surface (host side)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.kernels.optics import refract as refract_kernels
from warpcaustics.water import Surface


@dataclass
class Refracted:
    """Where each vertex's refracted sun ray meets the floor, per index group g (G, N, N)."""

    hit_xy: wp.array3d
    """Floor intersection (x, y) [m]; not wrapped into the patch."""
    path_m: wp.array3d
    """Path length from the surface vertex to the floor [m]."""
    transmittance: wp.array3d
    """Exact unpolarised Fresnel transmittance (0 where the vertex is lit from behind)."""

    @classmethod
    def allocate(cls, groups: int, n: int, device: str) -> Refracted:
        return cls(wp.empty((groups, n, n), dtype=wp.vec2, device=device),
                   wp.empty((groups, n, n), dtype=wp.float32, device=device),
                   wp.empty((groups, n, n), dtype=wp.float32, device=device))


def still_water_refraction(sun_dir: np.ndarray, ior: float) -> np.ndarray:
    """Unit direction of the sun's light refracted into still water (float64, pointing down)."""
    from warpcaustics.reference import refract

    t = refract(-np.asarray(sun_dir, np.float64), np.array([0.0, 0.0, 1.0]), 1.0 / ior)
    return t / np.linalg.norm(t)


def height_range(surface: Surface, device: str) -> tuple[float, float]:
    """(lowest, highest) surface height [m] (one small read-back)."""
    z_range = wp.array(np.array([np.inf, -np.inf], np.float32), dtype=wp.float32, device=device)
    n = surface.resolution
    wp.launch(refract_kernels.height_range, dim=(n, n), inputs=[surface.positions],
              outputs=[z_range], device=device)
    lo, hi = z_range.numpy()
    return float(lo), float(hi)


def height_blocks(surface: Surface, device: str) -> tuple[wp.array2d, wp.array2d]:
    """The highest vertex of each coarse and fine block of the surface's cells
    (``refract_kernels.COARSE_CELLS``, ``FINE_CELLS``): what :func:`sun_visibility` steps over.
    One pass per level over the heights; a frame builds them once for all its light directions."""
    n = surface.resolution
    blocks = []
    for cells in (refract_kernels.COARSE_CELLS, refract_kernels.FINE_CELLS):
        count = -(-n // cells)
        highest = wp.empty((count, count), dtype=wp.float32, device=device)
        wp.launch(refract_kernels.block_heights, dim=(count, count), inputs=[surface.positions, cells],
                  outputs=[highest], device=device)
        blocks.append(highest)
    return blocks[0], blocks[1]


def sun_visibility(surface: Surface, sun_dir: np.ndarray, highest_m: float, device: str,
                   out: wp.array2d | None = None, blocks: tuple[wp.array2d, wp.array2d] | None = None
                   ) -> wp.array2d:
    """(N, N) 1 where a vertex sees the sun, 0 where a crest of the surface hides it. ``blocks``:
    this surface's :func:`height_blocks` (built here if not given)."""
    n = surface.resolution
    out = out if out is not None else wp.empty((n, n), dtype=wp.float32, device=device)
    coarse, fine = blocks if blocks is not None else height_blocks(surface, device)
    z_range = wp.array(np.array([0.0, highest_m], np.float32), dtype=wp.float32, device=device)
    wp.launch(refract_kernels.sun_visibility, dim=(n, n),
              inputs=[surface.positions, wp.vec3(*np.asarray(sun_dir, np.float32)),
                      float(surface.extent_m), int(surface.periodic), z_range, coarse, fine],
              outputs=[out], device=device)
    return out


def refract_to_floor(surface: Surface, visible: wp.array2d, ior: np.ndarray, sun_dir: np.ndarray,
                     floor_z_m: float, device: str, out: Refracted | None = None) -> Refracted:
    """Refract the sun at every vertex for each refractive index in ``ior`` (one per group);
    ``visible`` (N, N) scales each vertex's transmittance (sun shading by the surface itself)."""
    n = surface.resolution
    groups = len(ior)
    out = out or Refracted.allocate(groups, n, device)
    wp.launch(refract_kernels.refract_to_floor, dim=(groups, n, n),
              inputs=[surface.positions, surface.normals, visible,
                      wp.array(np.asarray(ior, np.float32), dtype=wp.float32, device=device),
                      wp.vec3(*np.asarray(sun_dir, np.float32)), float(floor_z_m)],
              outputs=[out.hit_xy, out.path_m, out.transmittance], device=device)
    return out
