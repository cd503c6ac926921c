"""The camera above the water (host side): de la Fuente Caballé 2011 §4.2's above/under-water
division, by ray casting instead of stencil passes.

Each frame (:meth:`AboveWaterCamera.begin_frame`) the pixel rays meet the moving surface
(``kernels/scene/camera/above.py``). Where a ray meets the water, the exact Fresnel reflectance
R(θ, λ) splits it: the reflected ray sees the sky (``sky.model``'s radiance) and the sun's disk
(its glint), and the refracted ray runs down to the first receiver. Each light pass then lights
what the refracted rays see from the beams (:meth:`render_beams`): the receiver's Lambertian
radiance ``ρ E / π``, attenuated over the path, plus the single scattering into the ray along it,
by midpoint samples of :func:`point_inscatter`; that radiance leaves the water multiplied by
(1 − R)/n² (the radiance invariant L/n² across the surface). Photons light them through their
maps instead, and their shafts from E⊥ on horizontal slices of the water (:meth:`render_photons`).
The reflection is added once, after the passes (:meth:`finish`). A ray that misses the water sees
the sky, or a receiver in the air lit by the sun and the sky without shadows.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from warpcaustics.config import CausticsMethod, Config
from warpcaustics.kernels.scene import camera as camera_kernels
from warpcaustics.kernels.scene.camera import above as above_kernels
from warpcaustics.optics.phase import PhaseFunction
from warpcaustics.optics.refraction import still_water_refraction
from warpcaustics.optics.sky import cie_sky_type, sky_radiance
from warpcaustics.optics.snell import fresnel_transmittance
from warpcaustics.scene.camera import pinhole
from warpcaustics.scene.receivers import Receivers

PERIODIC_IMAGES = 3
"""The moving surface of a periodic sea is traced in 3 × 3 images of the patch; beyond, still water."""

ENTRY_OFFSET_M = 1.0e-4
"""The refracted ray starts this far below the surface point, off the surface's own triangles."""

PHOTON_SLICE_TEXELS = 128
"""The photons' slices of the water column (their shafts from above) have at most this many texels a
side over the patch (the floor map's resolution if coarser): S × R² × K floats a pass."""

SLICE_FLOOR_GAP = 1.0e-3
"""The photons' last slice lies this share of the water column above the receivers' lowest point:
photons that end on a floor there land on either side of it by float32 rounding."""

OPEN_WATER_ATTENUATION_LENGTHS = 10.0
"""A refracted ray that meets no receiver is sampled over this many attenuation lengths of its
clearest band (capped at 1 km): the rest of the line adds less than e^-10 of it."""


def above_camera_bytes(cfg: Config, k: int, water_n: int) -> int:
    """Device memory of the above-water camera's buffers [bytes]."""
    cam = cfg.camera
    pixels = cam.width * cam.height
    side = water_n + 1
    # per pixel: 7 vec3 images, 6 scalar images, 4 (K, H, W) images, the samples' points, views,
    # distances and pieces; per surface vertex: its point and normal, two triangles' indices and BVH
    # (the meshes' face areas, 4 bytes a face, are left to the receivers' own estimate)
    slices = 0  # photons' shafts: their E⊥ on camera.shaft_samples planes (render_photons)
    if cfg.caustics.method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH) and cfg.caustics.shafts:
        slices = cam.shaft_samples * min(cfg.caustics.map_resolution, PHOTON_SLICE_TEXELS) ** 2 * k * 4
    return (pixels * (7 * 12 + 6 * 4 + 4 * 4 * k) + pixels * (2 * 12 + 2 * 4)
            + side * side * (2 * 12 + 6 * 4 + 64) + slices)


