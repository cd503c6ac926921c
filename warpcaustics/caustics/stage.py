"""The interface every caustic method implements, and what the renderer hands it.

A method is a :class:`CausticStage` subclass registered by its ``caustics.method`` name in
:mod:`warpcaustics.caustics.registry`. The :class:`~warpcaustics.pipeline.Renderer` builds it once
per scene (``__init__``: allocate its buffers), then for every frame calls :meth:`CausticStage.check_frame`
and :meth:`CausticStage.render` with the frame's water surface; it never branches on the method.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import warp as wp

from warpcaustics.config import SkyModel
from warpcaustics.optics import spectra
from warpcaustics.optics.refraction import sun_visibility


class Stopwatch:
    """Wall time of each stage of a frame [s], the device synchronised at the end of each."""

    def __init__(self, device: str):
        self.device = device
        self.timings: dict[str, float] = {}

    def stage(self, name: str):
        watch = self

        class _Stage:
            def __enter__(self):
                self.t0 = time.perf_counter()

            def __exit__(self, *exc):
                wp.synchronize_device(watch.device)
                # a stage run several times in a frame (per sun-disk direction) adds up
                watch.timings[name] = watch.timings.get(name, 0.0) + time.perf_counter() - self.t0

        return _Stage()


@dataclass
class Lighting:
    """The light of a scene and the water's optics on the render's spectral bins, prepared once."""

    bins: spectra.SpectralBins
    sun_irradiance: np.ndarray
    """(K,) solar spectral irradiance on a plane perpendicular to the beam [W m^-2 nm^-1]."""
    optics: spectra.WaterOptics
    ior: np.ndarray
    """(K,) refractive index n(λ)."""
    group_ior: np.ndarray
    """One index per refraction: (K,) with dispersion, else the first bin's alone."""
    sun_directions: np.ndarray
    """(D, 3) unit vectors towards the points of the sun's disk (the centre alone for a point sun)."""
    sky_directions: np.ndarray | None = None
    """(S, 3) unit vectors towards the sky's directions; None without a sky."""
    sky_irradiance_horizontal: np.ndarray | None = None
    """(K,) the sky's horizontal spectral irradiance [W m⁻² nm⁻¹]."""
    sky_irradiance_np: list[np.ndarray] = field(default_factory=list)
    """Per sky direction: its irradiance on a plane perpendicular to it (K,)."""
    sky_irradiance_per_dir: list = field(default_factory=list)
    """The same as device arrays."""
    sky_visible: wp.array | None = None
    """The crests' shading from each sky direction: one (N, N) buffer reused, or (S, N, N), N the sky's
    surface's (:attr:`~warpcaustics.scene.Scene.sky_resolution`)."""

    @property
    def attenuation_per_m(self) -> np.ndarray:
        return self.optics.attenuation_per_m

    @classmethod
    def prepare(cls, scene, device: str, *, keep_sky_shading: bool) -> Lighting:
        """The scene's sun, sky and water optics; ``keep_sky_shading``: one shading buffer per sky
        direction instead of one reused (methods that revisit the directions)."""
        cfg = scene.config
        bins = spectra.bins_for(cfg.optics)
        sun = spectra.sun_irradiance(bins, cfg.sun, scene.base_dir)
        ior = spectra.refractive_index(cfg.optics, bins)
        light = cls(bins=bins, sun_irradiance=sun, optics=spectra.water_optics(cfg.optics, bins), ior=ior,
                    group_ior=ior if cfg.optics.dispersion else ior[:1],
                    sun_directions=scene.sun_disk_directions())
        if cfg.sky.model is not SkyModel.NONE:
            light.sky_irradiance_horizontal = scene.sky_irradiance(sun)
            light.set_sky(*scene.sky_directions(), device)
            n = scene.sky_resolution
            shape = (len(light.sky_directions), n, n) if keep_sky_shading else (n, n)
            light.sky_visible = wp.empty(shape, dtype=wp.float32, device=device)
        return light

    def set_sky(self, directions: np.ndarray, shares: np.ndarray, device: str) -> None:
        """The sky's directions (S, 3) and each one's share of its horizontal irradiance (S,)."""
        self.sky_directions = directions
        self.sky_irradiance_np = [self.sky_irradiance_horizontal * w for w in shares]
        self.sky_irradiance_per_dir = [wp.array(e.astype(np.float32), dtype=wp.float32, device=device)
                                       for e in self.sky_irradiance_np]

    def draw_sky(self, scene, time_s: float, device: str) -> None:
        """``sky.sampling = "halves"``: this frame's directions, two randomly turned and offset
        halves (:meth:`~warpcaustics.scene.Scene.sky_directions`), drawn from ``water.seed`` and the
        frame's time, so a frame's directions are the same in every run."""
        rng = np.random.default_rng([scene.config.water.seed, int(round(time_s * 1e6)) % 2**63])
        self.set_sky(*scene.sky_directions(rng), device)

    def passes(self) -> list[tuple[np.ndarray, np.ndarray, bool]]:
        """Light passes: (direction (3,), irradiance (K,) on a plane perpendicular to it, from the
        sky). One per direction of the sun's disk with its share of the sun, and one per sky
        direction with its share of the sky."""
        dirs = self.sun_directions
        out = [(d, self.sun_irradiance / len(dirs), False) for d in dirs]
        if self.sky_directions is not None:
            out += [(d, e, True) for d, e in zip(self.sky_directions, self.sky_irradiance_np)]
        return out


