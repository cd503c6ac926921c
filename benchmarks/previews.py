"""Render the README's pictures: ``python -m benchmarks.previews`` (CPU, about a minute).

- ``docs/images/ocean.png``: frame 0 of configs/ocean.toml;
- ``docs/images/pool_frames.png``: six frames of configs/pool.toml side by side (0.25 s apart),
  the pool stepping forward from frame to frame;
- ``docs/images/{ocean_floor,pool_pots,buried_in_sand}.png``: the camera images of the photon
  configs (the pools stepped to 1 s, so that their drops have spread into waves).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _preview(result) -> np.ndarray:
    from warpcaustics import colour_out

    xyz = colour_out.spectral_to_xyz(result.floor_irradiance[:, ::-1, :], result.bins)
    return colour_out.tone_map_srgb8(colour_out.xyz_to_linear_srgb(xyz), xyz[..., 1])


def _camera_preview(result) -> np.ndarray:
    from warpcaustics import colour_out

    xyz = colour_out.spectral_to_xyz(result.camera_radiance, result.bins)
    return colour_out.tone_map_srgb8(colour_out.xyz_to_linear_srgb(xyz), xyz[..., 1])


CAMERA_SCENES = {"ocean_floor": 0.0, "pool_pots": 1.0, "buried_in_sand": 1.0}
"""Photon configs with a camera, and the time [s] their picture shows."""


def main() -> int:
    import warpcaustics as wc
    from warpcaustics.output import write_png

    images = ROOT / "docs" / "images"
    ocean = wc.render(wc.load_scene(ROOT / "configs" / "ocean.toml"), device="cpu")
    write_png(images / "ocean.png", _preview(ocean))

    renderer = wc.Renderer(wc.load_scene(ROOT / "configs" / "pool.toml"), device="cpu")
    frames = [_preview(renderer.render(t)) for t in np.arange(1, 7) * 0.25]
    gap = np.full((frames[0].shape[0], 6, 3), 255, np.uint8)
    strip = np.concatenate([x for f in frames for x in (f, gap)][:-1], axis=1)
    write_png(images / "pool_frames.png", np.ascontiguousarray(strip[::2, ::2]))
    print(f"wrote {images / 'ocean.png'} and {images / 'pool_frames.png'}")

    for name, time_s in CAMERA_SCENES.items():
        renderer = wc.Renderer(wc.load_scene(ROOT / "configs" / f"{name}.toml"), device="cpu")
        write_png(images / f"{name}.png", _camera_preview(renderer.render(time_s)))
        print(f"wrote {images / f'{name}.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
