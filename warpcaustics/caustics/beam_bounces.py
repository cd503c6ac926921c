"""Beams through glass receivers and off mirrors (``caustics.bounces`` > 1), host side.

After a pass's primary beams are built, each is followed past the glass and mirrors it meets
(``kernels/caustics/beams/bounces.py``): its light goes on as one bounced beam, or, where its edges
parted at the object's silhouette, as SPLIT² sub-beams. The bounced beams are stored after the
primaries' slots, in the order of their primaries (count → exclusive scan → build), and the
gathers read them as any beam.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.caustics.receiver_stage import receiver_optics
from warpcaustics.kernels.caustics.beams import bounces as bounce_kernels

GROWTH = 1.25
"""The bounced region grows to this many times a frame's need when it runs out."""


def sub_triangle_corners(split: int) -> np.ndarray:
    """(split², 3, 3): the barycentrics of the corners of a triangle's split² congruent
    sub-triangles (the upright ones, then the inverted), each in the parent's orientation."""
    rows = []
    for a in range(split):
        for b in range(split - a):
            rows.append([(a, b), (a + 1, b), (a, b + 1)])
    for a in range(split):
        for b in range(split - a - 1):
            rows.append([(a + 1, b), (a + 1, b + 1), (a, b + 1)])
    uv = np.asarray(rows, np.float64) / split  # (u, v): weights of corners 1 and 2
    lam = np.stack([1.0 - uv[..., 0] - uv[..., 1], uv[..., 0], uv[..., 1]], -1)
    return np.clip(lam, 0.0, 1.0).astype(np.float32)


def bounced_capacity(primaries: int) -> int:
    """The bounced beams' first buffer size [beams]; it grows when a frame needs more (an object
    met by more than an eighth of the beams, or a long silhouette cut into sub-beams)."""
    return max(primaries // 8, 256)


class BouncedBeams:
    """The bounce pass's own buffers (per primary: how its light goes on, its slots and their
    offset; per bounced slot: its primary) and the receivers' optics."""

    def __init__(self, cfg, receivers, group_ior: np.ndarray, primaries: int, device: str):
        self.device = device
        self.optics = receiver_optics(cfg, receivers, group_ior, device)
        self.need = wp.zeros(primaries, dtype=wp.int32, device=device)
        self.slots = wp.zeros(primaries, dtype=wp.int32, device=device)
        self.offset = wp.zeros(primaries, dtype=wp.int32, device=device)
        self.capacity = bounced_capacity(primaries)
        self.source = wp.zeros(self.capacity, dtype=wp.int32, device=device)
        """The primary beam of each bounced slot."""
        corners = sub_triangle_corners(bounce_kernels.SPLIT)
        self.sub_corners = wp.array(corners, dtype=wp.vec3, device=device)
        self.count_array = wp.zeros(bounce_kernels.BOUNCE_COUNTS, dtype=wp.int32, device=device)
        self.used = 0
        """Bounced slots of the last pass."""

    def build(self, stage) -> None:
        """Fill the bounced region of ``stage``'s (a ``BeamCaustics``) buffers for the pass just built,
        growing it where this pass needs more slots."""
        dev = self.device
        mesh, face_receiver = stage.receivers.mesh.id, stage.receivers.face_receiver
        first = stage.primary_slots
        self.count_array.zero_()
        wp.launch(bounce_kernels.bounce_needs, dim=first,
                  inputs=[mesh, face_receiver, self.optics, stage.beams_per_group, stage.base,
                          stage.direction, stage.weight],
                  outputs=[self.need, self.slots], device=dev)
        wp.utils.array_scan(self.slots, self.offset, inclusive=False)
        total = int(self.offset[-1:].numpy()[0] + self.slots[-1:].numpy()[0])
        if total > self.capacity:
            self.capacity = int(total * GROWTH) + 1
            self.source = wp.zeros(self.capacity, dtype=wp.int32, device=dev)
            stage.allocate(first + self.capacity)
        stage.weight[first:].zero_()
        self.used = total
        if not total:
            return
        wp.launch(bounce_kernels.bounce_sources, dim=first, inputs=[self.slots, self.offset],
                  outputs=[self.source], device=dev)
        wp.launch(bounce_kernels.build_bounced, dim=total,
                  inputs=[mesh, face_receiver, self.optics, float(stage.plane_z), stage.beams_per_group,
                          first, self.sub_corners, self.need, self.offset, self.source],
                  outputs=[stage.base, stage.direction, stage.transmit, stage.end_m, stage.ends, stage.weight,
                           stage.area_coef, stage.before, self.count_array], device=dev)

    def counts(self) -> tuple[int, int, int]:
        """(bounced beams built, (sub-)beams whose edges parted, bounced beams dropped rising)."""
        built, parted, rising = (int(c) for c in self.count_array.numpy())
        return built, parted, rising
