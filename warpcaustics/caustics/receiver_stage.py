"""What the receiver methods (photons, beams, both) share: every receiver lit (relief, walls,
meshes), the camera fed (under the water, or above it: ``scene/above.py``), one light pass per
direction of the sun's disk and of the sky."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import warp as wp

from warpcaustics.caustics.stage import CausticStage, Frame, Lighting, StageOutput
from warpcaustics.config import SkyModel
from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.kernels.caustics.bounces import Optics
from warpcaustics.optics.phase import PhaseFunction
from warpcaustics.optics.refraction import still_water_refraction
from warpcaustics.scene.above import AboveWaterCamera, above_camera_bytes
from warpcaustics.scene.camera import UnderwaterCamera, camera_bytes
from warpcaustics.scene.receivers import (
    FIRST_MESH_ID,
    WALL_FACES,
    Receivers,
    floor_mesh_cells,
    floor_relief_height,
)

WALL_TOP_M = 1.0
"""Height of a walled pool's walls above the water at rest [m]."""


def check_camera_position(cfg, floor_relief: np.ndarray | None, periodic: bool) -> None:
    """The camera must be in the water: over a non-periodic patch (inside a pool's walls) and above
    the floor."""
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


def unlit_receivers(cfg, receivers: Receivers) -> np.ndarray:
    """Per receiver id (floor, walls, ``receivers[i]``): 1 for one that passes or sends on the light
    it meets instead of gathering it (glass, a mirror; ``caustics.bounces`` > 1)."""
    unlit = np.zeros(len(receivers.names), np.int32)
    for i, r in enumerate(cfg.receivers):
        unlit[FIRST_MESH_ID + i] = int(r.ior is not None or r.specular)
    return unlit


def receiver_optics(cfg, receivers: Receivers, group_ior: np.ndarray, device: str) -> Optics:
    """Per receiver id its refractive index (0: opaque) and whether it is a mirror, with the water's
    index per group, for ``caustics.bounces`` > 1."""
    count = len(receivers.names)
    ior = np.zeros(count, np.float32)
    specular = np.zeros(count, np.int32)
    for i, r in enumerate(cfg.receivers):
        ior[FIRST_MESH_ID + i] = r.ior or 0.0
        specular[FIRST_MESH_ID + i] = int(r.specular)
    optics = Optics()
    optics.ior = wp.array(ior, dtype=wp.float32, device=device)
    optics.specular = wp.array(specular, dtype=wp.int32, device=device)
    optics.water_ior = wp.array(np.asarray(group_ior, np.float32), dtype=wp.float32, device=device)
    optics.object_bounces = cfg.caustics.bounces - 1
    return optics


def check_meshes_inside_patch(cfg, meshes: tuple, sun_dir: np.ndarray, ior: np.ndarray) -> None:
    """On a periodic sea a photon is moved by whole periods so that, followed to the floor plane at
    rest, it lands in the patch; a mesh only gets the light of photons whose path through it would
    land there. Refuse meshes so near the patch edge that some of their light would be missed."""
    if not meshes:
        return
    half = 0.5 * cfg.water.extent_m
    plane_z = -cfg.floor.depth_m
    for i, mesh in enumerate(meshes):
        worst = 0.0
        for n in (float(np.min(ior)), float(np.max(ior))):
            d = still_water_refraction(sun_dir, n)
            drop = mesh.points[:, 2] - plane_z
            landing = mesh.points[:, :2] + (drop / -d[2])[:, None] * d[None, :2]
            # Waves tilt the rays: allow for a tenth of the drop either way, and 2 % of the patch.
            margin = 0.1 * np.abs(drop) + 0.02 * cfg.water.extent_m
            spots = np.concatenate([landing, mesh.points[:, :2]])
            reach = np.max(np.abs(spots) + np.tile(margin, 2)[:, None])
            worst = max(worst, float(reach - half))
        if worst > 0.0:
            raise ConfigError(
                f"receivers[{i}] is {worst:.2f} m too near the edge of the periodic {cfg.water.extent_m:g} m "
                "patch: part of the light that reaches it would land outside the patch and be missed; "
                "move it towards the centre (receivers[].translate_m) or enlarge water.extent_m")


