"""Floor caustics by flux ratio (``caustics.method = "fluxratio"``, host side): triangle fluxes, then
footprint deposits; with ``optics.scattering = "multiple"`` the random walk's map replaces it, with
``"small_angle"`` the scattered light of the small-angle transfer is added to it. The
approximate floor-map methods (sun map, eikonal, wave3d) build on :class:`FluxRatioStage`."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.caustics.multiple import MultipleScattering
from warpcaustics.caustics.sky_cones import SkyCones
from warpcaustics.caustics.small_angle import SmallAngleScattering
from warpcaustics.caustics.stage import CausticStage, Frame, Lighting, StageOutput
from warpcaustics.caustics.view import ViewCone
from warpcaustics.config import FloorShape, Scattering, SkyModel, SkySampling
from warpcaustics.kernels.caustics import coarse as coarse_kernels
from warpcaustics.kernels.caustics import coverage as cover_kernels
from warpcaustics.kernels.caustics import fluxratio as floor_kernels
from warpcaustics.optics.refraction import Refracted, refract_to_floor
from warpcaustics.scene.receivers import albedo_spectrum
from warpcaustics.water import Surface

SKY_GROUPS = ("sky_even", "sky")
"""The small-angle transfer's groups of the sky's even- and odd-numbered directions
(``sky.sampling = "halves"``; else all are ``sky``)."""

COARSE_FIELDS = ("coarse_floor_irradiance", "coarse_sky_floor_irradiance")
"""The whole patch's light on coarse texels beside a window (RenderResult), and its sky's part."""


def floor_bytes(n: int, m: int, k: int, groups: int) -> int:
    """Device memory of the refraction and floor stages [bytes]."""
    refraction = groups * n * n * (8 + 4 + 4) + n * n * 4  # hits, paths, T; sun visibility
    triangle_flux = (k + groups) * 2 * (n + 1) * (n + 1) * 4  # delivered per band; entering per group
    # the deposit's differences, the clipped footprints' texels, the band images; the rows' carry
    return refraction + triangle_flux + 3 * k * m * m * 4 + k * m * 8


COARSE_TEXELS_PER_WINDOW = 8
"""A window's side in coarse texels of the whole patch's map, where the surface's cells allow: the
small-angle transfer takes the scales above two coarse texels from the whole patch, those below
from the window."""

CELLS_PER_COARSE_TEXEL = 2
"""Surface cells a coarse texel spans at least (a power of two): each quad's light goes to the
coarse map as one point, so a texel must hold several, and a whole number of them keeps the map of
still water exactly uniform."""


def coarse_resolution(cfg, periodic: bool) -> int:
    """Coarse texels a side of the whole patch's map that the small-angle transfer of a floor-map
    window needs (0: none; the map is the whole patch, or the sea is not periodic): N / r for N cells
    a side, r the largest power of two with r cells within a window's 1/COARSE_TEXELS_PER_WINDOW,
    and at least CELLS_PER_COARSE_TEXEL."""
    side, _ = cfg.map_window
    extent = float(cfg.water.extent_m)
    if not periodic or side >= extent:
        return 0
    n = cfg.water.resolution
    cells = side / COARSE_TEXELS_PER_WINDOW / (extent / n)
    r = max(CELLS_PER_COARSE_TEXEL, 2 ** int(np.floor(np.log2(max(cells, 1.0)))))
    return max(1, n // r)


def sky_in_cones(cfg) -> bool:
    """A sky whose directions are spread over their cells (``sky.sampling = "cones"``); a radiance
    sensor (``floor.view_fov_deg``) traces the sky back instead."""
    return (cfg.sky.model is not SkyModel.NONE and cfg.sky.sampling is SkySampling.CONES
            and not cfg.floor.view_fov_deg)


def needs_coarse(cfg) -> bool:
    """Whether the floor stage keeps the whole patch's light on coarse texels beside a window: for the
    small-angle transfer, and for the sky's cells."""
    return cfg.optics.scattering is Scattering.SMALL_ANGLE or sky_in_cones(cfg)