def sky_bytes(cfg, n: int, keep_sky_shading: bool) -> int:
    """Device memory of the sky's shading buffers [bytes]."""
    if cfg.sky.model is SkyModel.NONE:
        return 0
    return n * n * 4 * (cfg.sky.directions if keep_sky_shading else 1)


@dataclass
class Frame:
    """What a method gets for one frame: the water surface and the sun's shading of it."""

    surface: object
    """The water's :class:`~warpcaustics.water.Surface` at ``time_s`` (device arrays)."""
    visible: wp.array2d
    """(N, N) share of each vertex lit by the sun's centre (crests shade the troughs)."""
    time_s: float
    lowest: float
    """Lowest and highest surface heights [m]."""
    highest: float
    watch: Stopwatch
    height_blocks: tuple | None = None
    """A walled surface's :func:`~warpcaustics.optics.refraction.height_blocks`, built once for the
    frame's light directions (None: each shading pass builds its own, if it marches)."""
    horizon: wp.array2d | None = None
    """A periodic surface's :func:`~warpcaustics.optics.refraction.horizon_buffer`, which every
    light direction's sweep reuses (None: each allocates its own)."""
    sky: Frame | None = None
    """The frame of the surface the sky's directions are refracted through where it is not this one
    (``sky.surface_resolution``: the same waves cut to a coarser grid; its ``visible`` is None)."""

    def for_sky(self) -> Frame:
        """The frame the sky's passes take: :attr:`sky`, or this one."""
        return self.sky or self

    def shade(self, direction: np.ndarray, device: str, out: wp.array2d) -> wp.array2d:
        """(N, N) the crests' shading of this frame's surface from ``direction`` (towards the light)
        into ``out``, with the frame's height range and shading aids."""
        return sun_visibility(self.surface, direction, self.highest, device, out=out,
                              blocks=self.height_blocks, lowest_m=self.lowest, horizon=self.horizon)


@dataclass
class StageOutput:
    """What a method returns for one frame, on the host; the renderer adds the common fields."""

    floor: np.ndarray
    """(K, M, M) floor irradiance [W m^-2 nm^-1]."""
    transmitted: np.ndarray
    """(K,) flux that enters the water through the surface, before attenuation [W nm^-1]."""
    method: str
    """The name that made :attr:`floor` (``RenderResult.method``)."""
    extra: dict = field(default_factory=dict)
    """Further :class:`~warpcaustics.pipeline.RenderResult` fields (receivers, camera, statistics)."""
    comparison: StageOutput | None = None
    """A second map of the same frame saved beside it (``RenderResult.comparison``)."""


class CausticStage:
    """One caustic method: built once per scene, then rendering one frame at a time.

    Subclasses set :attr:`name` and implement :meth:`render` and :meth:`bytes_needed`.
    """

    name: ClassVar[str] = ""
    keeps_sky_shading: ClassVar[bool] = False
    """Whether the crests' shading from each sky direction is kept, (S, N, N), for the method to
    revisit the directions, rather than one (N, N) buffer reused."""
    memory_key: ClassVar[str | None] = None
    """The config key to lower first when the scene does not fit (None: the usual ones)."""

    floor_top_z: float
    """Highest point of the floor [m]: the surface must stay above it."""

    def __init__(self, scene, water, light: Lighting, device: str):
        self.scene = scene
        self.water = water
        self.light = light
        self.device = device

    @classmethod
    def bytes_needed(cls, scene, k: int, groups: int) -> int:
        """Device memory the method needs for one frame of ``scene`` with K bins and ``groups``
        refractive-index groups [bytes] (the water and the sky are counted by the renderer)."""
        raise NotImplementedError

    def check_frame(self, frame: Frame) -> None:
        """Refuse a frame the method cannot render (raise :class:`WarpcausticsError`)."""

    def render(self, frame: Frame) -> StageOutput:
        """The floor map of one frame and what else the method reports (receivers, camera, statistics)."""
        raise NotImplementedError