def receiver_face_estimate(scene, periodic: bool) -> int:
    """Faces of the receivers' BVH (the floor grid with its margin, walls, meshes)."""
    cfg = scene.config
    cells = floor_mesh_cells(cfg)
    floor = 2 * int(cells * (1.5 if periodic else 1.0)) ** 2
    walls = WALL_FACES if cfg.water.walled else 0
    return floor + sum(len(m.triangles) for m in scene.receiver_meshes) + walls


@dataclass(frozen=True)
class CausticsSetup:
    """What a receiver method's caustics object is built from, once per scene."""

    cfg: object
    receivers: Receivers
    n: int
    """Water resolution (vertices per side)."""
    sun_irradiance: np.ndarray
    """(K,) the sun's irradiance on a plane perpendicular to it [W m^-2 nm^-1]."""
    attenuation_per_m: np.ndarray
    """(K,) beam attenuation c(λ) [m^-1]."""
    group_ior: np.ndarray
    """One refractive index per index group."""
    sun_dir: np.ndarray
    """(3,) towards the sun's centre."""
    device: str
    periodic: bool
    relief: np.ndarray | None
    """The floor's relief heights (None: flat or analytic)."""


@dataclass
class LightPass:
    """One light pass of a caustics object, read back to the host before the next pass starts: the
    object's device buffers are its workspace, and nothing a caller gets refers to them."""

    floor: np.ndarray
    """(K, M, M) floor irradiance [W m^-2 nm^-1] (float64)."""
    transmitted: np.ndarray
    """(K,) flux entering the water before attenuation [W nm^-1]."""
    face_flux_w_nm: np.ndarray
    """(F_other, K) flux on each non-floor face [W nm^-1]."""
    stats: dict
    """The method's counts (``RenderResult.photon_stats`` / ``beam_stats``)."""
    camera_radiance: np.ndarray | None = None
    """(K, H, W) the camera's radiance from this pass (float64), None without a camera."""


class PassCaustics:
    """Base of a receiver method's caustics object (photons, beams): built once per scene from a
    :class:`CausticsSetup`, then one :meth:`light_pass` per light direction. Subclasses implement
    :meth:`trace` (the device work), :meth:`_render_camera`, :meth:`_transmitted_flux`,
    :meth:`_face_flux_w_nm` and :meth:`_stats`, which read the buffers of the pass just traced."""

    timing_name: ClassVar[str] = ""
    """The stage's entry in RenderResult.timings_s and its RenderResult.method."""
    stats_key: ClassVar[str] = ""
    """Its counts' RenderResult field."""

    def attach_camera(self, camera) -> None:
        """Called once when the scene has a camera (before any pass)."""

    def trace(self, surface, visible, direction: np.ndarray, irradiance: np.ndarray):
        """The device work of a pass of light from ``direction`` (3,) (towards a point of the sun's
        disk, or of the sky) carrying ``irradiance`` (K,) on a plane perpendicular to it
        [W m⁻² nm⁻¹]; returns the (K, M, M) floor map on the device (benchmarks time this alone)."""
        raise NotImplementedError

    def light_pass(self, surface, visible, direction: np.ndarray, irradiance: np.ndarray, watch, *,
                   stage: str, camera=None, camera_stage: str = "camera", shafts: bool = False) -> LightPass:
        """Trace one pass, shade ``camera`` with it, and read everything back (timed as ``stage``,
        ``camera_stage`` and ``readback`` on ``watch``)."""
        with watch.stage(stage):
            floor = self.trace(surface, visible, direction, irradiance)
        radiance = None
        if camera is not None:
            with watch.stage(camera_stage):
                self._render_camera(camera, shafts)
                radiance = camera.radiance.numpy().astype(np.float64)
        with watch.stage("readback"):
            return LightPass(floor.numpy().astype(np.float64), self._transmitted_flux(),
                             self._face_flux_w_nm(),
                             {k: v for k, v in vars(self._stats()).items() if v is not None}, radiance)


