"""Render the README's pictures: ``python -m benchmarks.previews`` (CPU, about 25 minutes on one core:
the default 0.53° disk costs the flux-ratio map, photons and beams a pass per direction).

- ``docs/images/ocean.png``: frame 0 of configs/ocean.toml;
- ``docs/images/pool_frames.png``: six frames of configs/pool.toml side by side (0.25 s apart),
  the pool stepping forward from frame to frame;
- ``docs/images/{ocean_floor,pool_pots,buried_in_sand,above_water}.png``: the camera images of the
  photon configs and of the view from above (the pools stepped to 1 s, so that their drops have
  spread into waves);
- ``docs/images/beams_vs_photons.png``: the same camera frames of pool_pots, ocean_floor and
  above_water (seen from above) by photons (left) and by beams (right, ``caustics.method = "both"``);
- ``docs/images/two_sided_beams_vs_photons.png``: configs/two_sided.toml's glass ball, its floor map
  and camera frame by photons (left) and by bounced beams (right); alone with ``--two-sided``;
- ``docs/images/beam_bounds.png``: a few beams of ocean_floor's camera view, their tight hull and
  an Ernst-style bounding prism projected on the screen;
- ``docs/images/methods_ocean.png``, ``methods_mercier.png``: one frame of configs/ocean.toml
  (128², 256² map) and of configs/mercier_pool.toml (at 0.3 s) by every floor method, as
  ``warpcaustics compare`` draws them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _preview(result) -> np.ndarray:
    from warpcaustics.optics import colour as colour_out

    xyz = colour_out.spectral_to_xyz(result.floor_irradiance[:, ::-1, :], result.bins)
    return colour_out.tone_map_srgb8(colour_out.xyz_to_linear_srgb(xyz), xyz[..., 1])


def _camera_preview(result) -> np.ndarray:
    from warpcaustics.optics import colour as colour_out

    xyz = colour_out.spectral_to_xyz(result.camera_radiance, result.bins)
    return colour_out.tone_map_srgb8(colour_out.xyz_to_linear_srgb(xyz), xyz[..., 1])


CAMERA_SCENES = {"ocean_floor": 0.0, "pool_pots": 1.0, "buried_in_sand": 1.0, "above_water": 1.0}
"""Configs with a camera (photons; above_water: beams, seen from above), and the time [s] their
picture shows."""


def main(argv: list[str] | None = None) -> int:
    import warpcaustics as wc
    from warpcaustics.io.png import write_png

    images = ROOT / "docs" / "images"
    if "--two-sided" in (sys.argv[1:] if argv is None else argv):
        _bounce_picture(images)
        return 0
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
    _beam_pictures(images)
    _bounce_picture(images)
    _method_pictures(images)
    return 0


def _side_by_side(images: list[np.ndarray]) -> np.ndarray:
    """Images (H, W, 3) left to right, 6 white pixels apart."""
    gap = np.full((images[0].shape[0], 6, 3), 255, np.uint8)
    return np.concatenate([x for image in images for x in (image, gap)][:-1], axis=1)


def _stacked(rows: list[np.ndarray]) -> np.ndarray:
    """Rows (H, W, 3) top to bottom, padded white to the widest, 6 white pixels apart."""
    width = max(r.shape[1] for r in rows)
    rows = [np.pad(r, ((0, 0), (0, width - r.shape[1]), (0, 0)), constant_values=255) for r in rows]
    gap = np.full((6, width, 3), 255, np.uint8)
    return np.concatenate([x for row in rows for x in (row, gap)][:-1], axis=0)


def _bounce_picture(images: Path) -> None:
    """configs/two_sided.toml by photons and by beams (``caustics.method = "both"``): the floor maps
    (top) and the camera frames (bottom), each tone-mapped as a render's previews are."""
    import warpcaustics as wc
    from warpcaustics.io.png import write_png

    scene = wc.load_scene(ROOT / "configs" / "two_sided.toml", {"caustics.method": "both"})
    result = wc.Renderer(scene, device="cpu").render(0.0)
    photons, beams = result.comparison, result
    rows = [_side_by_side([view(photons), view(beams)]) for view in (_preview, _camera_preview)]
    write_png(images / "two_sided_beams_vs_photons.png", _stacked(rows))
    print(f"wrote {images / 'two_sided_beams_vs_photons.png'}")