def reached_runs(reach: np.ndarray, cells: int, quads: int) -> np.ndarray:
    """(R, 2) int32 (iy, first ix) of every row of every block of ``cells`` × ``cells`` quads that
    ``reach`` (blocks × blocks, non-zero: reached) marks, in row-major order of the quads (row by row,
    then the blocks along it), the rows cut at ``quads``."""
    rows, columns = np.nonzero(reach)
    runs = []
    for block_row in np.unique(rows):
        starts = columns[rows == block_row] * cells
        iy = block_row * cells + np.arange(min(cells, quads - block_row * cells))
        runs.append(np.stack(np.broadcast_arrays(iy[:, None], starts[None, :]), axis=-1).reshape(-1, 2))
    return np.concatenate(runs).astype(np.int32) if runs else np.zeros((0, 2), np.int32)


class FloorCaustics:
    """Owns the floor stage's device buffers, reused from frame to frame."""

    def __init__(self, n: int, map_resolution: int, sun_irradiance: np.ndarray,
                 attenuation_per_m: np.ndarray, device: str, *, periodic: bool = True,
                 window: tuple[float, tuple[float, float]] | None = None, groups: int = 1,
                 coarse_resolution: int = 0):
        """``window``: (side W [m], centre (x, y) [m]) of a floor-map window; None: the whole patch.
        ``groups``: refractive-index groups (K with dispersion, else 1). ``coarse_resolution`` > 0:
        also the whole periodic patch's light on that many coarse texels a side
        (:meth:`coarse_irradiance`), for the small-angle transfer's large scales."""
        k = len(sun_irradiance)
        m = map_resolution
        self.device = device
        self.sun_irradiance = wp.array(np.asarray(sun_irradiance, np.float32), dtype=wp.float32,
                                       device=device)
        self.attenuation_per_m = wp.array(np.asarray(attenuation_per_m, np.float32), dtype=wp.float32,
                                          device=device)
        quads = n if periodic else n + 1  # a walled surface also has quads reaching its walls
        self.flux = wp.empty((quads, quads, 2, k), dtype=wp.float32, device=device)
        """Flux per triangle and wavelength (Q, Q, 2, K) delivered to the floor [W nm^-1], Q quads per
        side."""
        self.entering = wp.empty((groups, quads, quads, 2), dtype=wp.float32, device=device)
        """Per index group and triangle (G, Q, Q, 2): the flux entering the water per unit irradiance,
        A⊥·mean T [m²]."""
        self.last_irradiance = self.sun_irradiance
        """The (K,) irradiance the last :meth:`run` used."""
        self.cover = wp.empty((m, m, k), dtype=wp.float32, device=device)
        """The deposit's differences along the map's rows (M, M, K) (``kernels/caustics/coverage.py``)."""
        self.carry = wp.empty((m, k), dtype=wp.float64, device=device)
        """Where each row's prefix sum starts (M, K): the cover carried over a periodic map's seam."""
        self.texels = wp.empty((m, m, k), dtype=wp.float32, device=device)
        """The small footprints' overlaps, clipped texel by texel (M, M, K)."""
        self.irradiance = wp.empty((k, m, m), dtype=wp.float32, device=device)
        """Floor spectral irradiance (K, M, M) [W m^-2 nm^-1]."""
        self.coarse_count = wp.zeros(1, dtype=wp.int32, device=device)
        """Footprints of the last run deposited by area samples (too large to clip texel by texel)."""
        self.window = window
        self.periodic = periodic
        cull = periodic and window is not None
        blocks = -(-n // cover_kernels.REACH_CELLS) if cull else 1
        self.reach_cells = cover_kernels.REACH_CELLS if cull else 0
        self.reach = wp.zeros((groups if cull else 1, blocks, blocks), dtype=wp.int32, device=device)
        """Per index group and block of REACH_CELLS² quads, 1 if its footprints may reach the window
        (a window of a periodic sea; else unused)."""
        self.coarse = None
        """(Mc, Mc, K) float64: the runs' flux [W nm⁻¹] at each quad's mean floor hit, on the whole
        patch's coarse texels (``kernels/caustics/coarse.py``), or None."""
        if coarse_resolution:
            if not periodic:
                raise ValueError("a coarse map of the whole patch needs a periodic sea")
            self.coarse = wp.zeros((coarse_resolution, coarse_resolution, k), dtype=wp.float64, device=device)

    def floor_map(self, extent_m: float) -> floor_kernels.FloorMap:
        """Where the M×M map lies: the whole patch of side ``extent_m``, or the window. On a
        periodic sea a window as wide as the patch wraps (it is the patch, shifted), and a window's
        centre is reduced to the period nearest the origin (float32 positions stay small)."""
        m = self.irradiance.shape[1]
        side, centre = (extent_m, (0.0, 0.0)) if self.window is None else self.window
        centre = np.asarray(centre, np.float64)
        if self.periodic:
            centre = centre - extent_m * np.round(centre / extent_m)
        fm = floor_kernels.FloorMap()
        fm.centre = wp.vec2(*centre.astype(np.float32))
        fm.origin = wp.vec2(*(centre - 0.5 * side).astype(np.float32))
        fm.scale = m / side
        whole = self.window is None or side >= extent_m
        fm.wrap = int(self.periodic and whole)
        fm.max_clipped = floor_kernels.MAX_CLIPPED_TEXELS if whole else m * m
        return fm

    def run(self, surface: Surface, refracted: Refracted, sun_dir: np.ndarray, *,
            clear: bool = True, irradiance: wp.array | None = None, bands: bool = True) -> wp.array3d:
        """Fill :attr:`irradiance`. On a periodic surface every triangle's flux lands on the floor,
        so per band ``sum(irradiance) * texel_area == sum(flux)`` to rounding; in a walled pool
        the flux that would land beyond the walls is not followed. ``clear = False`` adds to the
        last run's map (the directions of a sun disk, each with its share in ``sun_irradiance``);
        ``irradiance`` (K,) replaces ``sun_irradiance`` for this run (a direction of the sky).
        ``bands = False`` leaves :attr:`irradiance` as it was, for a run whose map a later one adds
        to (the prefix sums of the deposit's differences are taken once, when the map is read)."""
        quads = self.flux.shape[0]
        per_group = self.triangle_flux(surface, refracted, sun_dir, irradiance)
        if self.coarse is not None:
            if clear:
                self.coarse.zero_()
            wp.launch(coarse_kernels.splat_quads, dim=(refracted.hit_xy.shape[0], quads, quads),
                      inputs=[refracted.hit_xy, self.flux, per_group, float(surface.extent_m),
                              self.coarse.shape[0] / float(surface.extent_m)],
                      outputs=[self.coarse], device=self.device)
        return self.deposit(surface, refracted, clear=clear, bands=bands)

    def triangle_flux(self, surface: Surface, refracted: Refracted, sun_dir: np.ndarray,
                      irradiance: wp.array | None = None) -> int:
        """Each triangle's flux (:attr:`flux`, delivered; :attr:`entering`, into the water) from
        ``refracted``, with ``irradiance`` (K,) or the sun's; returns the bands per index group."""
        quads = self.flux.shape[0]
        self.last_irradiance = self.sun_irradiance if irradiance is None else irradiance
        if quads != (surface.resolution if surface.periodic else surface.resolution + 1):
            raise ValueError("FloorCaustics was built for the other kind of surface (periodic/walled)")
        per_group = self.sun_irradiance.shape[0] // refracted.hit_xy.shape[0]
        wp.launch(floor_kernels.triangle_flux, dim=(quads, quads),
                  inputs=[surface.positions, refracted.path_m, refracted.transmittance,
                          wp.vec3(*np.asarray(sun_dir, np.float32)),
                          self.last_irradiance,
                          self.attenuation_per_m, per_group, float(surface.extent_m),
                          int(surface.periodic)],
                  outputs=[self.flux, self.entering], device=self.device)
        return per_group

    def deposit(self, surface: Surface, refracted: Refracted, *, clear: bool = True,
                bands: bool = True) -> wp.array3d:
        """:meth:`run`'s deposit of the triangle fluxes it computed (:attr:`flux`) on the floor hits
        ``refracted``, and with ``bands`` the band images."""
        groups = refracted.hit_xy.shape[0]
        quads = self.flux.shape[0]
        k, m = self.irradiance.shape[0], self.irradiance.shape[1]
        floor_map = self.floor_map(float(surface.extent_m))
        if clear:
            self.cover.zero_()
            self.carry.zero_()
            self.texels.zero_()
            self.coarse_count.zero_()
        if self.reach_cells:  # the triangles of the blocks whose footprints may reach the window
            wp.launch(cover_kernels.block_reach, dim=self.reach.shape,
                      inputs=[refracted.hit_xy, self.reach_cells, float(surface.extent_m), floor_map],
                      outputs=[self.reach], device=self.device)
            reach, cells = self.reach.numpy(), self.reach_cells
        else:  # every triangle: one block of every quad
            reach, cells = np.ones((groups, 1, 1), np.int32), quads
        for g in range(groups):
            runs = reached_runs(reach[g], cells, quads)
            if len(runs):
                wp.launch(cover_kernels.deposit_footprints, dim=(len(runs), cells, 2),
                          inputs=[wp.array(runs, dtype=wp.vec2i, device=self.device), g, refracted.hit_xy,
                                  self.flux, k // groups, float(surface.extent_m), int(surface.periodic),
                                  floor_map],
                          outputs=[self.cover, self.carry, self.texels, self.coarse_count],
                          device=self.device)
        if bands:
            wp.launch(cover_kernels.cover_to_bands, dim=(m, k), inputs=[self.cover, self.carry, self.texels],
                      outputs=[self.irradiance], device=self.device)
        return self.irradiance

    def coarse_irradiance(self, extent_m: float) -> np.ndarray:
        """(K, Mc, Mc) the whole patch's irradiance on the coarse texels [W m⁻² nm⁻¹] since the last
        clearing run, texel (i, j) centred at −L/2 + (i + ½) L/Mc (L = ``extent_m``)."""
        mc = self.coarse.shape[0]
        return np.moveaxis(self.coarse.numpy(), -1, 0) * (mc / extent_m) ** 2

    def entering_flux(self) -> np.ndarray:
        """(K,) flux the last :meth:`run`'s triangles let into the water, before attenuation
        [W nm^-1] (float64 sums of the per-triangle A⊥·mean T)."""
        per_group = self.entering.numpy().sum(axis=(1, 2, 3), dtype=np.float64)
        e = self.last_irradiance.numpy().astype(np.float64)
        return e * np.repeat(per_group, len(e) // len(per_group))


class FluxRatioStage(CausticStage):
    """``fluxratio``: the floor map from each surface triangle's refracted footprint, one pass per
    direction of the sun's disk and of the sky; the random walk's map instead with
    ``optics.scattering = "multiple"``, or the map with the small-angle scattered light added with
    ``"small_angle"`` (either with the single-scattering map as its comparison)."""

    name = "fluxratio"

    def __init__(self, scene, water, light: Lighting, device: str):
        super().__init__(scene, water, light, device)
        cfg = scene.config
        n = scene.water_resolution
        self.floor_top_z = -cfg.floor.depth_m
        self.refracted = Refracted.allocate(len(light.group_ior), n, device)
        window = ((cfg.caustics.map_extent_m, tuple(cfg.caustics.map_center_m))
                  if cfg.caustics.map_extent_m else None)
        self.multiple = self.small_angle = None
        if cfg.optics.scattering is not Scattering.SINGLE:
            sky = {}
            if light.sky_directions is not None:
                sky = dict(sky_dirs=light.sky_directions, sky_irradiance=np.stack(light.sky_irradiance_np))
            floor_albedo = albedo_spectrum(cfg.floor.albedo, light.bins, cfg.floor.albedo_file,
                                           scene.base_dir, "floor")
            self.multiple = MultipleScattering(cfg, light.sun_directions, float(light.group_ior[0]),
                                               light.sun_irradiance, light.optics.absorption_per_m,
                                               light.optics.scattering_per_m, device,
                                               floor_albedo=floor_albedo, **sky)
        if cfg.optics.scattering is Scattering.SMALL_ANGLE:
            self.small_angle = SmallAngleScattering(cfg, float(light.group_ior[0]),
                                                    light.optics.absorption_per_m,
                                                    light.optics.scattering_per_m)
        self.view = ViewCone(cfg, light, scene.sun_direction, device) if cfg.floor.view_fov_deg else None
        self.cones = None
        if sky_in_cones(cfg):
            self.cones = SkyCones(cfg, light.sky_directions, scene.sun_direction, float(light.group_ior[0]))
        coarse = coarse_resolution(cfg, water.periodic) if needs_coarse(cfg) else 0
        disk_share = light.sun_irradiance / len(light.sun_directions)

        def floor(vertices: int) -> FloorCaustics:
            return FloorCaustics(vertices, cfg.caustics.map_resolution, disk_share, light.attenuation_per_m,
                                 device, periodic=water.periodic, window=window,
                                 groups=len(light.group_ior), coarse_resolution=coarse)

        self.floor = floor(n)
        # the sky's passes on a surface of their own (``sky.surface_resolution``), with its buffers
        ns = scene.sky_resolution
        groups = len(light.group_ior)
        self.sky_refracted = self.refracted if ns == n else Refracted.allocate(groups, ns, device)
        self.sky_floor = self.floor if ns == n else floor(ns)

    @classmethod
    def bytes_needed(cls, scene, k: int, groups: int) -> int:
        cfg = scene.config
        m = cfg.caustics.map_resolution
        walk = k * m * m * 4 if cfg.optics.scattering is not Scattering.SINGLE else 0  # the walk's texels
        coarse = k * coarse_resolution(cfg, cfg.water.periodic) ** 2 * 8 if needs_coarse(cfg) else 0
        n, ns = scene.water_resolution, scene.sky_resolution
        sky = floor_bytes(ns, m, k, groups) + coarse if ns != n else 0  # the sky's surface's own buffers
        view = k * m * m * 4 if cfg.floor.view_fov_deg else 0  # a radiance sensor's traced sky
        return floor_bytes(n, m, k, groups) + walk + coarse + sky + view

    def render(self, frame: Frame) -> StageOutput:
        floor, transmitted, extra, single = self.flux_ratio(frame)
        if single is None:
            return StageOutput(floor, transmitted, self.name, extra)
        return StageOutput(floor, transmitted, self.scene.config.optics.scattering.value, extra,
                           comparison=StageOutput(single[0], single[1], "single", single[2]))

    def flux_ratio(self, frame: Frame) -> tuple[np.ndarray, np.ndarray, dict, tuple | None]:
        """(floor map, flux entering the water, RenderResult fields, the single-scattering (map,
        entering flux, fields) the random walk replaced or None)."""
        watch = frame.watch
        extra = {}
        # A sun disk: one refraction and deposit per direction over it, each with an equal share of
        # the flux (the deposit's irradiance was divided by their number); crests shade by the
        # disk's centre.
        flux = 0.0  # (2, K): entering the water, delivered to the floor
        last = len(self.light.sun_directions) - 1
        for i, direction in enumerate(self.light.sun_directions):
            floor, pass_flux = self._deposit(frame, frame.visible, direction,
                                             ("refraction", "floor_caustics"), clear=i == 0, bands=i == last)
            flux = flux + pass_flux
        with watch.stage("readback"):
            # .copy(): on the CPU device .numpy() is a view of a buffer the next frame reuses.
            floor_np = floor.numpy().copy()
        coarse = self._coarse(self.floor, frame)  # the sun's, on the whole patch beside a window
        if self.small_angle is not None:
            self.small_angle.reset(frame.surface.positions.numpy()[..., 2])
            with watch.stage("small_angle"):  # the disk's directions share one transfer, its centre's
                centre = np.mean(self.light.sun_directions, axis=0)
                self.small_angle.add(floor_np, centre / np.linalg.norm(centre), flux[1], coarse=coarse)
        single_sky = coarse_sky = None
        if self.view is not None and self.light.sky_directions is not None:
            with watch.stage("sky"):  # traced back from the texels through the sensor's cone
                sky_np = self.view.sky(frame.surface)
            extra["sky_floor_irradiance"] = sky_np
            floor_np = floor_np + sky_np
        elif self.light.sky_directions is not None:
            sky_np, sky_flux, even, coarse_sky = self._sky(frame)
            extra["sky_floor_irradiance"] = single_sky = sky_np
            extra["sky_floor_irradiance_even"] = single_even = even
            floor_np, flux = floor_np + sky_np, flux + sky_flux
        if coarse is not None:
            extra["coarse_floor_irradiance"] = coarse if coarse_sky is None else coarse + coarse_sky
            extra["coarse_sky_floor_irradiance"] = coarse_sky
        transmitted = flux[0]
        # a radiance sensor's map sums L dω over its cone, not a flux: no delivered flux
        extra["delivered_flux_w_nm"] = None if self.view is not None else flux[1]
        if self.multiple is None:
            return floor_np, transmitted, extra, None
        # the walk's maps replace the single-scattering ones
        single = (floor_np, transmitted, {"delivered_flux_w_nm": extra.pop("delivered_flux_w_nm")})
        single_coarse = tuple(extra.pop(key, None) for key in COARSE_FIELDS)
        with watch.stage("multiple_scattering"):
            floor_np, walk = self.multiple.run(frame.surface, frame.visible)
            transmitted = np.asarray(walk["transmitted"])
        if self.light.sky_directions is not None:
            if self.scene.config.sky.sampling is SkySampling.HALVES:  # this frame's directions
                self.multiple.set_sky(self.light.sky_directions, np.stack(self.light.sky_irradiance_np))
            with watch.stage("sky"):
                sky_np, walk["sky"] = self.multiple.run_sky(frame.for_sky().surface, self.light.sky_visible)
            extra["sky_floor_irradiance"] = sky_np
            extra["sky_floor_irradiance_even"] = None  # the walk's sky is one estimate
            floor_np = floor_np + sky_np
            transmitted = transmitted + np.asarray(walk["sky"]["transmitted"])
        extra["multiple_scattering_stats"] = walk
        if self.small_angle is not None:  # the single-scattering map and its scattered light
            floor_flux = np.asarray(walk["floor"])
            if "sky" in walk:
                floor_flux = floor_flux + np.asarray(walk["sky"]["floor"])
            with watch.stage("small_angle"):
                scattered, walk["small_angle"] = self.small_angle.finish(floor_flux)
            floor_np = single[0] + sum(scattered.values())
            extra.update(self._coarse_scattered(*single_coarse))
            if single_sky is not None:
                sky_scattered = [scattered[g] for g in SKY_GROUPS if g in scattered]
                extra["sky_floor_irradiance"] = single_sky + sum(sky_scattered)
                if single_even is not None:
                    extra["sky_floor_irradiance_even"] = single_even + scattered[SKY_GROUPS[0]]
        return floor_np, transmitted, extra, single

    def _coarse_scattered(self, whole: np.ndarray | None, sky: np.ndarray | None) -> dict:
        """The coarse maps of the whole patch (:attr:`RenderResult.coarse_floor_irradiance`, its sky's
        part) with the small-angle transfer's scattered light added, as the window's map has it; {}
        without them."""
        if whole is None:
            return {}
        parts = self.small_angle.scattered_coarse
        out = {"coarse_floor_irradiance": whole + sum(parts.values())}
        if sky is not None:
            out["coarse_sky_floor_irradiance"] = sky + sum(parts[g] for g in SKY_GROUPS if g in parts)
        return out

    def _sky(self, frame: Frame) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        """The sky's floor map, (2, K) flux (entering, delivered), with ``sky.sampling = "halves"``
        the map of its even-numbered directions alone (else None), and beside a window of a periodic
        sea the whole patch's sky on coarse texels (else None): one shaded refraction
        and deposit per sky direction, each with its share of the sky's irradiance (with halves,
        the even-numbered ones first). With the small-angle transfer each direction's map is read
        back and given its own transfer (its own path), its scattered light reported by half; with
        ``sky.sampling = "cones"`` it is read back and spread over its cell of the sky first."""
        light = self.light
        sky = frame.for_sky()  # the surface its passes take (sky.surface_resolution)
        transmitted = 0.0
        total = even = total_coarse = None
        separate = self.small_angle is not None or self.cones is not None
        count = len(light.sky_directions)
        halves = self.scene.config.sky.sampling is SkySampling.HALVES
        order = [*range(0, count, 2), *range(1, count, 2)] if halves else range(count)
        for n, i in enumerate(order):
            direction, irradiance = light.sky_directions[i], light.sky_irradiance_per_dir[i]
            with frame.watch.stage("sky"):
                out = light.sky_visible[i] if light.sky_visible.ndim == 3 else light.sky_visible
                visible = sky.shade(direction, self.device, out)
            read = separate or n == count - 1 or (halves and n == count // 2 - 1)  # this map is read next
            floor, flux = self._deposit(sky, visible, direction, ("sky", "sky"), clear=n == 0 or separate,
                                        irradiance=irradiance, bands=read, sky=True)
            transmitted = transmitted + flux
            if separate:
                one, coarse = floor.numpy().copy(), self._coarse(self.sky_floor, frame)
                if self.cones is not None:
                    with frame.watch.stage("sky_cones"):
                        one, coarse = self.cones.spread(i, one, coarse)
                total = one if total is None else total + one
                if coarse is not None:
                    total_coarse = coarse if total_coarse is None else total_coarse + coarse
                if self.small_angle is not None:
                    with frame.watch.stage("small_angle"):
                        group = SKY_GROUPS[i % 2] if halves else "sky"
                        self.small_angle.add(one, direction, flux[1], group=group, coarse=coarse)
            if halves and n == count // 2 - 1:  # the last of the even-numbered directions
                even = total.copy() if separate else floor.numpy().copy()
        if not separate:
            total_coarse = self._coarse(self.sky_floor, frame)
        return (floor.numpy().copy() if total is None else total), transmitted, even, total_coarse

    def _coarse(self, floor: FloorCaustics, frame: Frame) -> np.ndarray | None:
        """The whole patch's light on ``floor``'s coarse texels since its last clearing pass
        (K, Mc, Mc), or None where the map is the whole patch."""
        if floor.coarse is None:
            return None
        return floor.coarse_irradiance(float(frame.surface.extent_m))

    def _deposit(self, frame: Frame, visible, direction, stages: tuple[str, str], *, clear: bool,
                 irradiance: wp.array | None = None, bands: bool = True,
                 sky: bool = False) -> tuple[wp.array3d, np.ndarray]:
        """One flux-ratio pass for light arriving from ``direction`` (the sun's centre, a point of
        its disk or of the sky): refraction through ``frame``'s surface, then the deposit added to
        the map unless ``clear``; returns the map and the pass's (2, K) flux per band entering the
        water and delivered to the floor [W nm^-1] (host read-backs; a device-side sum would spare
        them on CUDA). ``sky``: the sky surface's buffers (the sun's otherwise; the same where the
        sky takes the water's surface)."""
        out, floor_caustics = (self.sky_refracted, self.sky_floor) if sky else (self.refracted, self.floor)
        with frame.watch.stage(stages[0]):
            refracted = refract_to_floor(frame.surface, visible, self.light.group_ior, direction,
                                         -self.scene.config.floor.depth_m, self.device, out=out)
            entering = None
            if self.view is not None:  # the light entering the water, then only what reaches the cone
                floor_caustics.triangle_flux(frame.surface, refracted, direction, irradiance)
                entering = floor_caustics.entering_flux()
                self.view.weight(frame.surface, refracted, -self.scene.config.floor.depth_m)
        with frame.watch.stage(stages[1]):
            floor = floor_caustics.run(frame.surface, refracted, direction, clear=clear,
                                       irradiance=irradiance, bands=bands)
            flux = np.stack([floor_caustics.entering_flux() if entering is None else entering,
                             floor_caustics.flux.numpy().sum(axis=(0, 1, 2), dtype=np.float64)])
        return floor, flux


class ApproximateStage(FluxRatioStage):
    """A floor-map method of its own (sun map, eikonal, wave3d) on top of the flux ratio: the flux-
    ratio map of the same frame sets its scale and is saved beside it as its comparison."""

    def __init__(self, scene, water, light: Lighting, device: str):
        super().__init__(scene, water, light, device)
        # grey, one index for their rays (the bins' mean)
        self.approximate = self.make(float(np.mean(light.ior)))

    def make(self, mean_ior: float):
        """The method's own floor-map object (with ``floor_map(...)``), its rays refracted with
        ``mean_ior``."""
        raise NotImplementedError

    def sky_map(self, frame: Frame, flux_ratio: np.ndarray) -> np.ndarray | None:
        """The sky's floor map by the method itself, solved before the sun's (None: none)."""
        return None

    def finish(self, floor: np.ndarray) -> np.ndarray:
        """The sun's map after its solve (e.g. averaged over the sun's disk)."""
        return floor

    def render(self, frame: Frame) -> StageOutput:
        flux_ratio, transmitted, fields, _ = self.flux_ratio(frame)
        method_sky = self.sky_map(frame, flux_ratio)
        with frame.watch.stage(self.name):
            floor, extra = self.approximate.floor_map(frame.surface, self.water, frame.time_s, frame.highest,
                                                      frame.visible, flux_ratio)
            floor = self.finish(floor)
        if method_sky is not None:
            extra["sky_floor_irradiance"] = method_sky
            floor = floor + method_sky
        comparison = None  # the flux-ratio map is a flat floor's: no comparison on a relief (eikonal, wave3d)
        if self.scene.config.floor.shape is FloorShape.FLAT:
            comparison = StageOutput(flux_ratio, transmitted, FluxRatioStage.name,
                                     {"delivered_flux_w_nm": fields["delivered_flux_w_nm"]})
        return StageOutput(floor, transmitted, self.name, extra, comparison=comparison)
