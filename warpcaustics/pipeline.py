"""One frame end to end: water → refraction → floor caustics → a RenderResult."""

from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import warp as wp

from warpcaustics import device as devices
from warpcaustics.caustics import beams, photons
from warpcaustics.caustics import fluxratio as caustics
from warpcaustics.caustics.eikonal import EikonalCaustics, GridCaustics, eikonal_bytes
from warpcaustics.caustics.multiple import MultipleScattering
from warpcaustics.caustics.sunmap import SunMapCaustics
from warpcaustics.caustics.wave3d import Wave3DCaustics, wave3d_bytes
from warpcaustics.config import CausticsMethod, Scattering, SkyModel
from warpcaustics.errors import WarpcausticsError
from warpcaustics.optics import spectra
from warpcaustics.optics.phase import PhaseFunction
from warpcaustics.optics.refraction import Refracted, height_range, refract_to_floor, sun_visibility
from warpcaustics.scene import Scene
from warpcaustics.scene.camera import UnderwaterCamera, camera_bytes
from warpcaustics.scene.receivers import WALL_FACES, Receivers
from warpcaustics.water import make_water, water_bytes


@dataclass
class RenderResult:
    """A rendered frame, as numpy arrays on the host."""

    scene: Scene
    time_s: float
    device: str
    wavelengths_nm: np.ndarray
    """(K,) bin centres [nm]."""
    bin_widths_nm: np.ndarray
    """(K,) bin widths [nm]."""
    floor_irradiance: np.ndarray
    """(K, M, M) spectral irradiance on the floor [W m^-2 nm^-1]; row index along +y, texel
    centres at ``(i + 0.5) L/M - L/2`` (with a floor-map window, :meth:`map_coordinates`)."""
    attenuation_per_m: np.ndarray
    """(K,) beam attenuation c(λ) = a + b used [1/m]."""
    ior: np.ndarray
    """(K,) refractive index n(λ) used."""
    sun_irradiance: np.ndarray
    """(K,) solar spectral irradiance on a plane perpendicular to the beam [W m^-2 nm^-1]."""
    transmitted_flux_w_nm: np.ndarray
    """(K,) flux that enters the water [W nm^-1]: ``fluxratio`` counts it after attenuation on the
    way to the floor, ``photons`` and ``beams`` at the surface (before attenuation)."""
    surface_positions: np.ndarray
    """(N, N, 3) water surface vertices [m]."""
    surface_normals: np.ndarray
    """(N, N, 3) unit surface normals."""
    bins: spectra.SpectralBins | None = None
    """The spectral bins (edges, and the listed wavelengths when point-sampled)."""
    fold_fraction: float = 0.0
    """Fraction of surface vertices where choppy displacement folds the surface (Jacobian ≤ 0)."""
    timings_s: dict[str, float] = field(default_factory=dict)
    """Wall time of each stage [s] (device synchronised)."""
    face_flux_w_nm: np.ndarray | None = None
    """``photons``, ``beams``: (F, K) flux on each receiver face that is not floor [W nm^-1], faces
    ordered walls, then ``receivers[i]`` (see :attr:`face_receiver`)."""
    face_receiver: np.ndarray | None = None
    """``photons``, ``beams``: (F,) receiver id of each of those faces (1 = walls, 2 + i =
    ``receivers[i]``)."""
    face_area_m2: np.ndarray | None = None
    """``photons``, ``beams``: (F,) area of each of those faces [m²]."""
    face_centres_m: np.ndarray | None = None
    """``photons``, ``beams``: (F, 3) centroid of each of those faces [m]."""
    floor_texel_area_m2: np.ndarray | None = None
    """``photons``, ``beams``: (M, M) true area of the floor over each texel [m²] (None: flat, (L/M)²)."""
    receiver_mesh: tuple[np.ndarray, np.ndarray] | None = None
    """``photons``, ``beams``: (points (V, 3) [m], triangles (F, 3)) of the receivers other than the
    floor, the faces in the order of :attr:`face_flux_w_nm`."""
    photon_stats: dict[str, int] | None = None
    """``photons``: photons emitted, carrying flux, and landed on a receiver, added up over the
    frame's light passes (one per direction of the sun's disk and of the sky)."""
    beam_stats: dict[str, int] | None = None
    """``beams``: beams built, carrying flux, dropped, and tile-list entries, added up over the
    frame's light passes."""
    method: str = "fluxratio"
    """The caustics method that made :attr:`floor_irradiance` (``beams`` for ``both``)."""
    comparison: RenderResult | None = None
    """``both``: the photon method's result of the same frame (this result is the beams');
    ``sunmap``, ``eikonal``, ``wave3d``: the flux-ratio map of the same frame. Saved beside it with
    the difference of the floor maps."""
    sunmap_brightness: np.ndarray | None = None
    """``sunmap``: (M, M) grey sun-map brightness 0…1 before scaling to the flux-ratio mean."""
    eikonal_stats: dict[str, int] | None = None
    """``eikonal``: layers of the grid and Jacobi passes of the relaxation."""
    wave3d_stats: dict[str, int] | None = None
    """``wave3d``: layers of the grid, steps, averaged steps and node updates."""
    multiple_scattering_stats: dict | None = None
    """``optics.scattering = "multiple"``: photons walked and, per band, where their flux went
    (transmitted, floor, escaped, absorbed, unscattered, truncated) [W nm⁻¹]."""
    sky_floor_irradiance: np.ndarray | None = None
    """With a sky (``sky.model``): (K, M, M) the sky's part of :attr:`floor_irradiance`
    [W m⁻² nm⁻¹]; the direct sun's is the rest."""
    camera_radiance: np.ndarray | None = None
    """(K, H, W) spectral radiance reaching the camera [W m^-2 sr^-1 nm^-1], image row 0 at the top."""
    camera_gbuffer: dict[str, np.ndarray] | None = None
    """Per camera pixel: ``position`` (H, W, 3) [m], ``normal`` (H, W, 3), ``depth`` (H, W) [m] along
    the ray (inf: no receiver), ``receiver`` (H, W) id (−1: none)."""

    def water_iops(self) -> dict:
        """The water's absorption ``a``, scattering ``b`` and beam attenuation ``c`` [1/m] used by
        this render, as ``colour.SpectralDistribution``s on its wavelengths."""
        optics = spectra.water_optics(self.scene.config.optics, self.bins)
        return optics.distributions(self.bins)

    def receiver_irradiance(self, receiver: int) -> np.ndarray:
        """(F_r, K) irradiance on the faces of receiver id ``receiver`` [W m^-2 nm^-1]."""
        if self.face_flux_w_nm is None:
            raise ValueError("receiver irradiance needs caustics.method = 'photons' or 'beams'")
        sel = self.face_receiver == receiver
        return self.face_flux_w_nm[sel] / self.face_area_m2[sel, None]

    @property
    def extent_m(self) -> float:
        return self.scene.config.water.extent_m

    @property
    def map_extent_m(self) -> float:
        """Side of the floor map [m]: the water extent, or ``caustics.map_extent_m``'s window."""
        return self.scene.config.map_window[0]

    @property
    def map_center_m(self) -> tuple[float, float]:
        """Centre of the floor map [m]."""
        return self.scene.config.map_window[1]

    @property
    def map_periodic(self) -> bool:
        """Whether the floor map tiles (the whole patch of a periodic sea, or a window as wide)."""
        c = self.scene.config
        side = c.caustics.map_extent_m
        return c.water.periodic and (not side or side >= c.water.extent_m)

    def map_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) [m] of the texel centres of the floor map (row index along +y)."""
        m = self.floor_irradiance.shape[-1]
        side = self.map_extent_m
        offsets = (np.arange(m) + 0.5) * side / m - 0.5 * side
        cx, cy = self.map_center_m
        return cx + offsets, cy + offsets

    @property
    def texel_area_m2(self) -> float:
        return (self.map_extent_m / self.floor_irradiance.shape[-1]) ** 2

    @property
    def floor_flux_w_nm(self) -> np.ndarray:
        """(K,) total flux on the floor [W nm^-1], summed in float64 over each texel's true floor
        area (a relief's area exceeds the texel's horizontal area)."""
        if self.floor_texel_area_m2 is not None:
            return np.einsum("kij,ij->k", self.floor_irradiance.astype(np.float64), self.floor_texel_area_m2)
        return self.floor_irradiance.sum(axis=(1, 2), dtype=np.float64) * self.texel_area_m2

    def save(self, out_dir: str | Path, *, frame: int = 0) -> dict[str, Path]:
        """Write ``frame_NNNN.exr``, ``frame_NNNN.png`` and then ``run.json`` into out_dir.

        Each file is written to a temporary name and renamed; run.json comes last.
        """
        from warpcaustics.io.output import save_frame, write_run_json

        paths = save_frame(self, Path(out_dir), frame=frame)
        paths["json"] = write_run_json(Path(out_dir), [self])
        return paths


class _Stopwatch:
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


def keeps_sky_shading(cfg) -> bool:
    """Whether the crests' shading from each sky direction is kept, (D, N, N), rather than one
    (N, N) buffer reused per direction: the random walk takes the directions in turn, and the
    eikonal and wave grids solve per direction with the shading the flux ratio's sky pass made."""
    return (cfg.optics.scattering is Scattering.MULTIPLE
            or cfg.caustics.method in (CausticsMethod.EIKONAL, CausticsMethod.WAVE3D))