class AboveWaterCamera:
    """A pinhole camera above the water: its buffers for one scene on one device."""

    above_water = True

    def __init__(self, cfg: Config, receivers: Receivers, light, scattering_per_m: np.ndarray,
                 phase: PhaseFunction, sun_direction: np.ndarray, sky_irradiance: np.ndarray | None,
                 device: str):
        self.cfg = cfg.camera
        self.config = cfg
        self.device = device
        self.receivers = receivers
        self.phase = phase
        self.cam = pinhole(cfg.camera)
        self.sun_direction = np.asarray(sun_direction, np.float64)
        self.sun_irradiance = np.asarray(light.sun_irradiance, np.float64)
        k = len(self.sun_irradiance)
        # the index of each band's Fresnel factors: its own with dispersion, else the one index all
        # refractions use (the rays themselves follow the first)
        self.ior = np.broadcast_to(np.asarray(light.group_ior, np.float64), (k,)).copy()
        self.ray_ior = float(light.group_ior[0])
        self.attenuation = np.asarray(light.attenuation_per_m, np.float64)
        self.sky_irradiance = sky_irradiance
        self.sky_type = cie_sky_type(cfg.sky)
        self.samples = cfg.camera.shaft_samples
        self.scattering_per_m = wp.array(np.asarray(scattering_per_m, np.float32), dtype=wp.float32,
                                         device=device)
        h, w = self.cfg.height, self.cfg.width
        vec = {name: wp.empty((h, w), dtype=wp.vec3, device=device)
               for name in ("rays", "hit", "surface_normal", "origin", "direction", "position", "normal")}
        self.__dict__.update(vec)
        self.kind = wp.empty((h, w), dtype=wp.int32, device=device)
        self.depth = wp.empty((h, w), dtype=wp.float32, device=device)
        self.receiver = wp.empty((h, w), dtype=wp.int32, device=device)
        self.face = wp.empty((h, w), dtype=wp.int32, device=device)
        """The receivers' face each ray meets (−1: none)."""
        other = receivers.face_area_m2[receivers.floor_face_count:]
        self.face_area_m2 = wp.array(np.append(other, 1.0).astype(np.float32), dtype=wp.float32,
                                     device=device)
        """Area of each non-floor face [m²] (one more entry, so that the array is never empty)."""
        self.water_receiver = wp.empty((h, w), dtype=wp.int32, device=device)
        """The receiver each refracted ray meets; −1 where the pixel does not look into the water."""
        self.length = wp.empty((h, w), dtype=wp.float32, device=device)
        self.through = wp.empty((k, h, w), dtype=wp.float32, device=device)
        """(1 − R)/n² per band and pixel: what of the water's radiance leaves into the camera."""
        pixels = h * w
        self.points = wp.empty(pixels, dtype=wp.vec3, device=device)
        self.views = wp.empty(pixels, dtype=wp.vec3, device=device)
        self.along = wp.empty(pixels, dtype=wp.float32, device=device)
        self.piece = wp.empty(pixels, dtype=wp.float32, device=device)
        self.caustic = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self.shafts = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self.radiance = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self.surface_radiance = np.zeros((k, h, w))
        """What the camera sees that the light passes do not give: the reflection, the sky, the
        receivers in the air (float64)."""
        self.top_z = 0.0
        self.lowest_z = 0.0
        self.receivers_bottom_z = float(receivers.points[:, 2].min())
        """The receivers' lowest point [m] (they are static): the photons' last slice is just above."""
        self._mesh = None
        self._gbuffer: dict[str, np.ndarray] | None = None

    @property
    def position_z(self) -> float:
        return float(self.cfg.position_m[2])

    # --- per frame ---------------------------------------------------------------------------

    def _water_mesh(self, surface) -> wp.Mesh:
        """The frame's surface as a triangle mesh (built once, refitted after)."""
        n = surface.resolution
        periodic = int(surface.periodic)
        side = n + periodic
        if self._mesh is None:
            self._points = wp.empty(side * side, dtype=wp.vec3, device=self.device)
            self._point_normals = wp.empty(side * side, dtype=wp.vec3, device=self.device)
            j, i = np.meshgrid(np.arange(side - 1), np.arange(side - 1), indexing="ij")
            a = (j * side + i).ravel()
            tris = np.stack([a, a + 1, a + side + 1, a, a + side + 1, a + side], axis=1).reshape(-1)
            self._indices = wp.array(tris.astype(np.int32), dtype=wp.int32, device=self.device)
        wp.launch(above_kernels.water_vertices, dim=(side, side),
                  inputs=[surface.positions, surface.normals, periodic, float(surface.extent_m)],
                  outputs=[self._points, self._point_normals], device=self.device)
        if self._mesh is None:
            self._mesh = wp.Mesh(points=self._points, indices=self._indices)
        else:
            self._mesh.refit()
        return self._mesh

    def begin_frame(self, surface, highest_m: float, lowest_m: float = 0.0) -> None:
        """Trace the pixel rays to the water and below it for ``surface``; shade what the light
        passes do not (the reflection, the sky, the receivers in the air)."""
        dev = self.device
        h, w = self.cfg.height, self.cfg.width
        mesh = self._water_mesh(surface)
        self.top_z = float(highest_m)
        self.lowest_z = float(lowest_m)
        wp.launch(above_kernels.surface_hits, dim=(h, w),
                  inputs=[self.cam, mesh.id, self._points, self._point_normals, self._indices,
                          float(surface.extent_m), int(surface.periodic),
                          PERIODIC_IMAGES if surface.periodic else 1],
                  outputs=[self.rays, self.hit, self.surface_normal, self.kind], device=dev)
        kind = self.kind.numpy()
        rays = self.rays.numpy().astype(np.float64)
        hit = self.hit.numpy().astype(np.float64)
        normal = self.surface_normal.numpy().astype(np.float64)
        wet = kind != above_kernels.AIR
        cos_i = np.clip(-(rays * normal).sum(-1), 1e-6, 1.0)
        reflected = rays + 2.0 * cos_i[..., None] * normal
        eta = 1.0 / self.ray_ior
        k_t = np.clip(1.0 - eta * eta * (1.0 - cos_i * cos_i), 0.0, None)
        refracted = eta * rays + (eta * cos_i - np.sqrt(k_t))[..., None] * normal
        refracted /= np.linalg.norm(refracted, axis=-1, keepdims=True)
        transmit = np.stack([fresnel_transmittance(cos_i, 1.0 / n) for n in self.ior])  # (K, H, W)
        through = np.where(wet, transmit / self.ior[:, None, None] ** 2, 0.0)
        self.through.assign(through.astype(np.float32))
        origin = np.where(wet[..., None], hit + ENTRY_OFFSET_M * refracted, np.asarray(self.cfg.position_m))
        direction = np.where(wet[..., None], refracted, rays)
        self.origin.assign(origin.astype(np.float32))
        self.direction.assign(direction.astype(np.float32))
        rec = self.receivers
        wp.launch(above_kernels.first_receiver, dim=(h, w),
                  inputs=[rec.mesh.id, rec.face_receiver, self.origin, self.direction],
                  outputs=[self.position, self.normal, self.depth, self.receiver, self.face], device=dev)
        receiver = self.receiver.numpy()
        depth = self.depth.numpy().astype(np.float64)
        self.water_receiver.assign(np.where(wet, receiver, -1).astype(np.int32))
        open_water = min(OPEN_WATER_ATTENUATION_LENGTHS / max(float(self.attenuation.min()), 1e-12), 1.0e3)
        length = np.where(wet, np.where(receiver >= 0, depth, open_water), 0.0)
        self.length.assign(length.astype(np.float32))
        # What the passes do not give: the reflection on the water, and what a dry ray sees.
        surface = np.where(wet, 1.0 - transmit, 0.0) * self._sky_and_sun(reflected)
        dry = ~wet
        air_receiver = dry & (receiver >= 0)
        surface += np.where(dry & (receiver < 0), 1.0, 0.0) * self._sky_and_sun(rays)
        if air_receiver.any():
            surface += np.where(air_receiver, 1.0, 0.0) * self._lit_in_air(receiver, self.normal.numpy())
        self.surface_radiance = surface
        self._gbuffer = None

    def _sky_and_sun(self, directions: np.ndarray) -> np.ndarray:
        """(K, H, W) radiance towards ``directions`` (H, W, 3): the sky's, and the sun's disk
        (uniform, E_sun / Ω; a point sun draws none)."""
        out = np.zeros((len(self.sun_irradiance),) + directions.shape[:2])
        if self.sky_irradiance is not None:
            sky = sky_radiance(self.sky_type, directions, self.sun_direction, self.sky_irradiance)
            out += np.moveaxis(sky, -1, 0)
        radius = 0.5 * math.radians(self.config.sun.angular_diameter_deg)
        if radius > 0.0:
            solid_angle = 2.0 * math.pi * (1.0 - math.cos(radius))
            on_disk = directions @ self.sun_direction >= math.cos(radius)
            out += on_disk[None] * (self.sun_irradiance / solid_angle)[:, None, None]
        return out

    def _lit_in_air(self, receiver: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """(K, H, W) radiance of receivers seen in the air: ρ/π (E_sun max(n·s, 0) + E_sky (1 + n_z)/2),
        no shadows (a wall's top, a pool's rim)."""
        n = normal.astype(np.float64)
        albedo = self.receivers.albedo[np.maximum(receiver, 0)]  # (H, W, K)
        e = np.clip(n @ self.sun_direction, 0.0, None)[..., None] * self.sun_irradiance
        if self.sky_irradiance is not None:
            e = e + 0.5 * (1.0 + n[..., 2])[..., None] * self.sky_irradiance
        return np.moveaxis(albedo * e / math.pi, -1, 0)

    # --- per light pass ----------------------------------------------------------------------

    def render_beams(self, beams, shafts: bool) -> wp.array3d:
        """What the refracted rays see of ``beams``' pass, as it leaves the water: (K, H, W)."""
        from warpcaustics.kernels.caustics import beams as beam_kernels

        dev = self.device
        h, w = self.cfg.height, self.cfg.width
        k = self.caustic.shape[0]
        pixels = h * w
        beams.points(self.position.reshape((pixels,)), self.normal.reshape((pixels,)),
                     self.water_receiver.reshape((pixels,)), self.caustic.reshape((k, pixels)))
        self.shafts.zero_()
        if shafts:
            sb = beam_kernels.ShaftBeams()
            sb.copies = 1
            sb.soft_fade_m = 0.0
            sb.scattering_per_m = self.scattering_per_m
            ph = self.phase
            sb.phase_kind, sb.hg_g, sb.cone_phase = ph.kind, ph.g, ph.cone_phase
            sb.angles_rad, sb.log_phase = ph.angles_rad, ph.log_phase
            for n in range(self.samples):
                wp.launch(above_kernels.segment_samples, dim=(h, w),
                          inputs=[self.origin, self.direction, self.length, self.samples, n],
                          outputs=[self.points, self.views, self.along, self.piece], device=dev)
                beams.inscatter(sb, self.points, self.views, self.along, self.piece,
                                self.shafts.reshape((k, pixels)), self.top_z)
        return self._leave_water(beams.attenuation_per_m)

    def render_photons(self, photons, shafts: bool) -> wp.array3d:
        """What the refracted rays see of ``photons``' pass, as it leaves the water: (K, H, W). The
        photons light the points the refracted rays meet through their maps (the floor map
        bilinear, a face's flux over its area), and the light scattered into the rays from their
        E⊥ on horizontal slices of the water (:meth:`_photon_shafts`)."""
        dev = self.device
        h, w = self.cfg.height, self.cfg.width
        k = self.caustic.shape[0]
        wp.launch(above_kernels.photon_point_irradiance, dim=(k, h, w),
                  inputs=[self.water_receiver, self.position, self.face, self.receivers.floor_face_count,
                          photons.irradiance, float(self.config.water.extent_m), int(photons.periodic),
                          photons.face_flux, self.face_area_m2],
                  outputs=[self.caustic], device=dev)
        self.shafts.zero_()
        if shafts:
            self._photon_shafts(photons)
        return self._leave_water(photons.attenuation_per_m)

    def _leave_water(self, attenuation_per_m: wp.array) -> wp.array3d:
        """The radiance the refracted rays bring back from this pass (:attr:`caustic` on the receiver
        they meet, :attr:`shafts` along them), through the surface into the camera: (K, H, W)."""
        h, w = self.cfg.height, self.cfg.width
        k = self.caustic.shape[0]
        wp.launch(camera_kernels.shade, dim=(k, h, w),
                  inputs=[self.water_receiver, self.depth, self.caustic, self.shafts,
                          self.receivers.albedo_wp, attenuation_per_m],
                  outputs=[self.radiance], device=self.device)
        wp.launch(above_kernels.scale_by, dim=(k, h, w), inputs=[self.through], outputs=[self.radiance],
                  device=self.device)
        return self.radiance

    def _photon_shafts(self, photons) -> None:
        """The single scattering into the refracted rays from a photon pass: its E⊥ on
        ``camera.shaft_samples`` horizontal planes from the lowest trough down to just above the
        receivers' lowest point (``PhotonCaustics.slices``, at most :data:`PHOTON_SLICE_TEXELS`² texels over
        the patch), sampled at the rays' midpoints (linear between planes), with the phase
        function at the pass's direction refracted by still water."""
        dev = self.device
        h, w = self.cfg.height, self.cfg.width
        k = self.caustic.shape[0]
        pixels = h * w
        count = self.samples
        top = min(self.lowest_z, 0.0)
        lowest = self.receivers_bottom_z
        bottom = lowest + SLICE_FLOOR_GAP * (top - lowest)  # photons end on the floor, rounded either way
        step = (top - bottom) / max(count - 1, 1)
        planes = top - step * np.arange(count)
        resolution = min(self.config.caustics.map_resolution, PHOTON_SLICE_TEXELS)
        slices = photons.slices(planes, resolution)
        light = still_water_refraction(np.asarray(photons.light_dir, np.float64), self.ray_ior)
        ph = self.phase
        for n in range(self.samples):
            wp.launch(above_kernels.segment_samples, dim=(h, w),
                      inputs=[self.origin, self.direction, self.length, self.samples, n],
                      outputs=[self.points, self.views, self.along, self.piece], device=dev)
            wp.launch(above_kernels.slice_inscatter, dim=(pixels, k),
                      inputs=[slices, float(top), float(step), float(self.config.water.extent_m),
                              int(photons.periodic), wp.vec3(*light.astype(np.float32)), ph.kind, ph.g,
                              ph.angles_rad, ph.log_phase, ph.cone_phase, self.scattering_per_m,
                              photons.attenuation_per_m, self.points, self.views, self.along, self.piece],
                      outputs=[self.shafts.reshape((k, pixels))], device=dev)

    def finish(self, radiance: np.ndarray) -> np.ndarray:
        """The frame's image: the passes' ``radiance`` (K, H, W) plus the reflection and the dry rays."""
        return radiance + self.surface_radiance

    def gbuffer(self) -> dict[str, np.ndarray]:
        """The first receiver each pixel sees (below the surface, or in the air) on the host, for
        the last frame (the surface moves, so it is read back per frame)."""
        if self._gbuffer is None:
            depth = self.depth.numpy().copy()
            depth[depth >= 1.0e29] = np.inf
            self._gbuffer = {"position": self.position.numpy().copy(), "normal": self.normal.numpy().copy(),
                             "depth": depth, "receiver": self.receiver.numpy().copy(),
                             "face": self.face.numpy().copy()}
        return self._gbuffer