class ReceiverStage(CausticStage):
    """A method that lights every receiver and feeds the camera. Subclasses say which caustics
    objects run (:meth:`make_caustics`: :class:`PassCaustics`) and their memory
    (:meth:`caustics_bytes`); the first one's maps are the result, a second one's its comparison."""

    def __init__(self, scene, water, light: Lighting, device: str):
        super().__init__(scene, water, light, device)
        cfg = scene.config
        periodic = water.periodic
        self.receivers = Receivers(cfg, light.bins, device, periodic=periodic, relief=scene.floor_relief,
                                   meshes=scene.receiver_meshes, water_top_z=WALL_TOP_M,
                                   base_dir=scene.base_dir)
        setup = CausticsSetup(cfg, self.receivers, scene.water_resolution, light.sun_irradiance,
                              light.attenuation_per_m, light.group_ior, scene.sun_direction, device,
                              periodic, scene.floor_relief)
        self.caustics = self.make_caustics(setup)
        self.floor_top_z = self.receivers.floor_top_z
        if periodic:
            lights = [scene.sun_direction] + list(light.sky_directions if light.sky_directions is not None
                                                  else [])
            for direction in lights:
                check_meshes_inside_patch(cfg, scene.receiver_meshes, direction, light.group_ior)
        self.camera = None
        if cfg.camera.enabled and cfg.camera.position_m[2] > 0.0:  # the view from above the water
            sky = scene.sky_irradiance(light.sun_irradiance) if cfg.sky.model is not SkyModel.NONE else None
            self.camera = AboveWaterCamera(cfg, self.receivers, light, light.optics.scattering_per_m,
                                           PhaseFunction.from_optics(cfg.optics, device), scene.sun_direction,
                                           sky, device)
        elif cfg.camera.enabled:
            check_camera_position(cfg, scene.floor_relief, periodic)
            self.camera = UnderwaterCamera(cfg.camera, self.receivers, light.optics.scattering_per_m,
                                           PhaseFunction.from_optics(cfg.optics, device), device)
            for caustics in self.caustics:
                caustics.attach_camera(self.camera)

    def make_caustics(self, setup: CausticsSetup) -> list[PassCaustics]:
        """The caustics objects of this method."""
        raise NotImplementedError

    @classmethod
    def caustics_bytes(cls, scene, n: int, k: int, groups: int, faces: int) -> int:
        """Device memory of this method's caustics objects [bytes]."""
        raise NotImplementedError

    @classmethod
    def bytes_needed(cls, scene, k: int, groups: int) -> int:
        cfg = scene.config
        faces = receiver_face_estimate(scene, cfg.water.periodic)
        cam = 0
        if cfg.camera.enabled:
            above = cfg.camera.position_m[2] > 0.0
            cam = (above_camera_bytes(cfg, k, scene.water_resolution) if above
                   else camera_bytes(cfg.camera, k))
        return cls.caustics_bytes(scene, scene.water_resolution, k, groups, faces) + cam

    def check_frame(self, frame: Frame) -> None:
        if self.receivers.mesh_top_z >= frame.lowest:
            raise WarpcausticsError(
                f"a receiver reaches z = {self.receivers.mesh_top_z:.3f} m, above the water surface's "
                f"lowest point z = {frame.lowest:.3f} m at t = {frame.time_s:g} s; receivers must stay under "
                "the water: lower them (receivers[].translate_m) or make the floor deeper")
        if getattr(self.camera, "above_water", False):
            if self.camera.position_z <= frame.highest:
                raise WarpcausticsError(
                    f"camera.position_m z = {self.camera.position_z:g} is not above the water (a crest "
                    f"reaches z = {frame.highest:.3f} m at t = {frame.time_s:g} s); raise the camera "
                    "above the waves")
        elif self.camera is not None and self.camera.position_z >= frame.lowest:
            raise WarpcausticsError(
                f"camera.position_m z = {self.camera.position_z:g} is not under the water (the "
                f"surface reaches down to z = {frame.lowest:.3f} m at t = {frame.time_s:g} s); viewing from "
                "above the water needs the camera above every crest: lower it under the troughs or raise it")

    def render(self, frame: Frame) -> StageOutput:
        outputs = [self._passes(caustics, i == len(self.caustics) - 1, frame)
                   for i, caustics in enumerate(self.caustics)]
        first = outputs[0]
        if len(outputs) > 1:
            first.comparison = outputs[1]
        return first

    def _passes(self, caustics, last: bool, frame: Frame) -> StageOutput:
        """Run one caustics object (and the camera with it) over the light passes
        (:meth:`Lighting.passes`): its floor map, transmitted flux and the RenderResult fields of
        receivers, camera and sky, all on the host. Counts add up over the passes. Taking the
        disk's directions in turn within one photon pass made each photon's lattice neighbours
        another direction's, and the camera's lattice splats then drew that assignment's pattern."""
        cfg = self.scene.config
        watch = frame.watch
        rec = self.receivers
        totals: dict[bool, dict[str, np.ndarray]] = {False: {}, True: {}}
        extra = {}
        # with a second method, the first one's camera time is its own entry
        camera_stage = "camera" if last else f"camera_{caustics.timing_name}"
        above = getattr(self.camera, "above_water", False)
        if above:
            with watch.stage(camera_stage):
                self.camera.begin_frame(frame.surface, frame.highest, frame.lowest)
        for direction, irradiance, from_sky in self.light.passes():
            if from_sky:
                with watch.stage("sky"):
                    seen = frame.shade(direction, self.device, self.light.sky_visible)
            else:
                seen = frame.visible  # crests shade by the sun's centre
            # a sky pass's work is timed as "sky", as the flux-ratio map's and the grids' are
            done = caustics.light_pass(frame.surface, seen, direction, irradiance, watch,
                                       stage="sky" if from_sky else caustics.timing_name, camera=self.camera,
                                       camera_stage="sky" if from_sky else camera_stage,
                                       shafts=cfg.caustics.shafts)
            part = {"floor": done.floor, "transmitted": done.transmitted,
                    "face_flux_w_nm": done.face_flux_w_nm}
            if done.camera_radiance is not None:
                part["camera_radiance"] = done.camera_radiance
            total = totals[from_sky]
            for key, value in part.items():
                total[key] = total[key] + value if key in total else value
            key = caustics.stats_key
            extra[key] = {k: extra.get(key, {}).get(k, 0) + v for k, v in done.stats.items()}
        sun, sky = totals[False], totals[True]
        combined = {key: sun[key] + sky[key] if key in sky else sun[key] for key in sun}
        extra["face_flux_w_nm"] = combined["face_flux_w_nm"]
        if sky:
            extra["sky_floor_irradiance"] = sky["floor"].astype(np.float32)
        if self.camera is not None:
            radiance = combined["camera_radiance"]
            radiance = self.camera.finish(radiance) if above else radiance
            extra["camera_radiance"] = radiance.astype(np.float32)
            extra["camera_gbuffer"] = self.camera.gbuffer()
        with watch.stage("readback"):
            extra.update(face_receiver=rec.face_receiver_np[rec.floor_face_count:],
                         face_area_m2=rec.face_area_m2[rec.floor_face_count:],
                         face_centres_m=rec.face_centres_m[rec.floor_face_count:],
                         floor_texel_area_m2=rec.floor_texel_area_m2,
                         receiver_mesh=rec.non_floor_mesh())
        return StageOutput(combined["floor"].astype(np.float32), combined["transmitted"],
                           caustics.timing_name, extra)
