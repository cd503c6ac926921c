"""Warped beam volumes (Sandberg & Falemo 2005; Ernst et al. 2005; Liktor & Dachsbacher 2011).

One beam per surface triangle (or adaptive leaf quad's triangle) and index group: its base
vertices v_i on the displaced surface, the unit refracted directions d_i of its three edges, the
transmittance T_i at each vertex, the length e_i along each edge to the first receiver (a ray
query on the receivers' BVH), and its flux weight ``w = A⊥`` [m²] (the triangle's area projected
perpendicular to the sun). Beams are stored flat, index ``(g · leaves + leaf) · 2 + half``; the
uniform grid lists its quads row-major, so there ``((g Q + qy) Q + qx) 2 + half``. A beam that
carries nothing (facing away from the sun, no vertex transmitting) has ``w = 0``.

The modules, by what they do:

- :mod:`.build`: beams from the displaced surface (corner rays, edge ends on the receivers' BVH,
  end planes) and the adaptive refinement of the surface quads;
- :mod:`.section`: one beam's horizontal sections (area quadratic, watertight inside test), its
  sample at a point, shadows, periodic copies;
- :mod:`.raster`: tile binning over a horizontal plane or the screen (spans, oriented boxes, the
  per-tile lists);
- :mod:`.irradiance`: the flux density at a point (the beam's own or interpolated across beams)
  and the gather at receiver points;
- :mod:`.floor`: the floor's texels, each beam's cut through a texel's floor triangles clipped
  exactly;
- :mod:`.volume`: single scattering into camera rays through scan planes (light shafts).

What host code launches, and the functions the tests call, are re-exported here
(``beam_kernels.floor_texels``).
"""

from warpcaustics.kernels.caustics.beams.build import build_beams, fill_ends, refine_quads, vertex_rays
from warpcaustics.kernels.caustics.beams.floor import floor_texels
from warpcaustics.kernels.caustics.beams.irradiance import point_irradiance
from warpcaustics.kernels.caustics.beams.raster import TileGrid, bin_tiles, horizontal_spans, screen_spans
from warpcaustics.kernels.caustics.beams.section import (
    BeamCorners,
    Beams,
    clamped_sample,
    edge_corners,
    inside_triangle,
)
from warpcaustics.kernels.caustics.beams.volume import (
    ScreenBins,
    ShaftBeams,
    point_inscatter,
    scan_chord,
    scan_plane_radiance,
)

__all__ = [
    "BeamCorners",
    "Beams",
    "ScreenBins",
    "ShaftBeams",
    "TileGrid",
    "bin_tiles",
    "build_beams",
    "clamped_sample",
    "edge_corners",
    "fill_ends",
    "floor_texels",
    "horizontal_spans",
    "inside_triangle",
    "point_inscatter",
    "point_irradiance",
    "refine_quads",
    "scan_chord",
    "scan_plane_radiance",
    "screen_spans",
    "vertex_rays",
]
