"""The renderer composes registered stages (issue 25): every method is a registered stage object, the
renderer never branches on the method, and a frame's result is its own."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import pipeline
from warpcaustics.caustics.registry import METHODS
from warpcaustics.caustics.stage import CausticStage
from warpcaustics.config import CausticsMethod

from helpers import CONFIGS

SMALL = {"water.resolution": 32, "caustics.map_resolution": 32, "optics.wavelengths.bins": 3,
         "sun.disk_samples": 2, "caustics.eikonal_resolution": 24, "caustics.wave3d_resolution": 48,
         "caustics.wave3d_cells_per_wavelength": 4}


def test_every_method_is_a_registered_stage():
    """Each ``caustics.method`` value has a CausticStage subclass registered under its own name."""
    assert set(METHODS) == set(CausticsMethod)
    for method, stage in METHODS.items():
        assert issubclass(stage, CausticStage) and stage.name == method.value


def test_the_renderer_has_no_per_method_branch():
    """The pipeline module names no caustics method: it looks the stage up in the registry."""
    source = inspect.getsource(pipeline)
    assert "CausticsMethod" not in source
    for method in CausticsMethod:
        assert f'"{method.value}"' not in source


def _arrays(result) -> dict[str, np.ndarray]:
    """Every array a result holds (its comparison's and its dictionaries' too), copied."""
    out = {}
    for res, tag in ((result, ""), (result.comparison, "comparison.")):
        if res is None:
            continue
        for key, value in vars(res).items():
            if isinstance(value, np.ndarray):
                out[tag + key] = value.copy()
            elif isinstance(value, dict):
                out.update({f"{tag}{key}.{k}": v.copy() for k, v in value.items()
                            if isinstance(v, np.ndarray)})
    return out


@pytest.mark.parametrize("method,extra", [
    ("fluxratio", {"sky.model": "uniform", "sky.diffuse_fraction": 0.2, "sky.directions": 2}),
    ("photons", {"camera.enabled": True, "camera.width": 16, "camera.height": 12,
                 "camera.position_m": [0.0, -5.0, -1.5], "camera.look_at_m": [0.0, 0.0, -3.5]}),
    ("both", {"camera.enabled": True, "camera.width": 16, "camera.height": 12,
              "camera.position_m": [0.0, -5.0, -1.5], "camera.look_at_m": [0.0, 0.0, -3.5]}),
    ("sunmap", {}),
    ("eikonal", {}),
])
def test_a_result_is_not_changed_by_the_next_frame(method, extra):
    """The buffers a stage reuses from pass to pass and frame to frame never show through a
    RenderResult: rendering the next frame leaves the first frame's arrays as they were."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {**SMALL, "caustics.method": method, **extra})
    renderer = wc.Renderer(scene, device="cpu")
    first = renderer.render(0.0)
    kept = _arrays(first)
    second = renderer.render(0.5)
    assert not np.array_equal(second.floor_irradiance, first.floor_irradiance)  # the sea moved
    for key, value in _arrays(first).items():
        np.testing.assert_array_equal(value, kept[key], err_msg=key)


@pytest.mark.parametrize("method", ["photons", "beams"])
def test_a_light_pass_owes_nothing_to_the_pass_before(method):
    """A caustics object's buffers are its workspace, not its state: a sun pass traced after a sky
    pass (another direction, another irradiance) reads back to the bit what the same pass reads on
    a fresh object, floor, faces, counts and camera alike, and the sky pass's record is untouched."""
    from warpcaustics.caustics.stage import Stopwatch
    from warpcaustics.optics.refraction import height_range, sun_visibility

    scene = wc.load_scene(CONFIGS / "pool_pots.toml", {
        **SMALL, "caustics.method": method, "camera.width": 16, "camera.height": 12,
        "sky.model": "uniform", "sky.diffuse_fraction": 0.3, "sky.directions": 2})
    used, fresh = (wc.Renderer(scene, device="cpu") for _ in range(2))
    surface = used.water.at(0.0)
    _, highest = height_range(surface, "cpu")
    sun, sky = used.light.passes()[0], used.light.passes()[-1]
    assert sky[2] and not np.allclose(sky[0], sun[0])

    def light_pass(renderer, light):
        seen = sun_visibility(surface, light[0], highest, "cpu")
        return renderer.method.caustics[0].light_pass(surface, seen, light[0], light[1], Stopwatch("cpu"),
                                                      stage="test", camera=renderer.method.camera)

    sky_pass = light_pass(used, sky)
    kept = {k: np.copy(v) for k, v in vars(sky_pass).items() if not isinstance(v, dict)}
    after, alone = light_pass(used, sun), light_pass(fresh, sun)
    assert after.face_flux_w_nm.size and after.camera_radiance is not None and after.floor.max() > 0
    for key, value in vars(alone).items():
        if isinstance(value, dict):
            assert getattr(after, key) == value, key
        else:
            np.testing.assert_array_equal(getattr(after, key), value, err_msg=key)
    for key, value in kept.items():
        np.testing.assert_array_equal(getattr(sky_pass, key), value, err_msg=key)
