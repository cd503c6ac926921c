"""The under-water pinhole camera (host side): G-buffer, photon caustic map, light shafts, shading.

The camera looks at the receivers from inside the water (the camera above the water, looking
through the refracting surface, is ``scene/above.py``; what a radiance sensor looking up at the
surface from below reads is the floor map's, ``floor.view_*``, ``caustics/view.py``).
Receivers are static, so the G-buffer is cast once per scene; each frame splats the photons into a
camera caustic map, draws their light shafts and shades (``kernels/scene/camera/`` has the
equations).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import warp as wp

from warpcaustics.config import CameraConfig
from warpcaustics.kernels.scene import camera as camera_kernels
from warpcaustics.optics.phase import PhaseFunction
from warpcaustics.scene.receivers import Receivers

if TYPE_CHECKING:
    from warpcaustics.caustics.photons import PhotonCaustics

DEPTH_TOLERANCE = 0.02
"""A photon counts as seen at a pixel if its distance is within 2 % of the G-buffer depth there."""


def pinhole(cfg: CameraConfig) -> camera_kernels.PinholeCamera:
    position = np.asarray(cfg.position_m, np.float64)
    forward = np.asarray(cfg.look_at_m, np.float64) - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(cfg.up, np.float64))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    cam = camera_kernels.PinholeCamera()
    cam.position = wp.vec3(*position.astype(np.float32))
    cam.right = wp.vec3(*right.astype(np.float32))
    cam.up = wp.vec3(*up.astype(np.float32))
    cam.forward = wp.vec3(*forward.astype(np.float32))
    cam.tan_half_fov = math.tan(math.radians(cfg.fov_deg) / 2.0)
    cam.aspect = cfg.width / cfg.height
    cam.width = cfg.width
    cam.height = cfg.height
    return cam


def pyramid_pixels(width: int, height: int) -> int:
    """Pixels of the light-shaft pyramid: all its levels, packed."""
    levels = camera_kernels.SHAFT_LEVELS
    return sum(-(-width // 2**level) * -(-height // 2**level) for level in range(levels))


def camera_bytes(cfg: CameraConfig, k: int) -> int:
    """Device memory of the camera buffers [bytes]."""
    pixels = cfg.width * cfg.height
    # position, normal, ray; depth, receiver, footprint, depth slack; caustic, shafts, raw shafts, radiance
    return pixels * (3 * 12 + 4 * 4 + 4 * k * 4) + 4 * k * pyramid_pixels(cfg.width, cfg.height)


class UnderwaterCamera:
    """A pinhole camera's buffers for one scene on one device."""

    def __init__(
        self,
        cfg: CameraConfig,
        receivers: Receivers,
        scattering_per_m: np.ndarray,
        phase: PhaseFunction,
        device: str,
    ):
        self.cfg = cfg
        self.device = device
        self.receivers = receivers
        self.phase = phase
        self.cam = pinhole(cfg)
        h, w = cfg.height, cfg.width
        k = receivers.albedo.shape[1]
        self.scattering_per_m = wp.array(
            np.asarray(scattering_per_m, np.float32), dtype=wp.float32, device=device
        )
        self.position = wp.empty((h, w), dtype=wp.vec3, device=device)
        self.normal = wp.empty((h, w), dtype=wp.vec3, device=device)
        self.depth = wp.empty((h, w), dtype=wp.float32, device=device)
        self.receiver = wp.empty((h, w), dtype=wp.int32, device=device)
        self.inv_footprint = wp.empty((h, w), dtype=wp.float32, device=device)
        self.depth_slack = wp.empty((h, w), dtype=wp.float32, device=device)
        self.rays = wp.empty((h, w), dtype=wp.vec3, device=device)
        self.caustic = wp.empty((k, h, w), dtype=wp.float32, device=device)
        """Irradiance on the receiver seen in each pixel (K, H, W) [W m^-2 nm^-1]."""
        self.shafts = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self.shafts_raw = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self.pyramid = wp.empty((k, pyramid_pixels(w, h)), dtype=wp.float32, device=device)
        self.radiance = wp.empty((k, h, w), dtype=wp.float32, device=device)
        self._gbuffer: dict[str, np.ndarray] | None = None
        self.shaft_threads = "tile" if wp.get_device(device).is_cpu else "pixel"
        """How the beams' volume pass is split: a thread per ``"pixel"`` (the GPU's form) or per
        ``"tile"`` (the CPU's: each tile's beam list is walked once). Same result to the bit."""
        wp.launch(
            camera_kernels.gbuffer,
            dim=(h, w),
            inputs=[self.cam, receivers.mesh.id, receivers.face_receiver],
            outputs=[
                self.position,
                self.normal,
                self.depth,
                self.receiver,
                self.inv_footprint,
                self.depth_slack,
                self.rays,
            ],
            device=device,
        )

    @property
    def position_z(self) -> float:
        return float(self.cfg.position_m[2])

    def render(self, photons: PhotonCaustics, photon_spacing_m: float, shafts: bool) -> wp.array3d:
        """Splat the photons of ``photons``' pass into the camera, add their shafts, shade: (K, H, W)
        radiance [W m^-2 sr^-1 nm^-1]."""
        dev = self.device
        k = photons.sun_irradiance.shape[0]
        count = photons.weight.shape[0]
        traced = photons.traced()
        self.caustic.zero_()
        wp.launch(
            camera_kernels.splat_photons,
            dim=(count, 9),
            inputs=[
                self.cam,
                traced,
                float(photon_spacing_m),
                self.receivers.face_receiver,
                self.receivers.face_normal,
                self.position,
                self.normal,
                self.receiver,
                self.depth,
                self.inv_footprint,
                self.depth_slack,
                DEPTH_TOLERANCE,
            ],
            outputs=[self.caustic],
            device=dev,
        )
        self.pyramid.zero_()
        if shafts:
            stride = photons.subdivisions**2  # one line per surface cell, carrying the cell's photons
            ph = self.phase
            wp.launch(
                camera_kernels.shaft_lines,
                dim=(count // stride, 9),
                inputs=[
                    self.cam,
                    traced,
                    stride,
                    float(photon_spacing_m * photons.subdivisions),
                    self.scattering_per_m,
                    ph.kind,
                    ph.g,
                    ph.angles_rad,
                    ph.log_phase,
                    ph.cone_phase,
                    self.depth,
                ],
                outputs=[self.pyramid],
                device=dev,
            )
        h, w = self.cfg.height, self.cfg.width
        wp.launch(
            camera_kernels.collapse_pyramid,
            dim=(k, h, w),
            inputs=[self.pyramid],
            outputs=[self.shafts_raw],
            device=dev,
        )
        wp.launch(
            camera_kernels.blur3, dim=(k, h, w), inputs=[self.shafts_raw], outputs=[self.shafts], device=dev
        )
        return self._shade(photons.attenuation_per_m)

    def render_beams(self, beams, shafts: bool) -> wp.array3d:
        """Light the receivers the camera sees by the beams of ``beams``' pass (point-in-beam on the
        G-buffer), add the scan-plane volume caustics, shade: (K, H, W) radiance."""
        from warpcaustics.caustics.beams import SCREEN_TILE_PIXELS
        from warpcaustics.caustics.tile_bins import TileBins
        from warpcaustics.kernels.caustics import beams as beam_kernels
        from warpcaustics.kernels.caustics.beams import bounds

        dev = self.device
        h, w = self.cfg.height, self.cfg.width
        k = beams.k
        pixels = h * w
        beams.points(
            self.position.reshape((pixels,)),
            self.normal.reshape((pixels,)),
            self.receiver.reshape((pixels,)),
            self.caustic.reshape((k, pixels)),
        )
        self.shafts.zero_()
        if shafts:
            copies = 3 if beams.periodic else 1  # the patch and its eight neighbours, as for photons
            items = beams.weight.shape[0] * copies * copies
            bins = getattr(self, "_screen_bins", None)
            if bins is None or bins.spans.shape[0] != items:
                grid = beam_kernels.TileGrid()
                grid.origin = wp.vec2(0.0, 0.0)
                grid.size = wp.vec2(float(SCREEN_TILE_PIXELS), float(SCREEN_TILE_PIXELS))
                grid.nx = -(-w // SCREEN_TILE_PIXELS)
                grid.ny = -(-h // SCREEN_TILE_PIXELS)
                grid.wrap = 0
                bins = self._screen_bins = TileBins(grid, items, dev).with_boxes()
                self._box_pixels = wp.empty(items, dtype=wp.float32, device=dev)
                self._pairs = wp.zeros(4, dtype=wp.int32, device=dev)
            self._pairs.zero_()
            wp.launch(
                beam_kernels.screen_spans,
                dim=items,
                inputs=[bins.grid, self.cam, beams.base, beams.direction, beams.end_m, beams.weight, copies,
                        beams.extent_m, getattr(bounds, beams.cfg.caustics.beam_bounds.name)],
                outputs=[bins.spans, bins.box_axis, bins.box_lo, bins.box_hi, self._box_pixels, self._pairs],
                device=dev,
            )
            bins.bin()
            sb = beam_kernels.ShaftBeams()
            sb.beams, sb.copies = beams.gather_beams(), copies
            sb.soft_fade_m = float(beams.cfg.caustics.beam_soft_fade_m)
            sb.scattering_per_m = self.scattering_per_m
            ph = self.phase
            sb.phase_kind, sb.hg_g, sb.cone_phase = ph.kind, ph.g, ph.cone_phase
            sb.angles_rad, sb.log_phase = ph.angles_rad, ph.log_phase
            per_tile = int(self.shaft_threads == "tile")
            wp.launch(
                beam_kernels.scan_plane_radiance,
                dim=(bins.grid.ny, bins.grid.nx) if per_tile else (h, w),
                inputs=[bins.screen_bins(SCREEN_TILE_PIXELS), self.cam, self.rays, self.depth, sb, per_tile],
                outputs=[self.shafts, self._pairs],
                device=dev,
            )
        return self._shade(beams.attenuation_per_m)

    def _shade(self, attenuation_per_m: wp.array) -> wp.array3d:
        """Radiance at the camera from the caustic map and the shafts of this frame."""
        k = self.caustic.shape[0]
        wp.launch(
            camera_kernels.shade,
            dim=(k, self.cfg.height, self.cfg.width),
            inputs=[self.receiver, self.depth, self.caustic, self.shafts, self.receivers.albedo_wp,
                    attenuation_per_m],
            outputs=[self.radiance],
            device=self.device,
        )
        return self.radiance

    def beam_fill(self) -> dict[str, float]:
        """Rasteriser fill of the last :meth:`render_beams` with shafts, as (pixel, beam copy) pairs:
        in the axis-aligned screen boxes of the beams' bounding volumes, in the tile lists, inside
        the oriented boxes (where the scan plane is computed), and with a real chord through the
        beam; and the beam copies whose prism (``caustics.beam_bounds``) fell back to the hull."""
        pairs = self._pairs.numpy()
        return {
            "box_pixels": float(self._box_pixels.numpy().astype(np.float64).sum()),
            "tile_pairs": int(pairs[0]),
            "oriented_box_pairs": int(pairs[1]),
            "inside_pairs": int(pairs[2]),
            "hull_fallbacks": int(pairs[3]),
        }

    def gbuffer(self) -> dict[str, np.ndarray]:
        """The G-buffer on the host. Receivers are static, so it is read back once and shared by
        every frame's result."""
        if self._gbuffer is None:
            depth = self.depth.numpy().copy()
            depth[depth >= 1.0e29] = np.inf
            self._gbuffer = {
                "position": self.position.numpy().copy(),
                "normal": self.normal.numpy().copy(),
                "depth": depth,
                "receiver": self.receiver.numpy().copy(),
            }
        return self._gbuffer
