"""Photon caustics (host side): emit, refract, intersect (BVH or Shah's iteration), deposit.

See ``warpcaustics/kernels/photons.py`` for the method. The stage owns its photon buffers and the
receivers' light view; both are reused from frame to frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.caustics.receiver_stage import CausticsSetup, PassCaustics, ReceiverStage, receiver_optics
from warpcaustics.config import Config, FloorShape, Intersection, PhotonSplat
from warpcaustics.kernels.caustics import fluxratio as floor_kernels
from warpcaustics.kernels.caustics import photon_footprints as footprint_kernels
from warpcaustics.kernels.caustics import photon_slices as slice_kernels
from warpcaustics.kernels.caustics import photons as photon_kernels
from warpcaustics.optics.refraction import still_water_refraction
from warpcaustics.scene.receivers import WALLS_ID
from warpcaustics.water import Surface

PHOTON_BYTES = 12 + 12 + 4 + 12 + 4 + 4 + 4
"""Per photon: origin, direction, weight, hit, face, water path before its last segment, splatted."""


def photon_count(cfg: Config, n: int, groups: int, periodic: bool) -> int:
    quads = n if periodic else n + 1
    return groups * quads * quads * cfg.caustics.photon_subdivisions**2


def photons_bytes(cfg: Config, n: int, k: int, groups: int, periodic: bool, face_count: int) -> int:
    """Device memory of the photon stage, receivers included [bytes]."""
    m = cfg.caustics.map_resolution
    r = cfg.caustics.newton_buffer_resolution if cfg.caustics.intersection is Intersection.NEWTON else 0
    carried = 4 if cfg.caustics.bounces > 1 else 0  # the weight left after the bounces
    footprint = cfg.caustics.photon_splat is PhotonSplat.FOOTPRINT
    slices = cfg.camera.enabled and cfg.camera.position_m[2] > 0.0 and cfg.caustics.shafts
    splat = (4 * k if footprint or slices else 0)  # each photon's flux per band: footprints, slices
    return (
        photon_count(cfg, n, groups, periodic) * (PHOTON_BYTES + carried + splat)
        + (k * m * m * 4 if footprint else 0)
        + 2 * k * m * m * 4
        + m * m * 4
        + r * r * 16
        + face_count * (k * 4 + 4 + 12 + 64)
        + n * n * 4
    )


@dataclass
class PhotonStats:
    emitted: int
    """Photons launched (all index groups)."""
    carrying: int
    """Photons with non-zero weight (lit from the front, refracted downwards)."""
    landed: int
    """Photons that found a receiver."""
    reflected_w_nm: np.ndarray | None = None
    """``caustics.bounces`` > 1: (K,) flux reflected at glass receivers' faces (Fresnel) [W nm⁻¹],"""
    beyond_limit_w_nm: np.ndarray | None = None
    """that met a glass or specular receiver after its last bounce,"""
    trapped_w_nm: np.ndarray | None = None
    """still inside a glass receiver after its internal reflections,"""
    missed_w_nm: np.ndarray | None = None
    """and that met no receiver after a bounce; all at the point they left, attenuated on the way."""


def light_view_direction(sun_dir: np.ndarray, group_ior: np.ndarray) -> np.ndarray:
    """The direction the Newton light view looks from: towards the sun as seen under still water,
    i.e. minus the sun's refracted direction (mean index of the groups).

    The receivers all lie in the water, where the photons run near this direction, so Shah's
    iteration converges where a view along the sun in air does not: on the sphere of
    tests/test_photons.py 98 % of the photons end within a texel of their exact hit, against 86 %
    (docs/validation.md). A pool's walls are passed from outside (``render_light_view``)."""
    return -still_water_refraction(sun_dir, float(np.mean(group_ior)))