def scene_bytes(scene: Scene) -> int:
    """Device memory one frame of this scene needs [bytes]."""
    cfg = scene.config
    n = scene.water_resolution
    k = len(spectra.bins_for(cfg.optics).centres_nm)
    groups = k if cfg.optics.dispersion else 1
    sky = 0
    if cfg.sky.model is not SkyModel.NONE:  # its shading buffer: one, or one per direction
        sky = n * n * 4 * (cfg.sky.directions if keeps_sky_shading(cfg) else 1)
    if cfg.caustics.method.uses_receivers:
        periodic = cfg.water.periodic
        faces = receiver_face_estimate(scene, periodic)
        cam = camera_bytes(cfg.camera, k) if cfg.camera.enabled else 0
        stage = 0
        if cfg.caustics.method in (CausticsMethod.BEAMS, CausticsMethod.BOTH):
            walls = WALL_FACES if cfg.water.walled else 0
            sampled = sum(len(m.triangles) for m in scene.receiver_meshes) + walls
            stage += beams.beams_bytes(cfg, n, k, groups, periodic, faces, sampled)
        if cfg.caustics.method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH):
            stage += photons.photons_bytes(cfg, n, k, groups, periodic, faces)
        return water_bytes(cfg, n) + stage + cam + sky
    m = cfg.caustics.map_resolution
    extra = {CausticsMethod.SUNMAP: m * m * 4, CausticsMethod.EIKONAL: eikonal_bytes(cfg) + k * m * m * 4,
             CausticsMethod.WAVE3D: wave3d_bytes(cfg) + k * m * m * 4}
    walk = k * m * m * 4 if cfg.optics.scattering is Scattering.MULTIPLE else 0  # the walk's texels
    return (water_bytes(cfg, n) + caustics.floor_bytes(n, m, k, groups) + sky + walk
            + extra.get(cfg.caustics.method, 0))


