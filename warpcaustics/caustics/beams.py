"""Beam caustics (host side): build the warped beam volumes, bin them into tiles, gather.

See ``kernels/caustics/beams/`` for the method. Horizontal tile grids over the patch serve
the floor map (blocks of texels) and every query at a point (receiver faces, the receiver points
the camera sees); the camera's screen tiles serve the view rays of the volume caustics. The stage
owns its buffers and reuses them from frame to frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.caustics.beam_bounces import BouncedBeams, bounced_capacity
from warpcaustics.caustics.receiver_stage import (
    CausticsSetup,
    PassCaustics,
    ReceiverStage,
    unlit_receivers,
)
from warpcaustics.caustics.tile_bins import TileBins
from warpcaustics.config import BeamInterpolation, Config, FloorShape
from warpcaustics.kernels.caustics import beams as beam_kernels
from warpcaustics.kernels.scene.camera import PinholeCamera
from warpcaustics.scene.receivers import WALL_FACES, Receivers, floor_relief_height
from warpcaustics.water import Surface

BEAM_BYTES = 3 * 12 + 3 * 12 + 3 * 4 + 3 * 4 + 4 * 12 + 4 + 12 + 16
"""Per beam: base vertices, directions, transmittances, edge ends, end and base planes, weight,
A(z), span."""

FACE_SUBDIVISIONS = 4
"""Irradiance on a receiver face is the mean over the centroids of its FACE_SUBDIVISIONS²
congruent sub-triangles (a face cut by a shadow or the water line is integrated to ~1/16)."""

FACE_SAMPLES = FACE_SUBDIVISIONS**2

SCREEN_TILE_PIXELS = 8

REFINE_END_JUMP = 0.1
"""An adaptive quad is split where its corners' lengths to the receivers differ by more than 10 %."""

REFINE_MAX_PIXELS = 16.0
"""An adaptive quad is split where its beam covers more than this many pixels of the camera."""
"""Side of a screen tile of the volume-caustics rasteriser [pixels]."""


BEAM_ARRAYS = ("base", "direction", "transmit", "end_m", "ends", "weight", "area_coef")
"""The per-beam buffers a primary beam fills."""


def beam_count(n: int, groups: int, periodic: bool) -> int:
    quads = n if periodic else n + 1
    return groups * quads * quads * 2


TILE_CELLS = 2
"""A horizontal tile spans about this many surface cells: a beam's section (about a cell, more or
less as the light focuses or spreads) touches few tiles, and a tile's list stays short."""


def texels_per_tile(m: int, n: int) -> int:
    """Floor texels per side of a horizontal tile: the largest power of two up to TILE_CELLS surface
    cells (N per side) that divides M (the tiles must tile a periodic patch exactly)."""
    t = 1
    while t * 2 <= max(TILE_CELLS * m / n, 1.0) and m % (t * 2) == 0:
        t *= 2
    return t


def beams_bytes(
    cfg: Config, n: int, k: int, groups: int, periodic: bool, face_count: int, sampled_faces: int
) -> int:
    """Device memory of the beam stage, receivers and floor map included (not the tile lists, whose
    length depends on the frame: about one entry per beam and tile it touches) [bytes].
    ``face_count``: faces of the receivers' BVH; ``sampled_faces``: those that are not floor. With
    ``caustics.bounces`` > 1, the bounced beams' first buffers (``bounced_capacity``; they grow by
    BEAM_BYTES + 16 bytes a beam when a frame needs more) and the bounce pass's per-primary arrays."""
    m = cfg.caustics.map_resolution
    primaries = beam_count(n, groups, periodic)
    beams = primaries
    bounce_bytes = 0
    if cfg.caustics.bounces > 1:
        beams += bounced_capacity(primaries)
        # each beam's edges' paths before its base; each bounced slot's source; need, slots, offset
        bounce_bytes = 12 * beams + 4 * (beams - primaries) + 12 * primaries
    return (
        beams * BEAM_BYTES
        + bounce_bytes
        + 2 * k * m * m * 4
        + 2 * (m + 1) * (m + 1) * 4
        + face_count * 84
        + sampled_faces * (k * 4 + FACE_SAMPLES * (k * 4 + 28))
        + n * n * 4
        + 8 * beams
        + 16 * beams  # the second tile grid's spans
        + (beams * (9 if periodic else 1) * 48 if cfg.camera.enabled else 0)  # screen spans, boxes, lists
        + (16 * n * n if cfg.caustics.beam_levels else 0)  # adaptive: vertex directions and lengths
    )


