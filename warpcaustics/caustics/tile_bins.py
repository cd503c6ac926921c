"""Beams binned into the tiles of a grid (a horizontal grid over the patch, or the camera's screen
tiles): count → exclusive scan → scatter, the lists the beam gathers walk (``caustics/beams.py``)."""

from __future__ import annotations

import warp as wp

from warpcaustics.kernels.caustics import beams as beam_kernels


class TileBins:
    """Beams binned into the tiles of one grid: count → exclusive scan → scatter."""

    def __init__(self, grid: beam_kernels.TileGrid, items: int, device: str):
        self.grid = grid
        self.device = device
        tiles = grid.nx * grid.ny
        self.spans = wp.empty((items, 4), dtype=wp.int32, device=device)
        """Tile range (i0, j0, i1, j1) of each item; filled by the caller's span kernel."""
        self.count = wp.zeros(tiles, dtype=wp.int32, device=device)
        self.start = wp.zeros(tiles, dtype=wp.int32, device=device)
        self.fill = wp.zeros(tiles, dtype=wp.int32, device=device)
        self.items = wp.zeros(max(items, 1), dtype=wp.int32, device=device)
        self.use_boxes = 0
        self.box_axis = wp.zeros(1, dtype=wp.vec2, device=device)
        self.box_lo = wp.zeros(1, dtype=wp.vec2, device=device)
        self.box_hi = wp.zeros(1, dtype=wp.vec2, device=device)
        self.entries = 0
        """Entries in the tile lists after the last :meth:`bin`."""

    def with_boxes(self) -> TileBins:
        """Also test each tile against an oriented box per item (filled by the span kernel)."""
        n = self.spans.shape[0]
        self.use_boxes = 1
        self.box_axis = wp.zeros(n, dtype=wp.vec2, device=self.device)
        self.box_lo = wp.zeros(n, dtype=wp.vec2, device=self.device)
        self.box_hi = wp.zeros(n, dtype=wp.vec2, device=self.device)
        return self

    def bin(self) -> None:
        dev = self.device
        n = self.spans.shape[0]
        self.count.zero_()
        boxes = [self.use_boxes, self.box_axis, self.box_lo, self.box_hi]
        wp.launch(
            beam_kernels.bin_tiles,
            dim=n,
            inputs=[self.grid, self.spans, *boxes, 0, self.start, self.count, self.items],
            device=dev,
        )
        wp.utils.array_scan(self.count, self.start, inclusive=False)
        total = int(self.start[-1:].numpy()[0] + self.count[-1:].numpy()[0])
        self.entries = total
        if total > self.items.shape[0]:
            self.items = wp.zeros(int(total * 1.25) + 1, dtype=wp.int32, device=dev)
        self.fill.zero_()
        wp.launch(
            beam_kernels.bin_tiles,
            dim=n,
            inputs=[self.grid, self.spans, *boxes, 1, self.start, self.fill, self.items],
            device=dev,
        )

    def inputs(self) -> list:
        return [self.grid, self.start, self.count, self.items]

    def screen_bins(self, tile_pixels: int) -> beam_kernels.ScreenBins:
        """The lists and oriented boxes as the volume pass reads them (screen tiles of ``tile_pixels``)."""
        out = beam_kernels.ScreenBins()
        out.grid, out.start, out.count, out.items = self.inputs()
        out.tile_pixels = tile_pixels
        out.box_axis, out.box_lo, out.box_hi = self.box_axis, self.box_lo, self.box_hi
        return out