METHOD_SCENES = {
    "methods_ocean.png": ("ocean.toml", {"water.resolution": 128, "caustics.map_resolution": 256}, 0.0),
    "methods_mercier.png": ("mercier_pool.toml", {}, 0.3),
}
"""``warpcaustics compare`` pictures: (config, overrides, time [s])."""


def _method_pictures(images: Path) -> None:
    import tempfile

    from warpcaustics.batch.compare import compare_methods, write_comparison

    for name, (config, overrides, time_s) in METHOD_SCENES.items():
        comparison = compare_methods(ROOT / "configs" / config, overrides, time_s, "cpu")
        with tempfile.TemporaryDirectory() as tmp:
            png = write_comparison(Path(tmp), comparison, time_s)["png"]
            (images / name).write_bytes(png.read_bytes())
        print(f"wrote {images / name}")


def _beam_pictures(images: Path) -> None:
    import warpcaustics as wc
    from warpcaustics.io.png import write_png

    rows = []
    for name in ("pool_pots", "ocean_floor", "above_water"):
        scene = wc.load_scene(ROOT / "configs" / f"{name}.toml", {"caustics.method": "both"})
        renderer = wc.Renderer(scene, device="cpu")
        result = renderer.render(CAMERA_SCENES[name])
        rows.append(_side_by_side([_camera_preview(result.comparison), _camera_preview(result)]))
        if name == "ocean_floor":
            _bounds_plot(renderer, images / "beam_bounds.png")
    write_png(images / "beams_vs_photons.png", _stacked(rows))
    print(f"wrote {images / 'beams_vs_photons.png'} and {images / 'beam_bounds.png'}")


def _bounds_plot(renderer, path: Path) -> None:
    """Outlines of a few beams' projected tight hull and Ernst-style prism."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.spatial import ConvexHull

    from benchmarks.beam_fill import prism_ends

    stage, camera = renderer.method.caustics[0], renderer.method.camera
    cam = camera.cam
    pos = np.array(cam.position, np.float64)
    right, up, fwd = (np.array(a, np.float64) for a in (cam.right, cam.up, cam.forward))
    w, h = int(cam.width), int(cam.height)

    def project(x):
        rel = x - pos
        z = rel @ fwd
        return np.stack([(rel @ right / (z * cam.tan_half_fov * cam.aspect) + 1) * 0.5 * w,
                         (1 - rel @ up / (z * cam.tan_half_fov)) * 0.5 * h], -1), z

    v = stage.base.numpy().astype(np.float64)
    d = stage.direction.numpy().astype(np.float64)
    ends = stage.end_m.numpy().astype(np.float64)
    rng = np.random.default_rng(3)
    fig, ax = plt.subplots(figsize=(7, 4.7))
    drawn = 0
    for b in rng.permutation(len(v)):
        hull = np.concatenate([v[b], v[b] + ends[b][:, None] * d[b]])
        prism = np.concatenate([v[b], prism_ends(v[b][None], d[b][None], ends[b][None])[0]])
        hp, hz = project(hull)
        pp, pz = project(prism)
        if (hz <= 0.5).any() or (pz <= 0.5).any() or not np.isfinite(pp).all():
            continue
        if not (np.all((hp > 0) & (hp < [w, h]))):
            continue
        for pts, style in ((pp, "r-"), (hp, "b-")):
            loop = pts[ConvexHull(pts).vertices]
            ax.plot(*np.vstack([loop, loop[:1]]).T, style, lw=0.8)
        drawn += 1
        if drawn == 40:
            break
    ax.plot([], [], "b-", label="tight hull (base + end vertices)")
    ax.plot([], [], "r-", label="Ernst-style bounding prism")
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_aspect("equal")
    ax.set_xlabel("pixel column")
    ax.set_ylabel("pixel row")
    ax.set_title(f"{drawn} beams of configs/ocean_floor.toml projected on its camera")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