@dataclass
class BeamStats:
    beams: int
    """Beams built (all index groups)."""
    carrying: int
    """Beams with flux (lit from the front, refracted downwards at some vertex)."""
    dropped: int
    """Beams dropped: facing away from the sun, total internal reflection or degenerate."""
    tile_entries: int
    """Entries of the floor's horizontal tile lists (beam × tile pairs)."""
    bounced: int = 0
    """``caustics.bounces`` > 1: bounced beams built (``kernels/caustics/beams/bounces.py``),"""
    parted: int = 0
    """beams whose light met a glass or specular receiver but whose edges then parted (their light
    past it is not carried on),"""
    rising: int = 0
    """and bounced beams dropped because an edge leaves upwards."""


def _horizontal_grid(extent_m: float, tiles: int, periodic: bool) -> beam_kernels.TileGrid:
    """tiles × tiles tiles over the patch (wrapping on a periodic sea)."""
    grid = beam_kernels.TileGrid()
    grid.origin = wp.vec2(-0.5 * extent_m, -0.5 * extent_m)
    size = extent_m / tiles
    grid.size = wp.vec2(size, size)
    grid.nx = tiles
    grid.ny = tiles
    grid.wrap = int(periodic)
    return grid


def face_samples(receivers: Receivers) -> tuple[np.ndarray, np.ndarray]:
    """Sample points and unit normals of the non-floor faces: the centroids of each face's
    FACE_SUBDIVISIONS² congruent sub-triangles (equal areas), face-major."""
    from warpcaustics.reference import subtriangle_centroids

    tris = receivers.points[receivers.triangles[receivers.floor_face_count :]]
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    uv, _ = subtriangle_centroids(FACE_SUBDIVISIONS)
    points = a[:, None] + uv[None, :, 0, None] * (b - a)[:, None] + uv[None, :, 1, None] * (c - a)[:, None]
    cross = np.cross(b - a, c - a)
    normal = cross / np.maximum(np.linalg.norm(cross, axis=-1, keepdims=True), 1e-30)
    return points.reshape(-1, 3), np.repeat(normal, FACE_SAMPLES, axis=0)


