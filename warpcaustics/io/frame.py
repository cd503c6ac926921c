"""Saving a frame: the registry of frame writers, run in order by :func:`save_frame`.

A writer is a function ``write(result, out_dir, *, frame) -> {key: path}`` that writes its files
atomically, paired with a predicate saying whether a frame gets them (a switch in ``[output]``, or
what the render holds). Adding an output format = one module with its writer, one line in
:data:`WRITERS`, and a test.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from warpcaustics.io import arrays, comparison, images, vtk_meshes

if TYPE_CHECKING:
    from warpcaustics.result import RenderResult


@dataclass(frozen=True)
class FrameWriter:
    """One kind of file a frame is saved as."""

    write: Callable[..., dict[str, Path]]
    """``write(result, out_dir, *, frame)``: write the files, return their paths by key."""
    enabled: Callable[[RenderResult], bool]
    """Whether this frame gets them."""


def always(result: RenderResult) -> bool:
    return True


WRITERS: dict[str, FrameWriter] = {
    "floor": FrameWriter(images.write_floor, always),
    "camera": FrameWriter(images.write_camera, lambda r: r.camera_radiance is not None),
    "vtk": FrameWriter(vtk_meshes.write_vtk, lambda r: r.scene.config.output.vtk),
    "npz": FrameWriter(arrays.write_npz, lambda r: r.scene.config.output.npz),
    "netcdf": FrameWriter(arrays.write_netcdf, lambda r: r.scene.config.output.netcdf),
    "comparison": FrameWriter(comparison.write_comparison_frame, lambda r: r.comparison is not None),
}
"""The frame writers by name, in the order they run. ``floor`` and ``camera`` each write an EXR
and its PNG preview together (one colour conversion for both)."""


def save_frame(result: RenderResult, out_dir: Path, *, frame: int = 0) -> dict[str, Path]:
    """Write one frame's files (``frame_NNNN.exr`` with RGB + spectral bands, ``frame_NNNN.png``
    and whatever else :data:`WRITERS` enables for it); return them by key."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {}
    for writer in WRITERS.values():
        if writer.enabled(result):
            paths.update(writer.write(result, out_dir, frame=frame))
    return paths