def light_view_frame(points: np.ndarray, view_dir: np.ndarray, resolution: int):
    """(origin, u, v, texel) of an orthographic view along ``view_dir`` covering all ``points``;
    u, v ⊥ ``view_dir`` and u × v = ``view_dir``."""
    s = np.asarray(view_dir, np.float64)
    helper = np.array([0.0, 0.0, 1.0]) if abs(s[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, s)
    u /= np.linalg.norm(u)
    v = np.cross(s, u)
    a, b = points @ u, points @ v
    span = max(np.ptp(a), np.ptp(b))
    texel = span * (1.0 + 2.0 / resolution) / resolution
    origin = u * (a.min() - texel) + v * (b.min() - texel)
    return origin, u, v, texel


class PhotonCaustics(PassCaustics):
    """The photon stage's device buffers for one scene, reused from pass to pass and frame to frame."""

    timing_name = "photons"
    stats_key = "photon_stats"

    def __init__(self, setup: CausticsSetup):
        """The light view for the Newton guesses looks along the sun's centre's refracted direction."""
        cfg, receivers, n, device = setup.cfg, setup.receivers, setup.n, setup.device
        periodic, group_ior = setup.periodic, setup.group_ior
        self.cfg = cfg
        self.device = device
        self.receivers = receivers
        self.periodic = periodic
        self.n = n
        self.subdivisions = cfg.caustics.photon_subdivisions
        self.quads = n if periodic else n + 1
        groups = len(group_ior)
        self.groups = groups
        self.ior = wp.array(np.asarray(group_ior, np.float32), dtype=wp.float32, device=device)
        """Refractive index of each index group (one, or one per band with dispersion)."""
        count = photon_count(cfg, n, groups, periodic)
        self.photons_per_group = count // groups
        k = len(setup.sun_irradiance)
        m = cfg.caustics.map_resolution
        self.sun_irradiance = wp.array(
            np.asarray(setup.sun_irradiance, np.float32), dtype=wp.float32, device=device
        )
        """The current pass's irradiance (K,) on a plane perpendicular to its light [W m^-2 nm^-1]."""
        self.attenuation_per_m = wp.array(
            np.asarray(setup.attenuation_per_m, np.float32), dtype=wp.float32, device=device
        )
        self.origin = wp.empty(count, dtype=wp.vec3, device=device)
        self.direction = wp.empty(count, dtype=wp.vec3, device=device)
        self.weight = wp.empty(count, dtype=wp.float32, device=device)
        """A⊥·T per photon [m²]."""
        self.hit = wp.empty(count, dtype=wp.vec3, device=device)
        self.face = wp.empty(count, dtype=wp.int32, device=device)
        self.texels = wp.empty((m, m, k), dtype=wp.float32, device=device)
        self.irradiance = wp.empty((k, m, m), dtype=wp.float32, device=device)
        """Floor spectral irradiance (K, M, M) [W m^-2 nm^-1] on the floor's true area."""
        other_faces = max(receivers.face_count - receivers.floor_face_count, 1)
        self.face_flux = wp.empty((other_faces, k), dtype=wp.float32, device=device)
        """Flux on each non-floor face (F_other, K) [W nm^-1]."""
        self.floor_inv_area = wp.array(
            (1.0 / receivers.floor_texel_area_m2).astype(np.float32), dtype=wp.float32, device=device
        )
        sun = np.asarray(setup.sun_dir, np.float64)
        self.light_dir = wp.vec3(*sun.astype(np.float32))  # the photons' direction (set per pass)
        # A flat-floor plane for moving periodic photons by whole periods before they are traced.
        self.plane_z = -cfg.floor.depth_m
        self.flat_floor = cfg.floor.shape is FloorShape.FLAT
        self.view = self._light_view(
            light_view_direction(sun, group_ior),
            cfg.caustics.newton_buffer_resolution if cfg.caustics.intersection is Intersection.NEWTON else 1,
        )
        self.newton_iterations = (
            cfg.caustics.newton_iterations if cfg.caustics.intersection is Intersection.NEWTON else -1
        )
        self.splatted = wp.zeros(count, dtype=wp.int32, device=device)
        """1 where a photon was spread over its footprint (``photon_splat``): on the floor map, or
        over the faces of another receiver."""
        self.footprint = self.splat_flux = self.coarse_count = self._slices = None
        if cfg.caustics.photon_splat is PhotonSplat.FOOTPRINT:
            self._footprint_buffers(cfg, count, k, m)
        self.path_before = wp.zeros(count, dtype=wp.float32, device=device)
        """Water path before each photon's last segment [m] (0 without bounces)."""
        self.carried = self.weight
        """What each photon carries onto its receiver: its weight, less what the bounces left."""
        self.optics = None
        if cfg.caustics.bounces > 1:
            self.carried = wp.empty(count, dtype=wp.float32, device=device)
            self.tallies = wp.zeros((photon_kernels.TALLIES, k), dtype=wp.float64, device=device)
            self.optics = receiver_optics(cfg, receivers, group_ior, device)

    def _footprint_buffers(self, cfg: Config, count: int, k: int, m: int) -> None:
        """The footprint splats' map (irradiance per horizontal texel area), per-photon flux, and
        the floor map's frame (the whole patch, wrapping on a periodic sea)."""
        dev = self.device
        self.footprint = wp.empty((m, m, k), dtype=wp.float32, device=dev)
        self.splat_flux = wp.empty((count, 1, 1, k), dtype=wp.float32, device=dev)
        self.coarse_count = wp.zeros(1, dtype=wp.int32, device=dev)
        self.floor_map = self._patch_map(m)
        self.spacing_m = cfg.water.extent_m / self.n / self.subdivisions

    def _patch_map(self, resolution: int) -> floor_kernels.FloorMap:
        """The frame of a map of ``resolution``² texels over the whole patch (wrapping on a periodic
        sea)."""
        extent = self.cfg.water.extent_m
        fm = floor_kernels.FloorMap()
        fm.origin = wp.vec2(-0.5 * extent, -0.5 * extent)
        fm.centre = wp.vec2(0.0, 0.0)
        fm.scale = resolution / extent
        fm.wrap = int(self.periodic)
        fm.max_clipped = floor_kernels.MAX_CLIPPED_TEXELS
        return fm

    def _light_view(self, view_dir: np.ndarray, resolution: int) -> photon_kernels.LightView:
        # The view needs the receivers where photons land: on a periodic sea that is the patch
        # (photons are moved by whole periods first), not the floor's margin beyond it.
        points = self.receivers.points
        if self.periodic:
            reach = 0.55 * self.cfg.water.extent_m
            points = points[
                np.all(np.abs(points[:, :2]) <= reach, axis=1)
                | (np.arange(len(points)) >= self.receivers.floor_vertex_count)
            ]
        origin, u, v, texel = light_view_frame(points, view_dir, resolution)
        view = photon_kernels.LightView()
        view.origin = wp.vec3(*origin.astype(np.float32))
        view.u = wp.vec3(*u.astype(np.float32))
        view.v = wp.vec3(*v.astype(np.float32))
        view.texel_m = float(texel)
        view.positions = wp.empty((resolution, resolution), dtype=wp.vec3, device=self.device)
        view.faces = wp.empty((resolution, resolution), dtype=wp.int32, device=self.device)
        if resolution > 1:
            distance = float(np.abs(self.receivers.points @ view_dir).max() + 1.0)
            wp.launch(
                photon_kernels.render_light_view,
                dim=(resolution, resolution),
                inputs=[self.receivers.mesh.id, self.receivers.face_receiver, WALLS_ID,
                        wp.vec3(*view_dir.astype(np.float32)), distance, view],
                device=self.device,
            )
        return view

    def trace(self, surface: Surface, visible: wp.array2d, direction: np.ndarray,
              irradiance: np.ndarray) -> wp.array3d:
        """Emit, trace and deposit every photon of a pass; fills :attr:`irradiance` and
        :attr:`face_flux`. One direction per pass: a photon's lattice neighbours must share its
        direction, or the camera's lattice splats draw a pattern."""
        self.light_dir = wp.vec3(*np.asarray(direction, np.float32))
        self.sun_irradiance.assign(np.asarray(irradiance, np.float32))
        dev = self.device
        s = self.subdivisions
        ior = self.ior
        extent = float(surface.extent_m)
        wp.launch(
            photon_kernels.emit_photons,
            dim=(self.groups, self.quads, self.quads, s * s),
            inputs=[
                surface.positions,
                surface.normals,
                visible,
                ior,
                self.light_dir,
                s,
                extent,
                int(self.periodic),
            ],
            outputs=[self.origin, self.direction, self.weight],
            device=dev,
        )
        if self.optics is None:
            wp.launch(
                photon_kernels.trace_photons,
                dim=self.weight.shape[0],
                inputs=[self.receivers.mesh.id, self.view, self.receivers.face_receiver,
                        self.newton_iterations, extent, int(self.periodic), float(self.plane_z), self.origin,
                        self.direction, self.weight],
                outputs=[self.hit, self.face],
                device=dev,
            )
        else:
            self.tallies.zero_()
            wp.launch(
                photon_kernels.trace_bounces,
                dim=self.weight.shape[0],
                inputs=[self.receivers.mesh.id, self.receivers.face_receiver, self.optics, extent,
                        int(self.periodic), float(self.plane_z), self.sun_irradiance, self.attenuation_per_m,
                        self.photons_per_group, self.sun_irradiance.shape[0] // self.groups, self.origin,
                        self.direction, self.weight],
                outputs=[self.carried, self.path_before, self.hit, self.face, self.tallies],
                device=dev,
            )
        self.texels.zero_()
        self.face_flux.zero_()
        traced = self.traced()
        if self.footprint is not None:
            self.footprint.zero_()
            flat_plane = self.flat_floor and self.cfg.caustics.bounces == 1
            wp.launch(footprint_kernels.splat_footprints, dim=self.weight.shape[0],
                      inputs=[traced, self.receivers.face_receiver, self.receivers.face_normal,
                              self.spacing_m, self.floor_map, surface.positions, int(flat_plane),
                              float(self.plane_z), WALLS_ID],
                      outputs=[self.splat_flux, self.footprint, self.face_flux, self.coarse_count,
                               self.splatted], device=dev)
            if self.receivers.face_count > self.receivers.floor_face_count:
                mesh = self.receivers.mesh
                wp.launch(footprint_kernels.splat_receiver_footprints, dim=self.weight.shape[0],
                          inputs=[traced, mesh.id, mesh.points, mesh.indices, self.receivers.face_receiver,
                                  self.receivers.face_normal, self.spacing_m, self.floor_map,
                                  surface.positions, int(flat_plane), float(self.plane_z), WALLS_ID],
                          outputs=[self.splat_flux, self.footprint, self.face_flux, self.coarse_count,
                                   self.splatted], device=dev)
        wp.launch(
            photon_kernels.deposit_photons,
            dim=self.weight.shape[0],
            inputs=[traced, self.floor_inv_area, self.splatted],
            outputs=[self.texels, self.face_flux],
            device=dev,
        )
        m = self.texels.shape[0]
        if self.footprint is not None:
            wp.launch(footprint_kernels.add_footprints, dim=(m, m, self.texels.shape[2]),
                      inputs=[self.footprint, (self.cfg.water.extent_m / m) ** 2, self.floor_inv_area],
                      outputs=[self.texels], device=dev)
        wp.launch(
            floor_kernels.texels_to_bands,
            dim=(m, m),
            inputs=[self.texels],
            outputs=[self.irradiance],
            device=dev,
        )
        return self.irradiance

    def slices(self, planes_z: np.ndarray, resolution: int) -> wp.array4d:
        """(S, R, R, K) the pass's E⊥ [W m^-2 nm^-1] on the horizontal planes ``planes_z`` over the
        patch (R² texels; wrapping on a periodic sea): where each photon's last segment crosses a
        plane, spread over its lattice cell there (``kernels/caustics/photon_slices.py``)."""
        dev = self.device
        k = self.sun_irradiance.shape[0]
        shape = (len(planes_z), resolution, resolution, k)
        if self._slices is None or self._slices.shape != shape:  # kept from pass to pass
            self._slices = wp.zeros(shape, dtype=wp.float32, device=dev)
        else:
            self._slices.zero_()
        if self.splat_flux is None:  # texel deposits on the floor: the slices' own
            self.splat_flux = wp.empty((self.weight.shape[0], 1, 1, k), dtype=wp.float32, device=dev)
            self.coarse_count = wp.zeros(1, dtype=wp.int32, device=dev)
        out = self._slices
        frame = self._patch_map(resolution)
        traced = self.traced()
        spacing = self.cfg.water.extent_m / self.n / self.subdivisions
        for s, z in enumerate(planes_z):
            wp.launch(slice_kernels.splat_slice, dim=self.weight.shape[0],
                      inputs=[traced, float(z), spacing, frame],
                      outputs=[self.splat_flux, out[s], self.coarse_count], device=dev)
        return out

    def traced(self) -> photon_kernels.Photons:
        """The photons of the pass being traced as the deposit and the camera read them."""
        ph = photon_kernels.Photons()
        for name in ("hit", "face", "origin", "direction", "path_before", "photons_per_group",
                     "sun_irradiance", "attenuation_per_m", "quads", "subdivisions"):
            setattr(ph, name, getattr(self, name))
        ph.weight = self.carried
        ph.wavelengths_per_group = self.sun_irradiance.shape[0] // self.groups
        ph.extent_m, ph.periodic = float(self.cfg.water.extent_m), int(self.periodic)
        ph.floor_face_count = self.receivers.floor_face_count
        return ph

    def _render_camera(self, camera, shafts: bool) -> None:
        """Splat this pass's photons into ``camera``'s image, each over its lattice cell; a camera
        above the water looks the points its refracted rays meet up in the pass's maps, and its
        shafts in the pass's slices of the water (:meth:`slices`)."""
        if getattr(camera, "above_water", False):
            camera.render_photons(self, shafts)
            return
        spacing = self.cfg.water.extent_m / self.n / self.subdivisions
        camera.render(self, spacing, shafts)

    def _face_flux_w_nm(self) -> np.ndarray:
        """(F_other, K) flux on each non-floor face [W nm^-1] (float64)."""
        other = self.receivers.face_count - self.receivers.floor_face_count
        return self.face_flux.numpy()[:other].astype(np.float64)

    def _transmitted_flux(self) -> np.ndarray:
        """(K,) flux the photons carry into the water before attenuation [W nm^-1] (float64)."""
        w = self.weight.numpy().astype(np.float64).reshape(self.groups, -1).sum(axis=1)
        e = self.sun_irradiance.numpy().astype(np.float64)
        return e * np.repeat(w, len(e) // self.groups)

    def _stats(self) -> PhotonStats:
        w = self.weight.numpy()
        stats = PhotonStats(
            emitted=len(w),
            carrying=int(np.count_nonzero(w > 0)),
            landed=int(np.count_nonzero(self.face.numpy() >= 0)),
        )
        if self.optics is not None:
            t = self.tallies.numpy()
            stats.reflected_w_nm = t[photon_kernels.REFLECTED]
            stats.beyond_limit_w_nm = t[photon_kernels.BEYOND_LIMIT]
            stats.trapped_w_nm = t[photon_kernels.TRAPPED]
            stats.missed_w_nm = t[photon_kernels.MISSED]
        return stats


class PhotonStage(ReceiverStage):
    """``photons``: photon splatting with the exact or Shah's Newton intersection."""

    name = "photons"

    def make_caustics(self, setup: CausticsSetup) -> list[PassCaustics]:
        return [PhotonCaustics(setup)]

    @classmethod
    def caustics_bytes(cls, scene, n: int, k: int, groups: int, faces: int) -> int:
        return photons_bytes(scene.config, n, k, groups, scene.config.water.periodic, faces)
