"""``[caustics]``: the caustics method and its floor map."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _coordinate, _length, _positive, _range


class CausticsMethod(str, enum.Enum):
    FLUXRATIO = "fluxratio"
    PHOTONS = "photons"
    BEAMS = "beams"
    BOTH = "both"
    SUNMAP = "sunmap"
    EIKONAL = "eikonal"
    WAVE3D = "wave3d"

    @property
    def uses_receivers(self) -> bool:
        """Photons and beams light every receiver (relief, walls, meshes) and feed the camera."""
        return self in (CausticsMethod.PHOTONS, CausticsMethod.BEAMS, CausticsMethod.BOTH)


GREY_METHODS = (CausticsMethod.SUNMAP, CausticsMethod.EIKONAL, CausticsMethod.WAVE3D)
"""Methods that trace one refractive index for all bands."""


class Intersection(str, enum.Enum):
    NEWTON = "newton"
    EXACT = "exact"


class PhotonSplat(str, enum.Enum):
    TEXEL = "texel"
    FOOTPRINT = "footprint"


class SunMapVariant(str, enum.Enum):
    PER_VERTEX = "per_vertex"
    PER_PIXEL = "per_pixel"


class BeamBounds(str, enum.Enum):
    HULL = "hull"
    PRISM = "prism"
    ERNST = "ernst"


class BeamInterpolation(str, enum.Enum):
    SMOOTH = "smooth"
    FLAT = "flat"


@dataclass(frozen=True)
class CausticsConfig:
    method: CausticsMethod = CausticsMethod.FLUXRATIO
    """Caustics method: ``fluxratio`` (refracted triangle footprints on a flat floor),
    ``photons`` (photon splatting onto every receiver, Shah et al. 2007) or ``beams`` (warped beam
    volumes through a tile-binned rasteriser onto every receiver, with volume caustics in the
    camera; Ernst et al. 2005, Liktor & Dachsbacher 2011) or ``both`` (beams and photons on the same
    frame, both saved with the difference of their floor maps) or ``sunmap`` (GPU Gems ch. 2:
    backward rays from the floor looked up in a soft sun map, scaled to the flux-ratio map's mean,
    which is saved beside it) or ``eikonal`` (after Mercier 2013: the refracted front's travel
    time on a 3-D grid, its Laplacian carried along the rays to the floor) or ``wave3d`` (after
    Mercier 2013 §4: the 3-D wave equation driven by the refracted wave, its time-averaged
    intensity on the floor); those two also save the flux-ratio map beside theirs."""
    map_resolution: int = field(default=512, metadata=_range(1, 16384))
    """Texels M per side of the floor irradiance map over the water extent (or the window) [-]."""
    map_extent_m: float = field(default=0.0, metadata=_length())
    """Side of a square floor-map window [m] (``fluxratio``): millimetre texels over a small part
    of a large sea; 0 = the whole water extent."""
    map_center_m: tuple[float, ...] = field(default=(0.0, 0.0), metadata=_coordinate())
    """Centre (x, y) of the floor-map window [m]."""
    bounces: int = field(default=1, metadata=_range(1, 3))
    """Specular interactions a photon may make: 1 = the water surface's refraction alone; 2 or 3 add
    one or two passes through a glass receiver (``receivers[].ior``: in and out is one) or
    reflections off a mirror (``receivers[].specular``) before the light lands (``photons`` with the
    exact intersection) [-]."""
    intersection: Intersection = Intersection.EXACT
    """How a ``photons`` photon finds its receiver: ``exact`` (ray query on the receivers' BVH) or
    ``newton`` (Shah's iteration on a receiver-position buffer rendered from the light, along the
    sun's refracted direction under still water)."""
    photon_splat: PhotonSplat = PhotonSplat.FOOTPRINT
    """How a ``photons`` photon lights the floor map: ``texel`` (its flux into the texel under its
    hit) or ``footprint`` (spread evenly over its lattice cell, the parallelogram its grid
    neighbours' hits span, clipped exactly into the texels; Frisvad et al. 2014's footprint from
    finite differences; a photon without a cell keeps its texel)."""
    photon_subdivisions: int = field(default=4, metadata=_range(1, 64))
    """s: photons per surface cell are s×s [-]."""
    newton_iterations: int = field(default=3, metadata=_range(0, 64))
    """Iterations k of the ``newton`` intersection [-]."""
    newton_buffer_resolution: int = field(default=1024, metadata=_range(16, 16384))
    """Texels per side of the ``newton`` receiver-position buffer seen from the light [-]."""
    beam_interpolation: BeamInterpolation = BeamInterpolation.FLAT
    """How ``beams`` spread a beam's light over its section: ``flat`` (each beam's own flux over its
    own section, as the flux-ratio map; triangle facets can show in close-ups) or ``smooth`` (after
    Ernst et al. 2005: per-vertex wave-front densities of the surrounding beams interpolated across
    each beam, continuous from beam to beam but blurred over about two surface cells)."""
    beam_levels: int = field(default=0, metadata=_range(0, 4))
    """Adaptive beams (Liktor & Dachsbacher 2011 §4.2): start from quads of 2^beam_levels surface
    cells and split where needed down to single cells; 0 = one beam pair per cell (uniform) [-]."""
    beam_tolerance: float = field(default=0.25, metadata=_range(0.0, 1.0e6))
    """Split an adaptive quad where a vertex's refracted ray, followed to its receiver, misses the
    quad's interpolated ray by more than this many surface cells [-]."""
    beam_bounds: BeamBounds = BeamBounds.HULL
    """The volume each beam's light shafts are bounded by on the screen (Liktor & Dachsbacher 2011
    §4.3): ``hull`` (the convex hull of the beam's base and end vertices: the paper's 6-triangle
    volume), ``prism`` (touching planes through the base edges, capped by the ends' plane) or
    ``ernst`` (Ernst et al. 2005's prism as §4.3 gives it, capped parallel to the base). The image is
    the same; only the pixels tested differ (docs/benchmarks.md)."""
    shafts: bool = True
    """Add light shafts (single scattering in the water: along each photon's path, or through each
    beam by scan planes) to the camera image."""
    beam_soft_fade_m: float = field(default=0.0, metadata=_length())
    """Liktor & Dachsbacher (2011) §5.2's soft fade of a beam's shaft where it meets a receiver: a
    chord whose near face lies less than this far in front of the receiver the pixel sees is
    scaled by that distance over it (soft particles, Lorach 2007). It hides a rasteriser's clipping,
    which the exact scan-plane chords do not have, and removes light by design; 0 = off [m]."""
    eikonal_resolution: int = field(default=128, metadata=_range(8, 1024))
    """Nodes N per side of the ``eikonal`` grid over the water extent; the spacing L/N is also the
    layer spacing in depth [-]."""
    eikonal_threshold_depth_m: float | None = field(default=None, metadata=_length(positive=True))
    """Mercier (2013) §3.3's post-process, an aesthetic option: below this depth the ``eikonal``
    caustic texture is replaced by a wave simulation in the xy plane started from the layer at this
    depth, so the thin structures of the viscosity solution spread again; unset = off [m]."""
    eikonal_spread_deg: float = field(default=20.0, metadata=_range(1.0, 35.0))
    """Half-angle of the cones in which §3.3's wave spreads light below the threshold (the wave's
    speed per unit depth is its tangent; the leapfrog is stable up to 35.26°) [deg]."""
    wave3d_resolution: int = field(default=64, metadata=_range(8, 1024))
    """Nodes N per side of the ``wave3d`` grid over the water extent (also its layer spacing) [-]."""
    wave3d_cells_per_wavelength: float = field(default=8.0, metadata=_range(4.0, 1000.0))
    """The ``wave3d`` wave's wavelength λ in the water, in grid spacings: far longer than light's,
    so diffraction blurs the caustics over about √(λ·depth); at most a sixth of the patch [-]."""
    wave3d_periods: float = field(default=4.0, metadata=_range(0.5, 1000.0))
    """Periods of the drive over which u² is averaged into the ``wave3d`` intensity [-]."""
    wave3d_gain: float = field(default=1.0, metadata=_positive(1.0e6))
    """a of Mercier's post-process a·I^b of the ``wave3d`` intensity (1, 1: the intensity) [-]."""
    wave3d_exponent: float = field(default=1.0, metadata=_positive(10.0))
    """b of Mercier's post-process a·I^b [-]."""
    sunmap_halo_deg: float = field(default=5.3, metadata=_positive(180.0))
    """Angular diameter of the halo where the ``sunmap`` brightness falls to 0 (GPU Gems ch. 2: an
    arc about 10 times the disk's); it must exceed ``sun.angular_diameter_deg`` [deg]."""
    sunmap_variant: SunMapVariant = SunMapVariant.PER_VERTEX
    """``sunmap``: ``per_vertex`` (GPU Gems §2.3–2.4: a backward ray from each texel to the moving
    surface, Snell's law out, the sun map at the angle from the sun) or ``per_pixel`` (§2.5,
    Listings 2-1 and 2-2: the wave's gradient directly above the texel, the line along its normal
    to a plane at the water's depth, the light map read at that offset; no Snell's law)."""