def check_camera_position(cfg, floor_relief: np.ndarray | None, periodic: bool) -> None:
    """The camera must be in the water: over a non-periodic patch (inside a pool's walls) and above
    the floor."""
    from warpcaustics.errors import ConfigError
    from warpcaustics.scene.receivers import floor_relief_height

    x, y, z = cfg.camera.position_m
    half = 0.5 * cfg.water.extent_m
    if not periodic and max(abs(x), abs(y)) >= half:
        where = "the pool's walls" if cfg.water.walled else f"the {cfg.water.model.value!r} water patch"
        raise ConfigError(f"camera.position_m = {list(cfg.camera.position_m)} is outside {where} "
                          f"(|x|, |y| < {half:g} m); move the camera into the water")
    floor_z = float(floor_relief_height(cfg.floor, floor_relief, cfg.water.extent_m, np.array(x),
                                        np.array(y)))
    if z <= floor_z:
        raise ConfigError(f"camera.position_m = {list(cfg.camera.position_m)} is below the floor (z = "
                          f"{floor_z:.3f} m there); move the camera up into the water")


def receiver_face_estimate(scene: Scene, periodic: bool) -> int:
    """Faces of the receivers' BVH (the floor grid with its margin, walls, meshes)."""
    from warpcaustics.scene.receivers import floor_mesh_cells

    cfg = scene.config
    cells = floor_mesh_cells(cfg)
    floor = 2 * int(cells * (1.5 if periodic else 1.0)) ** 2
    walls = WALL_FACES if cfg.water.walled else 0
    return floor + sum(len(m.triangles) for m in scene.receiver_meshes) + walls