class BeamCaustics(PassCaustics):
    """The beam stage's device buffers for one scene, reused from pass to pass and frame to frame."""

    timing_name = "beams"
    stats_key = "beam_stats"

    def __init__(self, setup: CausticsSetup):
        cfg, receivers, n, device = setup.cfg, setup.receivers, setup.n, setup.device
        periodic, group_ior, relief = setup.periodic, setup.group_ior, setup.relief
        self.cfg = cfg
        self.device = device
        self.receivers = receivers
        self.periodic = periodic
        self.quads = n if periodic else n + 1
        self.groups = len(group_ior)
        self.ior = wp.array(np.asarray(group_ior, np.float32), dtype=wp.float32, device=device)
        count = beam_count(n, self.groups, periodic)
        self.beams_per_group = count // self.groups
        self.primary_slots = count
        """Slots of the primary beams; the bounced beams follow them."""
        self.bounces = None
        if cfg.caustics.bounces > 1:
            self.bounces = BouncedBeams(cfg, receivers, group_ior, count, device)
        """Light through glass and off mirrors (``caustics/beam_bounces.py``)."""
        k = len(setup.sun_irradiance)
        self.k = k
        m = cfg.caustics.map_resolution
        self.m = m
        self.extent_m = float(cfg.water.extent_m)
        self.sun_irradiance = wp.array(
            np.asarray(setup.sun_irradiance, np.float32), dtype=wp.float32, device=device
        )
        """The current pass's irradiance (K,) on a plane perpendicular to its light [W m^-2 nm^-1]."""
        self.attenuation_per_m = wp.array(
            np.asarray(setup.attenuation_per_m, np.float32), dtype=wp.float32, device=device
        )
        self.sun_dir = wp.vec3(*np.asarray(setup.sun_dir, np.float32))
        """The current pass's light direction."""
        self.smooth = cfg.caustics.beam_interpolation is BeamInterpolation.SMOOTH
        self.plane_z = -cfg.floor.depth_m
        self.unlit_receiver = wp.array(unlit_receivers(cfg, receivers), dtype=wp.int32, device=device)
        self.no_source = wp.zeros(1, dtype=wp.int32, device=device)
        """``Beams.source`` without bounces (never read: there are no bounced beams)."""
        self.dropped = wp.zeros(1, dtype=wp.int32, device=device)
        self.texels_per_tile = texels_per_tile(m, n)
        self.grids = (_horizontal_grid(self.extent_m, m // self.texels_per_tile, periodic),
                      _horizontal_grid(self.extent_m, max(n // TILE_CELLS, 1), periodic))
        """The floor's and the points' horizontal tile grids."""
        self.flat_floor = cfg.floor.shape is FloorShape.FLAT
        self.allocate(count + (self.bounces.capacity if self.bounces else 0))
        self.irradiance = wp.empty((k, m, m), dtype=wp.float32, device=device)
        """Floor spectral irradiance (K, M, M) [W m^-2 nm^-1] on the floor's true area."""
        coords = np.arange(m + 1) * (self.extent_m / m) - 0.5 * self.extent_m
        cx, cy = np.meshgrid(coords, coords)
        corner_z = floor_relief_height(cfg.floor, relief, self.extent_m, cx, cy)
        self.floor_z_range = (float(corner_z.min()), float(corner_z.max()))
        self.corner_z = wp.array(corner_z.astype(np.float32), dtype=wp.float32, device=device)
        """Floor height at the texel corners (M+1, M+1) [m]: the floor mesh's vertices."""
        self.texel_area = wp.array(
            receivers.floor_texel_area_m2.astype(np.float32), dtype=wp.float32, device=device
        )
        other = receivers.face_count - receivers.floor_face_count
        self.face_count = other
        self.face_flux = wp.zeros((max(other, 1), k), dtype=wp.float32, device=device)
        """Flux on each non-floor face (F_other, K) [W nm^-1]."""
        if other:
            points, normals = face_samples(receivers)
            self.face_points = wp.array(points.astype(np.float32), dtype=wp.vec3, device=device)
            self.face_normals = wp.array(normals.astype(np.float32), dtype=wp.vec3, device=device)
            ids = np.repeat(receivers.face_receiver_np[receivers.floor_face_count :], FACE_SAMPLES)
            self.face_ids = wp.array(ids.astype(np.int32), dtype=wp.int32, device=device)
            """Each sample's receiver id (glass and mirror faces gather nothing)."""
            self.face_values = wp.empty((k, len(points)), dtype=wp.float32, device=device)
        self.occluders = (
            (not periodic) or bool(receivers.face_count - receivers.floor_face_count) or (not self.flat_floor)
        )
        """Whether anything but a flat floor can shadow a receiver point (then shadow rays decide)."""
        lo, hi = receivers.bounds()
        self.query_z = (float(lo[2]), float(hi[2]))
        self.levels = cfg.caustics.beam_levels
        if self.levels and self.smooth:
            raise ValueError(
                "smooth interpolation needs the uniform grid of beams (caustics.beam_levels = 0)"
            )
        quads = self.quads
        uniform = np.stack(np.meshgrid(np.arange(quads), np.arange(quads)), -1).reshape(-1, 2)
        self.uniform_leaves = wp.array(
            np.concatenate([uniform, np.zeros((len(uniform), 1), int)], 1).astype(np.int32),
            dtype=wp.vec3i,
            device=device,
        )
        """Every quad at level 0, row-major: the uniform grid."""
        self.leaf_count = quads * quads
        self.camera = None
        """The camera whose screen footprint the refinement limits (set by the renderer)."""
        if self.levels and n % (1 << self.levels):
            from warpcaustics.errors import ConfigError

            raise ConfigError(
                f"caustics.beam_levels = {self.levels} needs a water resolution divisible by "
                f"{1 << self.levels} (it is {n}); lower caustics.beam_levels"
            )
        if self.levels:
            self.refine_ior = float(group_ior[0])
            """Index the refinement criteria refract with (the first group's)."""
            self.vertex_direction = wp.empty((n, n), dtype=wp.vec3, device=device)
            self.vertex_length = wp.empty((n, n), dtype=wp.float32, device=device)
            self.tolerance_m = cfg.caustics.beam_tolerance * self.extent_m / n

    def allocate(self, slots: int) -> None:
        """Beam buffers and tile bins for ``slots`` beams. When the bounced beams' region grows
        within a frame, the primaries already built are kept."""
        dev = self.device
        kept = {name: getattr(self, name) for name in BEAM_ARRAYS if hasattr(self, name)}
        self.base = wp.empty((slots, 3), dtype=wp.vec3, device=dev)
        self.direction = wp.empty((slots, 3), dtype=wp.vec3, device=dev)
        self.transmit = wp.empty((slots, 3), dtype=wp.float32, device=dev)
        self.end_m = wp.empty((slots, 3), dtype=wp.float32, device=dev)
        self.ends = wp.empty((slots, 4), dtype=wp.vec3, device=dev)
        """Per beam: a point of its end plane, the plane's unit normal along the beam, the unit mean
        edge direction, the base plane's unit normal (``kernels/caustics/beams/build.py fill_ends``)."""
        self.weight = wp.zeros(slots, dtype=wp.float32, device=dev)
        """A⊥ per beam [m²] (0: dropped)."""
        self.area_coef = wp.empty(slots, dtype=wp.vec3, device=dev)
        self.before = wp.zeros((slots if self.bounces else 1, 3), dtype=wp.float32, device=dev)
        """A bounced beam's edges' water paths before its base [m]."""
        for name, old in kept.items():
            new = getattr(self, name)
            per_beam = old.size // old.shape[0]
            wp.copy(new, old, count=self.primary_slots * per_beam)
        self.floor_bins = TileBins(self.grids[0], slots, dev)
        """Bins of the sections over the floor's heights (the clipped-texel map)."""
        self.point_bins = TileBins(self.grids[1], slots, dev)
        """Bins of each beam's whole length (receiver points at any height)."""
        self.volume_bins = None

    def attach_camera(self, camera) -> None:
        """Refine adaptive beams near ``camera``'s screen footprint."""
        self.camera = camera

    def _render_camera(self, camera, shafts: bool) -> None:
        """Shade ``camera``'s image with this pass's beams (and their shafts)."""
        camera.render_beams(self, shafts)

    # --- per frame --------------------------------------------------------------------------

    def trace(self, surface: Surface, visible: wp.array2d, direction: np.ndarray,
              irradiance: np.ndarray) -> wp.array3d:
        """Build and bin a pass's beams; fill :attr:`irradiance` (floor) and :attr:`face_flux`."""
        self.sun_dir = wp.vec3(*np.asarray(direction, np.float32))
        self.sun_irradiance.assign(np.asarray(irradiance, np.float32))
        dev = self.device
        self.dropped.zero_()
        leaves = self.uniform_leaves if not self.levels else self._refine(surface)
        self.leaf_count = leaves.shape[0]
        self.beams_per_group = 2 * self.leaf_count
        if self.levels:
            self.weight.zero_()  # slots past this frame's beams carry nothing
        wp.launch(
            beam_kernels.build_beams,
            dim=(self.groups, self.leaf_count, 2),
            inputs=[
                surface.positions,
                surface.normals,
                visible,
                self.ior,
                self.sun_dir,
                self.extent_m,
                int(self.periodic),
                float(self.plane_z),
                self.receivers.mesh.id,
                leaves,
            ],
            outputs=[
                self.base,
                self.direction,
                self.transmit,
                self.end_m,
                self.ends,
                self.weight,
                self.area_coef,
                self.dropped,
            ],
            device=dev,
        )
        if self.bounces:
            self.bounces.build(self)
        self._points_binned = False
        self._volume_binned = False
        k, m = self.k, self.m
        self._bin_horizontal(self.floor_bins, *self.floor_z_range)
        wp.launch(
            beam_kernels.floor_texels,
            dim=(m, m),
            inputs=[
                *self.floor_bins.inputs(),
                self.texels_per_tile,
                self.gather_beams(),
                self.corner_z,
                self.texel_area,
            ],
            outputs=[self.irradiance.reshape((k, m * m))],
            device=dev,
        )
        if self.face_count:
            self.points(self.face_points, self.face_normals, self.face_ids, self.face_values)
        return self.irradiance

    def _refine(self, surface: Surface) -> wp.array:
        """Leaf quads (qx, qy, level) of the adaptive beams: from quads of 2^levels cells, split by
        ``refine_quads`` level by level down to single cells. Leaves come sorted (level, then row),
        so the beams do not depend on the order the device finds them in."""
        dev = self.device
        n = surface.resolution
        wp.launch(
            beam_kernels.vertex_rays,
            dim=(n, n),
            inputs=[
                surface.positions,
                surface.normals,
                self.refine_ior,
                self.sun_dir,
                self.extent_m,
                float(self.plane_z),
                self.receivers.mesh.id,
            ],
            outputs=[self.vertex_direction, self.vertex_length],
            device=dev,
        )
        top = self.levels
        q = n >> top
        grid = np.stack(np.meshgrid(np.arange(q), np.arange(q)), -1).reshape(-1, 2)
        active = np.concatenate([grid, np.full((len(grid), 1), top)], 1).astype(np.int32)
        leaves = []
        cam = self.camera
        for level in range(top, 0, -1):
            if not len(active):
                break
            quads = wp.array(active, dtype=wp.vec3i, device=dev)
            split = wp.zeros(len(active), dtype=wp.int32, device=dev)
            wp.launch(
                beam_kernels.refine_quads,
                dim=len(active),
                inputs=[
                    quads,
                    surface.positions,
                    self.vertex_direction,
                    self.vertex_length,
                    float(self.tolerance_m),
                    REFINE_END_JUMP,
                    self.extent_m,
                    int(cam is not None),
                    cam.cam if cam is not None else PinholeCamera(),
                    REFINE_MAX_PIXELS,
                ],
                outputs=[split],
                device=dev,
            )
            cut = split.numpy().astype(bool)
            leaves.append(active[~cut])
            parents = active[cut]
            children = [
                np.stack(
                    [2 * parents[:, 0] + dx, 2 * parents[:, 1] + dy, np.full(len(parents), level - 1)], 1
                )
                for dy in (0, 1)
                for dx in (0, 1)
            ]
            active = np.concatenate(children).astype(np.int32) if len(parents) else active[:0]
        leaves.append(active)
        ordered = np.concatenate(leaves)
        ordered = ordered[np.lexsort((ordered[:, 0], ordered[:, 1], -ordered[:, 2]))]
        self.level_counts = {int(lv): int(np.count_nonzero(ordered[:, 2] == lv)) for lv in range(top + 1)}
        return wp.array(ordered, dtype=wp.vec3i, device=dev)

    def gather_beams(self) -> beam_kernels.Beams:
        """The beams of the pass being traced as the gathers read them (floor, points, shafts)."""
        bm = beam_kernels.Beams()
        for name in ("base", "direction", "transmit", "ends", "weight", "area_coef", "beams_per_group",
                     "sun_irradiance", "attenuation_per_m", "extent_m", "quads"):
            setattr(bm, name, getattr(self, name))
        bm.wavelengths_per_group = self.k // self.groups
        bm.periodic, bm.smooth, bm.occluders = int(self.periodic), int(self.smooth), int(self.occluders)
        bm.mesh = self.receivers.mesh.id
        bm.primaries = self.primary_slots
        bm.before, bm.unlit_receiver = self.before, self.unlit_receiver
        bm.source = self.bounces.source if self.bounces else self.no_source
        return bm

    def _bin_horizontal(self, bins: TileBins, lo_z: float, hi_z: float) -> None:
        wp.launch(
            beam_kernels.horizontal_spans,
            dim=self.weight.shape[0],
            inputs=[
                bins.grid,
                self.base,
                self.direction,
                self.end_m,
                self.weight,
                self.area_coef,
                float(lo_z),
                float(hi_z),
            ],
            outputs=[bins.spans],
            device=self.device,
        )
        bins.bin()

    def points(self, points: wp.array, normals: wp.array, ids: wp.array, out: wp.array2d) -> wp.array2d:
        """Irradiance (K, P) [W m^-2 nm^-1] on receivers at ``points`` with unit ``normals`` (ids < 0
        are skipped and get 0) from the beams of the pass being traced."""
        if not self._points_binned:  # binned on first use: a flat floor alone does not need it
            self._bin_horizontal(self.point_bins, *self.query_z)
            self._points_binned = True
        wp.launch(
            beam_kernels.point_irradiance,
            dim=points.shape[0],
            inputs=[*self.point_bins.inputs(), self.gather_beams(), points, normals, ids],
            outputs=[out],
            device=self.device,
        )
        return out

    def inscatter(self, sb: beam_kernels.ShaftBeams, points: wp.array, views: wp.array, along_m: wp.array,
                  piece_m: wp.array, out: wp.array2d, top_z: float) -> wp.array2d:
        """Add to ``out`` (K, P) one midpoint piece of the single scattering into view rays at
        ``points`` from the beams of the pass being traced (``kernels/caustics/beams/volume.py
        point_inscatter``; ``sb``: the medium's scattering and phase function). The beams are
        binned over the whole water column, from the receivers' lowest point to ``top_z``."""
        if not self._volume_binned:
            if self.volume_bins is None:
                self.volume_bins = TileBins(self.point_bins.grid, self.weight.shape[0], self.device)
            self._bin_horizontal(self.volume_bins, self.query_z[0], top_z)
            self._volume_binned = True
        sb.beams = self.gather_beams()
        wp.launch(beam_kernels.point_inscatter, dim=points.shape[0],
                  inputs=[*self.volume_bins.inputs(), sb, points, views, along_m, piece_m], outputs=[out],
                  device=self.device)
        return out

    def _face_flux_w_nm(self) -> np.ndarray:
        """(F_other, K) flux on each non-floor face [W nm^-1]: mean sample irradiance × area."""
        if not self.face_count:
            return np.zeros((0, self.k))
        values = self.face_values.numpy().astype(np.float64).reshape(self.k, self.face_count, FACE_SAMPLES)
        area = self.receivers.face_area_m2[self.receivers.floor_face_count :]
        return (values.mean(axis=2) * area[None, :]).T

    def _transmitted_flux(self) -> np.ndarray:
        """(K,) flux the beams carry into the water before attenuation [W nm^-1] (float64)."""
        used = self.groups * self.beams_per_group  # adaptive beams fill only part of the buffers
        w = self.weight.numpy()[:used].astype(np.float64)
        t = self.transmit.numpy()[:used].astype(np.float64).mean(axis=1)
        per_group = (w * t).reshape(self.groups, -1).sum(axis=1)
        e = self.sun_irradiance.numpy().astype(np.float64)
        return e * np.repeat(per_group, len(e) // self.groups)

    def _stats(self) -> BeamStats:
        used = self.groups * self.beams_per_group
        w = self.weight.numpy()[:used]
        built, parted, rising = self.bounces.counts() if self.bounces else (0, 0, 0)
        return BeamStats(
            beams=used,
            carrying=int(np.count_nonzero(w > 0)),
            dropped=int(self.dropped.numpy()[0]),
            tile_entries=self.floor_bins.entries,
            bounced=built,
            parted=parted,
            rising=rising,
        )


class BeamStage(ReceiverStage):
    """``beams``: warped beam volumes, software-rasterised, with scan-plane shafts."""

    name = "beams"

    def make_caustics(self, setup: CausticsSetup) -> list[PassCaustics]:
        return [BeamCaustics(setup)]

    @classmethod
    def caustics_bytes(cls, scene, n: int, k: int, groups: int, faces: int) -> int:
        cfg = scene.config
        walls = WALL_FACES if cfg.water.walled else 0
        sampled = sum(len(m.triangles) for m in scene.receiver_meshes) + walls
        return beams_bytes(cfg, n, k, groups, cfg.water.periodic, faces, sampled)
