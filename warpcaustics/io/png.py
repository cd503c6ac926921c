"""8-bit RGB PNG previews through Pillow (a dependency of pyvista, named in pyproject.toml too)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.io.files import atomic_path


def write_png(path: Path, rgb8: np.ndarray) -> None:
    """An (H, W, 3) uint8 image as a PNG, written atomically."""
    from PIL import Image

    image = Image.fromarray(np.ascontiguousarray(rgb8, dtype=np.uint8), mode="RGB")
    with atomic_path(path) as tmp:
        image.save(tmp, format="PNG", compress_level=6)