class Renderer:
    """Renders frames of one scene on one device; holds the water model and spectral tables.

    Use one Renderer for an animation so the ocean spectrum is built once (and, for the stateful
    pools of later models, so state carries over between frames).
    """

    def __init__(self, scene: Scene, device: str | None = None):
        cfg = scene.config
        self.scene = scene
        self.device = devices.resolve_device(device, config_value=cfg.device.value)
        self.bytes_needed = scene_bytes(scene)
        self.memory_fix = memory_fix(cfg)
        devices.check_fits(self.device, self.bytes_needed, self.memory_fix)
        self.bins = spectra.bins_for(cfg.optics)
        self.sun_irradiance = spectra.sun_irradiance(self.bins, cfg.sun, scene.base_dir)
        optics = spectra.water_optics(cfg.optics, self.bins)
        self.attenuation_per_m = optics.attenuation_per_m
        self.ior = spectra.refractive_index(cfg.optics, self.bins)
        # One refraction per distinct index: K groups with dispersion, else one shared by all bins.
        self.group_ior = self.ior if cfg.optics.dispersion else self.ior[:1]
        with _memory_errors(self.device, self.bytes_needed, self.memory_fix):
            self.water = make_water(cfg, self.device, scene.heights, scene.floor_relief)
            n = scene.water_resolution
            self.visible = wp.empty((n, n), dtype=wp.float32, device=self.device)
            self.photons = None
            self.beams = None
            self.approximate = None
            self.sky_directions = None
            self.multiple = None
            self.sun_directions = scene.sun_disk_directions()  # the centre alone for a point sun
            if cfg.sky.model is not SkyModel.NONE:
                self.sky_directions, shares = scene.sky_directions()
                sky = scene.sky_irradiance(self.sun_irradiance)
                self.sky_irradiance_np = [sky * w for w in shares]
                """Per sky direction: its irradiance on a plane perpendicular to it (K,)."""
                self.sky_irradiance_per_dir = [
                    wp.array(e.astype(np.float32), dtype=wp.float32, device=self.device)
                    for e in self.sky_irradiance_np]
                # The crests' shading from each sky direction: one buffer reused, or all of them
                # (keeps_sky_shading).
                shape = (len(self.sky_directions), n, n) if keeps_sky_shading(cfg) else (n, n)
                self.sky_visible = wp.empty(shape, dtype=wp.float32, device=self.device)
            if cfg.caustics.method.uses_receivers:
                self.receivers = Receivers(cfg, self.bins, self.device, periodic=self.water.periodic,
                                           relief=scene.floor_relief, meshes=scene.receiver_meshes,
                                           water_top_z=_WALL_TOP_M, base_dir=scene.base_dir)
                method = cfg.caustics.method
                args = (cfg, self.receivers, n, self.sun_irradiance, self.attenuation_per_m, self.group_ior,
                        scene.sun_direction, self.device)
                if method in (CausticsMethod.BEAMS, CausticsMethod.BOTH):
                    self.beams = beams.BeamCaustics(*args, periodic=self.water.periodic,
                                                    relief=scene.floor_relief)
                if method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH):
                    self.photons = photons.PhotonCaustics(*args, periodic=self.water.periodic)
                self.floor_top_z = self.receivers.floor_top_z
                if self.water.periodic:
                    lights = [scene.sun_direction] + list(self.sky_directions if self.sky_directions
                                                          is not None else [])
                    for light in lights:
                        photons.check_meshes_inside_patch(cfg, scene.receiver_meshes, light, self.group_ior)
                self.camera = None
                if cfg.camera.enabled:
                    check_camera_position(cfg, scene.floor_relief, self.water.periodic)
                    self.camera = UnderwaterCamera(cfg.camera, self.receivers, optics.scattering_per_m,
                                                   PhaseFunction.from_optics(cfg.optics, self.device),
                                                   self.device)
                    if self.beams is not None:
                        self.beams.camera = self.camera  # adaptive beams refine near it
            else:
                self.floor_top_z = -cfg.floor.depth_m
                self.refracted = Refracted.allocate(len(self.group_ior), n, self.device)
                window = ((cfg.caustics.map_extent_m, tuple(cfg.caustics.map_center_m))
                          if cfg.caustics.map_extent_m else None)
                if cfg.optics.scattering is Scattering.MULTIPLE:
                    sky = {}
                    if self.sky_directions is not None:
                        sky = dict(sky_dirs=self.sky_directions,
                                   sky_irradiance=np.stack(self.sky_irradiance_np))
                    self.multiple = MultipleScattering(cfg, self.sun_directions,
                                                       float(self.group_ior[0]),
                                                       self.sun_irradiance, optics.absorption_per_m,
                                                       optics.scattering_per_m, self.device, **sky)
                disk_share = self.sun_irradiance / len(self.sun_directions)
                self.floor = caustics.FloorCaustics(n, cfg.caustics.map_resolution, disk_share,
                                                    self.attenuation_per_m, self.device,
                                                    periodic=self.water.periodic, window=window)
                # The approximate methods (issue 8): grey, one index for their rays (the bins' mean).
                mean_ior = float(np.mean(self.ior))
                if cfg.caustics.method is CausticsMethod.SUNMAP:
                    self.approximate = SunMapCaustics(cfg, scene.sun_direction, mean_ior, self.device,
                                                      periodic=self.water.periodic)
                elif cfg.caustics.method in (CausticsMethod.EIKONAL, CausticsMethod.WAVE3D):
                    grid_stage = {CausticsMethod.EIKONAL: EikonalCaustics,
                                  CausticsMethod.WAVE3D: Wave3DCaustics}[cfg.caustics.method]
                    self.approximate = grid_stage(
                        cfg, scene.sun_direction, mean_ior, self.sun_irradiance, self.attenuation_per_m,
                        self.device, periodic=self.water.periodic)

    def render(self, time_s: float = 0.0) -> RenderResult:
        """Render the floor caustics at ``time_s`` [s]."""
        if not math.isfinite(time_s):
            raise WarpcausticsError(f"time_s = {time_s} is not a finite number of seconds")
        with _memory_errors(self.device, self.bytes_needed, self.memory_fix):
            return self._render(float(time_s))

    def _render(self, time_s: float) -> RenderResult:
        cfg = self.scene.config
        dev = self.device
        sun_dir = self.scene.sun_direction
        watch = _Stopwatch(dev)
        with watch.stage("water"):
            surface = self.water.at(time_s)
            lowest, highest = height_range(surface, dev)
        if lowest <= self.floor_top_z:
            raise WarpcausticsError(
                f"floor.depth_m = {cfg.floor.depth_m} is too shallow: the water surface reaches "
                f"z = {lowest:.3f} m at t = {time_s:g} s, the floor z = {self.floor_top_z:.3f} m; make "
                "the floor deeper or the waves lower")
        with watch.stage("shading"):
            visible = sun_visibility(surface, sun_dir, highest, dev, out=self.visible)
        extra = {}
        comparison = None
        if self.photons is not None or self.beams is not None:
            if self.receivers.mesh_top_z >= lowest:
                raise WarpcausticsError(
                    f"a receiver reaches z = {self.receivers.mesh_top_z:.3f} m, above the water surface's "
                    f"lowest point z = {lowest:.3f} m at t = {time_s:g} s; receivers must stay under the "
                    "water: lower them (receivers[].translate_m) or make the floor deeper")
            if self.camera is not None and self.camera.position_z >= lowest:
                raise WarpcausticsError(
                    f"camera.position_m z = {self.camera.position_z:g} is not under the water (the "
                    f"surface reaches down to z = {lowest:.3f} m at t = {time_s:g} s); viewing from "
                    "above the water is not implemented yet: lower the camera")
            stages = [st for st in (self.beams, self.photons) if st is not None]
            outputs = [self._receiver_stage(st, surface, visible, highest, watch) for st in stages]
            floor_np, transmitted, extra = outputs[0]
        else:
            # A sun disk: one refraction and deposit per direction over it, each with an equal
            # share of the flux (sun_irradiance was divided by their number); crests shade by the
            # disk's centre.
            transmitted = 0.0
            for i, direction in enumerate(self.sun_directions):
                floor, flux = self._deposit(surface, visible, direction, watch,
                                            ("refraction", "floor_caustics"), clear=i == 0)
                transmitted = transmitted + flux
            with watch.stage("readback"):
                # .copy(): on the CPU device .numpy() is a view of a buffer the next frame reuses.
                floor_np = floor.numpy().copy()
            if self.sky_directions is not None:
                sky_np, sky_transmitted = self._sky(surface, highest, watch)
                extra["sky_floor_irradiance"] = sky_np
                floor_np, transmitted = floor_np + sky_np, transmitted + sky_transmitted
            if self.multiple is not None:  # the walk's maps replace the single-scattering ones
                single_floor, single_transmitted = floor_np, transmitted
                with watch.stage("multiple_scattering"):
                    floor_np, walk = self.multiple.run(surface, visible)
                    transmitted = np.asarray(walk["transmitted"])
                if self.sky_directions is not None:
                    with watch.stage("sky"):
                        sky_np, walk["sky"] = self.multiple.run_sky(surface, self.sky_visible)
                    extra["sky_floor_irradiance"] = sky_np
                    floor_np = floor_np + sky_np
                    transmitted = transmitted + np.asarray(walk["sky"]["transmitted"])
                extra["multiple_scattering_stats"] = walk
            if self.approximate is not None:
                flux_ratio_floor = floor_np
                grid_sky = None
                if self.sky_directions is not None and isinstance(self.approximate, GridCaustics):
                    # the grid's own sky replaces the flux ratio's; solved before the sun, so that
                    # the grid holds the sun's solve afterwards (texture(), stats)
                    with watch.stage("sky"):
                        grid_sky = self._grid_sky(surface, time_s, highest, flux_ratio_floor)
                with watch.stage(cfg.caustics.method.value):
                    floor_np, extra = self.approximate.floor_map(surface, self.water, time_s, highest,
                                                                 visible, flux_ratio_floor)
                    if isinstance(self.approximate, GridCaustics):  # the sun's disk, if any
                        floor_np = self.approximate.disk_average(floor_np, self.sun_directions)
                if grid_sky is not None:
                    extra["sky_floor_irradiance"] = grid_sky
                    floor_np = floor_np + grid_sky
        with watch.stage("surface_readback"):
            positions = surface.positions.numpy()
            normals = surface.normals.numpy()
            folds = float(np.mean(surface.jacobian.numpy() <= 0.0)) if surface.jacobian is not None else 0.0
        common = dict(
            scene=self.scene, time_s=time_s, device=dev, wavelengths_nm=self.bins.centres_nm,
            bin_widths_nm=self.bins.widths_nm, attenuation_per_m=self.attenuation_per_m, ior=self.ior,
            sun_irradiance=self.sun_irradiance, surface_positions=positions, surface_normals=normals,
            bins=self.bins, fold_fraction=folds, timings_s=watch.timings)
        method = cfg.caustics.method
        if self.photons is not None and self.beams is not None:  # "both": photons as the comparison
            other_floor, other_transmitted, other_extra = outputs[1]
            comparison = RenderResult(floor_irradiance=other_floor, transmitted_flux_w_nm=other_transmitted,
                                      method="photons", **common, **other_extra)
        if self.photons is None and self.beams is None and self.approximate is not None:
            # the flux-ratio map of the same frame as the comparison (the sun map's scale)
            comparison = RenderResult(floor_irradiance=flux_ratio_floor, transmitted_flux_w_nm=transmitted,
                                      method="fluxratio", **common)
        name = "beams" if method is CausticsMethod.BOTH else method.value
        if self.multiple is not None:  # the single-scattering map beside the random walk's
            comparison = RenderResult(floor_irradiance=single_floor, transmitted_flux_w_nm=single_transmitted,
                                      method="single", **common)
            name = "multiple"
        return RenderResult(floor_irradiance=floor_np, transmitted_flux_w_nm=transmitted, method=name,
                            comparison=comparison, **common, **extra)

    def _sky(self, surface, highest: float, watch) -> tuple[np.ndarray, np.ndarray]:
        """The sky's floor map and transmitted flux: one shaded refraction and deposit per sky
        direction, each with its share of the sky's irradiance."""
        transmitted = 0.0
        for i, (direction, irradiance) in enumerate(zip(self.sky_directions, self.sky_irradiance_per_dir)):
            with watch.stage("sky"):
                out = self.sky_visible[i] if self.sky_visible.ndim == 3 else self.sky_visible
                visible = sun_visibility(surface, direction, highest, self.device, out=out)
            floor, flux = self._deposit(surface, visible, direction, watch, ("sky", "sky"), clear=i == 0,
                                        irradiance=irradiance)
            transmitted = transmitted + flux
        return floor.numpy().copy(), transmitted

    def _grid_sky(self, surface, time_s: float, highest: float, flux_ratio: np.ndarray) -> np.ndarray:
        """The sky's floor map by the eikonal or wave grid: a solve per sky direction, lit with its
        share of the sky and shaded by the crests as seen from it, as :meth:`_sky` shaded them this
        frame (the sun's light is put back after)."""
        stage = self.approximate
        total = None
        try:
            for i, (direction, irradiance) in enumerate(zip(self.sky_directions, self.sky_irradiance_np)):
                stage.set_light(direction, irradiance)
                floor, _ = stage.floor_map(surface, self.water, time_s, highest, self.sky_visible[i],
                                           flux_ratio)
                total = floor.astype(np.float64) if total is None else total + floor
        finally:
            stage.set_light(self.scene.sun_direction, self.sun_irradiance)
        return total.astype(np.float32)

    def _deposit(self, surface, visible, direction, watch, stages: tuple[str, str], *, clear: bool,
                 irradiance: wp.array | None = None) -> tuple[wp.array3d, np.ndarray]:
        """One flux-ratio pass for light arriving from ``direction`` (the sun's centre, a point of
        its disk or of the sky): refraction, then the deposit added to the map unless ``clear``;
        returns the map and the pass's transmitted flux per band (one host read-back; a device-side
        sum would spare it on CUDA)."""
        with watch.stage(stages[0]):
            refracted = refract_to_floor(surface, visible, self.group_ior, direction,
                                         -self.scene.config.floor.depth_m, self.device, out=self.refracted)
        with watch.stage(stages[1]):
            floor = self.floor.run(surface, refracted, direction, clear=clear, irradiance=irradiance)
            flux = self.floor.flux.numpy().sum(axis=(0, 1, 2), dtype=np.float64)
        return floor, flux

    def _light_passes(self) -> list[tuple[np.ndarray, np.ndarray, bool]]:
        """The passes of a photon or beam stage: (direction (3,), irradiance (K,) on a plane
        perpendicular to it, from the sky). A pass per direction of the sun's disk with its share
        of the sun, and per sky direction with its share of the sky. Photons too: taking the disk's
        directions in turn within one pass made each photon's lattice neighbours another
        direction's, and the camera's lattice splats then drew the pattern of that assignment."""
        dirs = self.sun_directions
        passes = [(d, self.sun_irradiance / len(dirs), False) for d in dirs]
        if self.sky_directions is not None:
            passes += [(d, e, True) for d, e in zip(self.sky_directions, self.sky_irradiance_np)]
        return passes

    def _receiver_stage(self, stage, surface, visible, highest, watch) -> tuple[np.ndarray, np.ndarray, dict]:
        """Run the photon or beam stage (and the camera with it) over its light passes
        (:meth:`_light_passes`): (floor map, transmitted flux, the RenderResult fields of receivers,
        camera and sky), all on the host. Counts add up over the passes."""
        cfg = self.scene.config
        photons = stage is self.photons
        rec = self.receivers
        other = rec.face_count - rec.floor_face_count
        totals: dict[bool, dict[str, np.ndarray]] = {False: {}, True: {}}
        extra = {}
        passes = self._light_passes()
        for direction, irradiance, from_sky in passes:
            stage.set_light(direction, irradiance)
            if from_sky:
                with watch.stage("sky"):
                    seen = sun_visibility(surface, direction, highest, self.device, out=self.sky_visible)
            else:
                seen = visible  # crests shade by the sun's centre
            # a sky pass's work is timed as "sky", as the flux-ratio map's and the grids' are
            with watch.stage("sky" if from_sky else "photons" if photons else "beams"):
                floor = stage.run(surface, seen)
            part = {}
            if self.camera is not None:
                camera_stage = "camera" if photons or self.photons is None else "camera_beams"
                with watch.stage("sky" if from_sky else camera_stage):
                    if photons:
                        n = self.scene.water_resolution
                        spacing = cfg.water.extent_m / n / cfg.caustics.photon_subdivisions
                        self.camera.render(stage, spacing, cfg.caustics.shafts)
                    else:
                        self.camera.render_beams(stage, cfg.caustics.shafts)
                    part["camera_radiance"] = self.camera.radiance.numpy().astype(np.float64)
            with watch.stage("readback"):
                part["floor"] = floor.numpy().astype(np.float64)
                part["transmitted"] = stage.transmitted_flux()
                part["face_flux_w_nm"] = (stage.face_flux.numpy()[:other].astype(np.float64) if photons
                                          else stage.face_flux_w_nm())
                counts = vars(stage.stats())
            total = totals[from_sky]
            for key, value in part.items():
                total[key] = total[key] + value if key in total else value
            stats_key = "photon_stats" if photons else "beam_stats"
            extra[stats_key] = {k: extra.get(stats_key, {}).get(k, 0) + v for k, v in counts.items()}
        sun, sky = totals[False], totals[True]
        combined = {key: sun[key] + sky[key] if key in sky else sun[key] for key in sun}
        floor_np = combined["floor"].astype(np.float32)
        transmitted = combined["transmitted"]
        extra["face_flux_w_nm"] = combined["face_flux_w_nm"]
        if sky:
            extra["sky_floor_irradiance"] = sky["floor"].astype(np.float32)
        if self.camera is not None:
            extra["camera_radiance"] = combined["camera_radiance"].astype(np.float32)
            extra["camera_gbuffer"] = self.camera.gbuffer()
        with watch.stage("readback"):
            extra.update(face_receiver=rec.face_receiver_np[rec.floor_face_count:],
                         face_area_m2=rec.face_area_m2[rec.floor_face_count:],
                         face_centres_m=rec.face_centres_m[rec.floor_face_count:],
                         floor_texel_area_m2=rec.floor_texel_area_m2,
                         receiver_mesh=rec.non_floor_mesh())
        return floor_np, transmitted, extra


