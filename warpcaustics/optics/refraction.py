"""Per-vertex refraction of the sun through the water surface (host side)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.kernels.optics import horizon as horizon_kernels
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


def horizon_side(n: int) -> int:
    """Lattice lines (and points per line, less two) that :func:`sweep_visibility` needs at most for
    an N² surface: the patch turned by 45° at half a cell, with margins."""
    return int(math.ceil(2.0 * math.sqrt(2.0) * n)) + 6


def horizon_buffer(n: int, device: str) -> wp.array2d:
    """The sweep's lattice for an N² surface (float32, ``horizon_side`` lines of ``horizon_side`` + 2
    points; 8 N² floats and more: reused by every light direction of a frame)."""
    side = horizon_side(n)
    return wp.empty((side, side + 2), dtype=wp.float32, device=device)


def horizon_bytes(n: int) -> int:
    """Device memory of :func:`horizon_buffer` [bytes]."""
    side = horizon_side(n)
    return 4 * (side + 2) * side


def sun_visibility(surface: Surface, sun_dir: np.ndarray, highest_m: float, device: str,
                   out: wp.array2d | None = None, blocks: tuple[wp.array2d, wp.array2d] | None = None, *,
                   lowest_m: float | None = None, horizon: wp.array2d | None = None) -> wp.array2d:
    """(N, N) 1 where a vertex sees the sun, 0 where a crest of the surface hides it: on a periodic
    surface by :func:`sweep_visibility` (``lowest_m``: the surface's lowest height, read back here if
    not given; ``horizon``: its :func:`horizon_buffer`, allocated here if not given), on a walled one
    by :func:`march_visibility` (``blocks``: its :func:`height_blocks`, built here if not given)."""
    d = np.asarray(sun_dir, np.float64)
    if surface.periodic and d[2] > 1e-6:
        if lowest_m is None:
            lowest_m, _ = height_range(surface, device)
        return sweep_visibility(surface, d, lowest_m, highest_m, device, out=out, horizon=horizon)
    return march_visibility(surface, d, highest_m, device, out=out, blocks=blocks)


def sweep_visibility(surface: Surface, sun_dir: np.ndarray, lowest_m: float, highest_m: float, device: str,
                     out: wp.array2d | None = None, horizon: wp.array2d | None = None) -> wp.array2d:
    """(N, N) crest shading of a periodic surface by one sweep down each line of a lattice aligned
    with the light's azimuth (``kernels/optics/horizon.py``): the march's test of the same half-cell
    points along the ray, each vertex reading the highest of them from the lattice (bilinear), so
    its answer differs from the march's only where a crest grazes the ray to within the lattice's
    interpolation. Light from above the horizon (``sun_dir[2]`` > 0)."""
    n = surface.resolution
    out = out if out is not None else wp.empty((n, n), dtype=wp.float32, device=device)
    d = np.asarray(sun_dir, np.float64)
    horizontal = math.hypot(d[0], d[1])
    if horizontal < 1e-6:
        out.fill_(1.0)  # light from the zenith: a height field cannot shade itself
        return out
    horizon = horizon if horizon is not None else horizon_buffer(n, device)
    extent = float(surface.extent_m)
    along = d[:2] / horizontal
    spacing = 0.5 * extent / n
    rise = spacing * d[2] / horizontal
    half = 0.5 * extent * (abs(along[0]) + abs(along[1])) + 2.0 * spacing
    lines = int(math.ceil(2.0 * half / spacing)) + 1
    # each line starts where a crest could no longer reach a ray from the lowest vertex
    steps = lines + 2 + int(math.ceil((highest_m - lowest_m) / rise)) + 2
    heights = out  # the visibility is written over the heights once the sweep has read them
    wp.launch(horizon_kernels.surface_heights, dim=(n, n), inputs=[surface.positions], outputs=[heights],
              device=device)
    lattice = horizon_kernels.Lattice()
    lattice.extent_m, lattice.start, lattice.spacing, lattice.rise = extent, -half, spacing, rise
    lattice.along, lattice.across = wp.vec2(*along), wp.vec2(-along[1], along[0])
    wp.launch(horizon_kernels.horizon_sweep, dim=lines, inputs=[heights, lattice, steps], outputs=[horizon],
              device=device)
    wp.launch(horizon_kernels.horizon_visibility, dim=(n, n), inputs=[surface.positions, lattice, horizon],
              outputs=[out], device=device)
    return out


def march_visibility(surface: Surface, sun_dir: np.ndarray, highest_m: float, device: str,
                     out: wp.array2d | None = None, blocks: tuple[wp.array2d, wp.array2d] | None = None
                     ) -> wp.array2d:
    """(N, N) crest shading by a march from every vertex towards the light in half-cell steps,
    stepping over blocks of cells its ray clears (``blocks``: the surface's :func:`height_blocks`,
    built here if not given); walled surfaces, whose rays leave over the rim, and the baseline of
    :func:`sweep_visibility`."""
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
