"""A minimal 8-bit RGB PNG writer (zlib + CRC), so previews need no imaging library."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

from warpcaustics.io.files import atomic_path


def write_png(path: Path, rgb8: np.ndarray) -> None:
    """Minimal 8-bit RGB PNG writer (zlib + CRC), so previews need no imaging library."""
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[row].tobytes() for row in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    with atomic_path(path) as tmp:
        tmp.write_bytes(png)