_WALL_TOP_M = 1.0
"""Height of a walled pool's walls above the water at rest [m]."""

_MEMORY_FIX = "lower water.resolution, caustics.map_resolution or optics.wavelengths.bins"


def memory_fix(cfg) -> str:
    """What to lower when a scene does not fit: the grid methods' 3-D grid comes first."""
    grid_key = {CausticsMethod.EIKONAL: "caustics.eikonal_resolution",
                CausticsMethod.WAVE3D: "caustics.wave3d_resolution"}.get(cfg.caustics.method)
    return f"lower {grid_key}, water.resolution or caustics.map_resolution" if grid_key else _MEMORY_FIX


@contextmanager
def _memory_errors(device: str, needed: int, fix: str = _MEMORY_FIX):
    """Turn Warp's allocation failures into a one-line DeviceError that states the need."""
    try:
        yield
    except RuntimeError as exc:
        text = str(exc).lower()
        if "alloc" in text or "out of memory" in text:
            raise devices.out_of_memory(device, needed, fix) from None
        raise


def render(scene: Scene, time_s: float = 0.0, device: str | None = None) -> RenderResult:
    """Render the floor caustics of ``scene`` at ``time_s`` [s].

    ``device``: ``"cpu"``, ``"cuda"``, ``"cuda:N"`` or None (``$WARPCAUSTICS_DEVICE``, then the
    config's ``device``, then CUDA if available else CPU). For many frames use :class:`Renderer`.
    """
    return Renderer(scene, device).render(time_s)
